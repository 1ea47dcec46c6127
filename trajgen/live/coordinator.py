"""What the live master decides: the first orders, the releases, the holds, re-plans, goals and the stop.

:class:`LiveCoordinator` takes what the vehicles report (states and connections, decoded and
trusted by the master) and the plans made for it, and decides what to send; it holds no MQTT
client, no thread and no lock: :class:`~trajgen.live.master.LiveMaster` keeps the link, calls it
under its lock, and carries out what it asks of its outbox (publish an order or ``cancelOrder``,
make a plan in a thread of its own). The first orders wait for every vehicle at the plan's start
(:mod:`trajgen.live.start_check`); a vehicle's reported node moves the release rule
(:class:`~trajgen.export.vda5050.release.BaseRelease`) on, each growth an order update
(:mod:`trajgen.live.ordering`); a new goal or a vehicle back without its order re-plans from where
the vehicles stand; the tally is :mod:`trajgen.live.record`'s.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time

from topology import TrackGraph
from trajgen.errors import InputError
from trajgen.execution.goals import schedule_for_execution
from trajgen.execution.tracks import GraphTrack, JunctionTrack
from trajgen.live.ordering import OrderDesk
from trajgen.live.outcome import LiveOutcome, LiveRun
from trajgen.live.places import live_goal, path_place, restart_place
from trajgen.live.plans import ReadyPlan, ready_plan, run_id
from trajgen.live.record import RunRecord, stop_message
from trajgen.live.replanning import moved_since, replan_start
from trajgen.live.start_check import CANCEL_RESEND_S, not_begun, same_place, start_decision
from trajgen.live.view import RESEND_INTERVAL_S, VehicleView, not_taken_message
from trajgen.methods import method_for
from trajgen.model.summary import provenance

__all__ = ["LiveCoordinator"]

logger = logging.getLogger(__name__)
#: Log lines that the run log says too (``timeline``: left off stderr while a command prints it).
said = logging.LoggerAdapter(logger, {"timeline": True})


class LiveCoordinator:
    """The decisions of a live run; its caller holds the lock, the link and the threads.

    Parameters
    ----------
    scenario : trajgen.scenario.Scenario or trajgen.scenario.GraphScenario
    identities : sequence of VehicleIdentity
        One per vehicle, in the scenario's order.
    outbox
        ``order(v, payload)``, ``instant_actions(v, payload)``: publish to vehicle ``v``;
        ``plan(make, what=...)``: run ``make()`` (it returns a :class:`~trajgen.live.plans.ReadyPlan`)
        in a thread of its own and call :meth:`planned` with the job when it ends; returns the job.
    clock : RunClock
    log : RunLog
    method : TimingMethod or str or None
    order_prefix, map_id : str
    spacing : float
        Longest edge of the paths sent, metres.
    give_up_after : float
        Seconds of the run a vehicle may lack its order, or stand off its plan, before the run ends.
    """

    def __init__(
        self,
        scenario,
        identities,
        *,
        outbox,
        clock,
        log,
        method,
        order_prefix: str,
        map_id: str,
        spacing: float,
        give_up_after: float,
    ) -> None:
        self.scenario = scenario
        self.graph = scenario.track
        graph = isinstance(self.graph, TrackGraph)
        self.track = GraphTrack(self.graph) if graph else JunctionTrack(self.graph)
        self.names = tuple(scenario.names)
        self.limits = scenario.limits  # the plan's (its planned separation) once a plan is taken
        self.method = method
        self.asked = method_for(method, self.graph).name  # as the plans name it (exact after a fallback)
        self.outbox = outbox
        self.clock = clock
        self.log = log
        self.map_id = map_id
        self.spacing = spacing
        self.give_up_after = give_up_after
        self.run_id = run_id(clock)
        pairs = zip(self.names, identities, strict=True)
        self.views = [VehicleView(name, identity) for name, identity in pairs]
        self.desk = OrderDesk(
            self.views,
            outbox,
            limits=scenario.limits.vehicles,
            order_ids=[f"{order_prefix}-{name}-{self.run_id}" for name in self.names],
            run_id=self.run_id,
            clock=clock,
            write=self.write,
        )
        #: set once every vehicle stands at its goal
        self.done = threading.Event()
        #: set once the run ended otherwise (refused, given up, interrupted)
        self.over = threading.Event()
        self.verified = None  # the plan being driven, or waiting to be
        self.rule = None
        self.job = None  # the plan waited for
        self.goal = None  # a new goal not yet planned for
        self.plan_goal = None
        self.stopping = False
        #: the run's tally: counts, times, the closest approach
        self.record = RunRecord()
        self.first_plan: dict | None = None  # the first plan's log record, written with the first orders
        self.outcome: LiveOutcome | None = None  # how the run ended, when not at the goals
        self.why: str | None = None
        self.planned_from = None  # where the vehicles stood when the first plan was made from their places

    # ----------------------------------------------------------------- time and the log
    @property
    def started_at(self) -> float | None:
        """Run clock at the first orders, the run's time 0; ``None`` before them."""
        return self.record.started_at

    def now(self) -> float:
        """Seconds of the run: since the first order was sent (0 before it)."""
        began = self.record.started_at
        return 0.0 if began is None else self.clock.now() - began

    def write(self, event: str, **fields) -> None:
        """A record of the run log, at the run's time now."""
        self.log.write({"t": self.now(), "event": event, **fields})

    def ended(self) -> bool:
        """Whether the run ended early (refused, given up, interrupted)."""
        return self.outcome is not None

    def end(self, outcome: LiveOutcome, why: str) -> None:
        """End the run early (once): nothing more is sent; :attr:`over` is set."""
        if self.outcome is not None:
            return
        self.outcome, self.why = outcome, why
        self.job = None
        if outcome is not LiveOutcome.INTERRUPTED:
            logger.debug("%s", why)  # the owner reports it once: the summary's error line
        self.over.set()

    # ----------------------------------------------------------------- plans
    def take_plan(self, plan) -> None:
        """The plan from the scenario's start (a VerifiedSchedule), made before the run."""
        self._log_planned("the scenario's start", plan, 0.0)
        self._adopt(self._ready(plan, (0,) * len(self.views)), first=True)

    def start(self) -> None:
        """The run starts: its plan is made now from the scenario's start, unless it was given."""
        self.record.began_at = self.clock.now()
        if self.verified is None and self.job is None:
            self._plan_scenario(self.scenario, "the scenario's start")

    def _plan_scenario(self, scenario, what: str) -> None:
        """The first plan, of ``scenario`` (its start where the vehicles stand, or the scenario's)."""
        method = self.method
        self._plan(
            lambda: schedule_for_execution(scenario, method=method),
            what=what,
            context=("start",),
            offsets=(0,) * len(self.views),
        )

    def _ready(self, verified, offsets) -> ReadyPlan:
        return ready_plan(verified, offsets, spacing=self.spacing, map_id=self.map_id)

    def _plan(self, plan, *, what: str, context, offsets) -> None:
        """Make a plan and ready it to send, beside the network (the outbox); :meth:`planned` takes it up.

        ``offsets``: per vehicle, the ``sequenceId`` its new path starts at.
        """
        self.write("planning", what=what, method=self.asked)
        said.info("master: planning %s (%s)", what, self.asked)
        ready = self._ready
        self.job = self.outbox.plan(lambda: ready(plan(), offsets), what=what, context=context)

    def _log_planned(self, what: str, verified, seconds: float) -> None:
        self.write(
            "planned",
            what=what,
            planning_s=seconds,
            planned_s=verified.schedule.duration,
            **provenance(verified.schedule, self.asked),
        )

    def planned(self, job) -> None:
        """A plan job ended (made, or failed): take it up, unless the run no longer waits for it."""
        if job is not self.job:
            logger.debug("master: a plan no longer waited for is dropped (%s)", job.what)
            return
        self.job = None
        self.record.planning_s += job.seconds
        if self.ended():
            return
        if job.error is not None:
            sent = "the vehicles stand at their bases" if self.started_at else "no order was sent"
            self.end(LiveOutcome.REFUSED, f"master: no plan {job.what}: {job.error}; {sent}")
            return
        ready: ReadyPlan = job.result
        self._log_planned(job.what, ready.verified, job.seconds)
        if job.context[0] == "start":
            self._adopt(ready, first=True)
            self.maybe_begin()
            return
        _, start, goal = job.context
        views = self.views
        if moved_since(self.graph, views, start):
            self.goal = goal  # they moved meanwhile (a restart): plan again from where they stand
            self._maybe_replan()
            return
        self.record.replans += 1
        self.write("replan", goal=self.track.name(goal))
        self._adopt(ready, first=False)
        for v in range(len(views)):
            self.desk.send(v, 0, self.rule.released[v])
        self._check_end()

    def _adopt(self, ready: ReadyPlan, *, first: bool) -> None:
        """Take a new plan: paths, release rule, order elements, each path's first ``sequenceId``."""
        verified, plan = ready.verified, ready.releases
        self.verified = verified
        self.limits = verified.schedule.limits
        self.plan_goal = verified.schedule.route.goal
        self.rule = ready.rule
        for v, view in enumerate(self.views):
            view.adopt(plan.paths[v], offset=ready.offsets[v], elements=ready.elements[v], first=first)
        record = {
            "event": "plan",
            **provenance(verified.schedule, self.asked),
            "planned_s": plan.planned_duration,
            "nodes": [len(p.nodes) for p in plan.paths],
        }
        if first:  # logged with the first order, where the run's time starts
            self.record.planned_s = plan.planned_duration
            self.record.provenance = provenance(verified.schedule, self.asked)
            self.first_plan = record
        else:
            self.log.write({"t": self.now(), **record})

    # ----------------------------------------------------------------- the start
    def maybe_begin(self) -> None:
        """The first orders, once the plan is made, the broker there and every vehicle at its start.

        What else comes first is :func:`~trajgen.live.start_check.start_decision`'s.
        """
        if self.started_at is not None or self.ended() or self.verified is None or self.job is not None:
            return
        if self.record.broker_at is None:
            return
        views = self.views
        starts = [path_place(self.graph, view.path, 0, 0.0) for view in views]
        decision = start_decision(
            self.graph,
            self.track,
            views,
            starts,
            separation=self.scenario.limits.min_separation,
            planned_from=self.planned_from,
            goal_pending=self.goal is not None,
        )
        for v in decision.off:
            at, start = self.track.name(views[v].place), self.track.name(starts[v])
            self.write("off-start", vehicle=views[v].name, at=at, start=start)
            name = views[v].name
            said.warning("master: %s stands at %s, not at %s where the plan starts it", name, at, start)
        if decision.action == "cancel":
            for v in decision.vehicles:
                views[v].cancelled_order = views[v].foreign
                self.desk.cancel(v, decision.why, again=decision.again)
        elif decision.action == "refuse":
            self.end(LiveOutcome.REFUSED, decision.why)
        elif decision.action == "plan":
            self._plan_from(decision.places)
        elif decision.action == "begin":
            self.record.started_at = self.clock.now()
            self._log_first_plan()
            for v in range(len(views)):
                self.desk.send(v, 0, self.rule.released[v])

    def _plan_from(self, places) -> None:
        """Plan from where the vehicles stand (before any order), to the plan's goal (or a new one)."""
        track = self.track
        goal, self.goal = (self.goal if self.goal is not None else self.plan_goal), None
        try:
            scenario = dataclasses.replace(self.scenario, start=track.start_of(places), goal=goal)
        except InputError as error:
            why = f"master: no plan starts where the vehicles stand: {error}; no order was sent"
            self.end(LiveOutcome.REFUSED, why)
            return
        self.planned_from = places
        self._plan_scenario(scenario, f"from where the vehicles stand {track.name(track.start_of(places))}")

    def _take_place(self, v: int, state) -> None:
        """Before the run: where the vehicle says it is, whether it drives, and an earlier run's order."""
        view = self.views[v]
        before, unplaced = view.place, view.unplaced
        place = view.take_place(self.graph, state, self.desk.order_ids[v])
        if view.unplaced is not None and view.unplaced != unplaced:
            self.write("unplaced", vehicle=view.name, reason=view.unplaced)
            said.warning("master: %s reports no place on the track: %s", view.name, view.unplaced)
        if place is None:
            return
        if before is None or not same_place(self.graph, place, before):
            self.write("place", vehicle=view.name, at=self.track.name(place), driving=state.driving)
        self._note_place(v, place)

    def _note_place(self, v: int, place) -> None:
        """A vehicle's latest reported place; the closest approach to every other's."""
        self.views[v].place = place
        self.record.near(self.graph, place, [other.place for w, other in enumerate(self.views) if w != v])

    def _log_first_plan(self) -> None:
        """The first plan's record, at the run's time 0, with the waits before it (once)."""
        if self.first_plan is not None:
            self.log.write({"t": 0.0, **self.first_plan, **self.record.waits()})
            self.first_plan = None

    # ----------------------------------------------------------------- what comes in
    def connected(self) -> None:
        """The broker accepted the master's connection (the first, or again after a loss)."""
        if self.record.broker_at is None:
            self.record.broker_at = self.clock.now()
            self.maybe_begin()
        elif self.started_at is not None and not self.stopping:  # the broker restarted
            for v in range(len(self.views)):
                self.desk.resend(v)

    def link_changed(self, state, text: str) -> None:
        """The master's link said ``text`` of entering ``state`` (a LinkState)."""
        self.write("broker", state=state.value, detail=text)

    def ignore(self, topic: str, reason: str, vehicle: str | None = None) -> None:
        """A message that cannot be read or trusted: logged, counted, said."""
        self.record.ignored += 1
        said.warning("master: ignored a message on %s: %s", topic, reason)
        self.write("ignored", topic=topic, vehicle=vehicle, reason=reason)

    def take_connection(self, v: int, message) -> None:
        """Vehicle ``v``'s ``connection`` message (vda5050 Connection)."""
        view = self.views[v]
        online = message.connection_state.value == "ONLINE"
        if not view.connection(online, running=self.started_at is not None):
            return
        self.write("connection", vehicle=view.name, state=message.connection_state.value)
        if online:
            said.info("master: %s is online", view.name)
        elif view.at_goal() or self.stopping:
            said.info("master: %s is %s", view.name, message.connection_state.value)
        else:
            said.warning("master: %s is %s: no base is released", view.name, message.connection_state.value)

    def take_state(self, v: int, topic: str, state, taken: float) -> None:
        """Vehicle ``v``'s ``state`` (vda5050 State), taken at ``taken`` (``time.perf_counter``)."""
        view = self.views[v]
        if view.state_header is not None and state.header_id <= view.state_header:
            self.ignore(topic, f"headerId {state.header_id} is not after {view.state_header}", view.name)
            return
        view.state_header = state.header_id
        view.heard = True
        for kind, description in view.new_errors(state):  # an order it refused, say: each said once
            said.warning("master: %s reports %s: %s", view.name, kind, description)
            self.write("vehicle-error", vehicle=view.name, type=kind, description=description)
        if view.cancelled is not None and not view.told:
            view.told = any(action.action_id == view.cancelled for action in state.action_states)
        if self.started_at is None:  # where it stands decides the first orders
            self._take_place(v, state)
            self.maybe_begin()
            return
        # back online without its order, or without it all of a sudden (restarted faster than the
        # broker saw it go): its order is gone, plan again from where it stands
        lost = view.rejoined or (view.taken and view.restart is None)
        view.rejoined = False
        if lost and not state.order_id and (state.agv_position is not None or state.last_node_id):
            self._recover(v, state, topic)
            return
        view.taken = state.order_id == self.desk.order_ids[v] and state.order_update_id >= view.plan_update
        if not view.taken or state.order_update_id < view.update:
            view.driving = state.driving
            self._lacking(v, state)
            return
        view.resend_after = RESEND_INTERVAL_S
        view.lacking_since = None
        j = view.base_node(state, self.rule.released[v])
        if j is None:
            self._off_plan(
                v,
                f"its last node {state.last_node_id!r} (sequenceId {state.last_node_sequence_id}) is not a "
                "node of its released base",
            )
            return
        if view.off_plan is not None:
            view.off_plan = view.off_plan_since = None
            self.write("on-plan", vehicle=view.name)
            said.warning("master: %s is back on its plan", view.name)
        view.node = max(view.node, j)
        view.driving = state.driving
        self._note_place(v, path_place(self.graph, view.path, j, state.distance_since_last_node or 0.0))
        self.log.write(view.state_record(state, j, self.now()))
        if self._release():
            self.record.latencies.append(time.perf_counter() - taken)
        self._check_end()

    def _lacking(self, v: int, state) -> None:
        """A state without the latest order: send it again (backing off), give the vehicle up in time."""
        view = self.views[v]
        if view.restart is not None or self.stopping:  # restarted: its new order comes with the re-plan
            return
        self.desk.resend_if_due(v, state)
        if view.lacking_since is None:
            view.lacking_since = self.clock.now()
        elif self.clock.now() - view.lacking_since >= self.give_up_after:
            why = f"master: {view.name} {not_taken_message(state, self.give_up_after)}"
            self.end(LiveOutcome.ORDER_NOT_TAKEN, why)

    def _off_plan(self, v: int, why: str) -> None:
        """A state that puts its vehicle off its plan: nothing is released to anyone until it is back."""
        view = self.views[v]
        if view.off_plan != why:
            view.off_plan = why
            self.write("off-plan", vehicle=view.name, reason=why)
            said.warning("master: %s stands off its plan (%s): nothing is released", view.name, why)
        if view.off_plan_since is None:
            view.off_plan_since = self.clock.now()
        elif self.clock.now() - view.off_plan_since >= self.give_up_after:
            self.end(
                LiveOutcome.REFUSED,
                f"master: {view.name} stood off its plan for {self.give_up_after:g} s of the run ({why}); "
                "nothing was released meanwhile",
            )

    # ----------------------------------------------------------------- releases
    def _holding(self) -> bool:
        """Whether what the vehicles report holds every release: offline, unheard, off plan, lacking."""
        return any(
            (view.online is False and not view.at_goal())
            or view.rejoined
            or not view.taken
            or view.off_plan is not None
            for view in self.views
        )

    def _release(self) -> int:
        """Take the nodes reached into the rule and send the releases that follow; their count."""
        if self.goal is not None or self.job is not None:
            self._maybe_replan()
            return 0
        if self.stopping or self._holding():
            return 0
        count = 0
        for v, view in enumerate(self.views):
            if view.node > self.rule.reached[v]:
                for vehicle, old, new in self.rule.reach(v, view.node):
                    self.desk.send(vehicle, old, new)
                    count += 1
        return count

    def _check_end(self) -> None:
        if (
            self.goal is None
            and self.job is None
            and self.started_at is not None
            and all(view.at_goal() and not view.driving for view in self.views)
        ):
            if not self.done.is_set():
                self.record.end_time = self.clock.now()
            self.done.set()

    # ----------------------------------------------------------------- goals and restarts
    def request_goal(self, goal) -> None:
        """A new goal: the vehicles stop at their bases, then are re-planned from there.

        Before the first orders, the first plan is made for it.

        Raises
        ------
        InputError
            ``goal`` is not on the track, or leaves the vehicles closer than the separation.
        """
        goal = live_goal(self.graph, goal, len(self.names))
        refusal = self.track.goal_refusal(goal, self.limits.min_separation)
        if refusal is not None:
            raise InputError(f"{refusal} (the separation the plan keeps)")
        self.goal = goal
        self.done.clear()
        self.write("goal", goal=self.track.name(goal))
        said.info("master: new goal %s: holding every vehicle at its base", self.track.name(goal))
        if self.started_at is None:
            self.maybe_begin()
        else:
            self._maybe_replan()

    def _recover(self, v: int, state, topic: str) -> None:
        """A vehicle back without its order (restarted): hold the others, re-plan from where all stand."""
        view = self.views[v]
        try:
            view.restart = restart_place(self.graph, state)
        except InputError as error:
            self.ignore(topic, f"back without its order at no place on the track: {error}", view.name)
            return
        view.driving = state.driving
        self._note_place(v, view.restart)
        if self.goal is None:
            self.goal = self.plan_goal
        at = self.track.name(view.restart)
        self.write("restart", vehicle=view.name, at=at)
        said.warning("master: %s is back without its order, at %s: re-planning", view.name, at)
        self._maybe_replan()

    def _maybe_replan(self) -> None:
        """Plan from where the vehicles stand, once every one stands at its base (or where it restarted)."""
        if self.job is not None or self.goal is None or self.ended():
            return
        standing = replan_start(self.graph, self.views, self.rule.released)
        if standing is None:
            return
        start, offsets = standing
        goal, self.goal = self.goal, None
        track, limits, method, names = self.track, self.limits, self.method, self.names
        origin = track.start_of(start)
        self._plan(
            lambda: track.plan_from_rest(limits, origin, goal, method=method, margin=0.0, names=names),
            what=f"from {track.name(origin)} to {track.name(goal)}",
            context=("replan", start, goal),
            offsets=offsets,
        )

    def drop_plan(self) -> None:
        """A plan still being made is never used (the run is ending)."""
        self.job = None

    # ----------------------------------------------------------------- the stop
    def interrupt(self, reason: str, *, linked: bool) -> tuple:
        """Stop the run now: release nothing more; ``cancelOrder`` to each vehicle holding an order.

        ``linked``: the link is up (else nothing can be sent). Returns the names of the vehicles sent
        ``cancelOrder``.
        """
        if self.done.is_set() or self.stopping:
            return ()
        self.stopping = True
        held = [v for v, view in enumerate(self.views) if view.order is not None or view.foreign is not None]
        names = tuple(self.names[v] for v in held) if linked else ()
        for v in held if linked else ():
            self.desk.cancel(v, f"the run was stopped ({reason})")
        self.write("stop", reason=reason, cancelled=list(names))
        self.end(LiveOutcome.INTERRUPTED, reason)
        return names

    def cancels_shown(self, *, linked: bool) -> bool:
        """Whether every vehicle sent ``cancelOrder`` shows it; sends it again where due (``linked``)."""
        return self.desk.cancels_shown(linked=linked, every=CANCEL_RESEND_S)

    # ----------------------------------------------------------------- the result
    def result(self, link, broker_url: str) -> LiveRun:
        """The run so far (see :class:`LiveRun`); logs its end (``link``: the master's BrokerLink)."""
        if self.done.is_set():
            outcome = LiveOutcome.GOALS_REACHED
        elif link.failed.is_set():
            outcome = LiveOutcome.BROKER_FAILED
        else:
            outcome = self.outcome if self.outcome is not None else LiveOutcome.TIMED_OUT
        self._log_first_plan()
        why = self.why if outcome is self.outcome else None
        if outcome is LiveOutcome.INTERRUPTED:
            why = stop_message(self.views, self.why)
        if outcome is LiveOutcome.TIMED_OUT and self.started_at is None and link.ever_connected:
            planning = None
            if self.verified is None or self.job is not None:
                planning = self.job.what if self.job is not None else "the scenario's start"
            why = f"master: no order was sent: {not_begun(self.views, planning)}"
        run = self.record.live_run(
            outcome,
            now=self.clock.now(),
            orders=(self.desk.sent, self.desk.resent),
            why=why,
            link=link,
            broker_url=broker_url,
            views=self.views,
        )
        end = {"t": self.now(), "event": "end", "outcome": outcome.value, "makespan_s": run.makespan}
        end["closest_m"] = run.summary()["closest_m"]
        if run.error is not None:
            end["error"] = run.error
        self.log.write(end)
        return run
