"""The live master: drives two VDA 5050 vehicles over MQTT, releasing base by the frontier.

Once the broker and both vehicles are there, it sends each vehicle one order: its
base up to its frontier (the last released node) and a short horizon past it
(:mod:`trajgen.live.orders`). Then it follows the vehicles' states; a vehicle
whose states keep showing it lacks its order ends the run (``ORDER_NOT_TAKEN``).
When a vehicle reports a node reached, the release rule
(:class:`~trajgen.export.vda5050.release.BaseRelease`) may let the base of
either vehicle grow; each growth is an order update (same ``orderId``,
``orderUpdateId`` + 1, stitched at the previous decision point).

What keeps the vehicles apart is the released base, never the timing: a
vehicle claims the track from the last node it reported to its decision point,
the two claims never come closer than the minimum separation, and a claim only
shrinks when its vehicle reports it has moved on. A late, lost or duplicated
message therefore only delays a release; it never makes one unsafe. Messages
that cannot be trusted (malformed, another vehicle's, older than one already
taken, or naming a node the vehicle cannot have reached) are logged and
ignored. While a vehicle is offline (its last will, or OFFLINE) nothing is
released to either vehicle, nor once it is back until its first state says whether it kept its order.
After a broker restart the client reconnects and re-sends every vehicle's
latest order (a vehicle ignores one it already has).

A new goal: no more base is released; once both vehicles stand at their
decision points, the planner plans from there and each vehicle gets an order
update stitched where it stands, with the new path.
On a junction or a track graph alike: what differs (node ids, goals, re-plans, where a
vehicle stands) is the executor's track and :mod:`trajgen.live.places`.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Sequence

import numpy as np

from topology import Configuration, EdgePoint
from trajgen.errors import InputError
from trajgen.execution.tracks import execution_track
from trajgen.export.vda5050.messages import path_node_id
from trajgen.export.vda5050.release import BaseRelease, order_releases
from trajgen.live.clock import RunClock
from trajgen.live.link import BrokerLink
from trajgen.live.mqtt import BrokerSettings, Topic, VehicleIdentity, make_client
from trajgen.live.orders import horizon_length, order_message, path_elements
from trajgen.live.outcome import LiveOutcome, LiveRun
from trajgen.live.places import live_goal, restart_place
from trajgen.live.runlog import RunLog
from trajgen.live.view import (
    GIVE_UP_AFTER_S,
    NOT_TAKEN_AFTER,
    NOT_TAKEN_WHY,
    RESEND_INTERVAL_S,
    RESEND_MAX_S,
    VehicleView,
    not_taken_message,
    reported_order,
    run_failure,
)
from trajgen.methods import METHODS
from trajgen.model.summary import provenance
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["RELEASE_SPACING", "LiveMaster", "LiveOutcome", "LiveRun"]

logger = logging.getLogger(__name__)

#: Longest edge of the paths sent by default, metres.
RELEASE_SPACING = 0.25


class LiveMaster:
    """Drive two VDA 5050 vehicles through a verified plan over an MQTT broker.

    Parameters
    ----------
    verified : VerifiedSchedule
        The plan (from :func:`~trajgen.verification.certify`); its route fixes both paths and the
        order at every conflict.
    names : sequence of 2 str
        The vehicles' names (in the run log).
    identities : tuple of 2 VehicleIdentity
    broker : BrokerSettings
    method : TimingMethod or str, optional
        What times a new plan after a goal change (default: the registry's default).
    clock : RunClock, optional
        The run's clock (its time scale must be the vehicles').
    order_id : str
        ``orderId`` prefix: ``<order_id>-<vehicle name>`` (default ``"trajgen"``).
    map_id : str
        ``nodePosition.mapId`` (default ``"trajgen"``).
    log : RunLog, optional
        Where every event is logged (default: a new one, its ``log``).
    spacing : float
        Longest edge of the paths sent, metres (default :data:`RELEASE_SPACING`): the base is released
        node by node, so finer nodes let a vehicle follow the other closely instead of braking early.
    """

    def __init__(
        self,
        verified: VerifiedSchedule,
        names: Sequence[str],
        *,
        identities: tuple[VehicleIdentity, VehicleIdentity],
        broker: BrokerSettings,
        method=None,
        clock: RunClock | None = None,
        order_id: str = "trajgen",
        map_id: str = "trajgen",
        log: RunLog | None = None,
        spacing: float = RELEASE_SPACING,
        give_up_after: float = GIVE_UP_AFTER_S,
    ) -> None:
        verified = require_verified(verified, "LiveMaster")
        self.spacing = spacing
        if len(identities) != 2 or identities[0].topic("") == identities[1].topic(""):
            raise InputError("live vehicles must have two different identities (one topic each)")
        self._track = execution_track(verified.schedule)
        self.graph = self._track.graph
        self.limits = verified.schedule.limits
        self.names = tuple(names)
        self.method = method
        self._asked = METHODS.create(method).name  # as the plans name it (exact after a fallback)
        self._provenance: dict = {}
        self.broker = broker
        self.clock = clock if clock is not None else RunClock()
        self.order_id = order_id
        self.map_id = map_id
        self.log = log if log is not None else RunLog()
        self._horizons = [horizon_length(limits) for limits in self.limits.vehicles]
        self._views = [VehicleView(self.names[v], identities[v]) for v in (0, 1)]
        self._topics = {
            identity.topic(kind): (v, kind)
            for v, identity in enumerate(identities)
            for kind in (Topic.STATE, Topic.CONNECTION)
        }
        self._lock = threading.RLock()
        self._done = threading.Event()
        self._goal: Configuration | tuple[EdgePoint, EdgePoint] | None = None
        self._rule: BaseRelease | None = None
        self._started_at: float | None = None  # run clock at the first orders: the run's time 0
        self._broker_at: float | None = None  # run clock at the first connection to the broker
        self._began_at = 0.0  # run clock at start()
        self._latencies: list[float] = []
        self._counts = {"orders": 0, "resent": 0, "ignored": 0, "replans": 0}
        self._planned = 0.0
        self._end_time = 0.0
        self._first_plan: dict | None = None
        self.give_up_after = give_up_after
        self._gave_up: str | None = None  # why the run ended before its goals (an order not taken)
        self._adopt(verified, first=True)
        self._client = make_client(broker, f"trajgen-master-{identities[0].interface}-{id(self):x}")
        self._client.on_message = self._on_message
        self.link = BrokerLink(self._client, broker, who="master", on_connected=self._connected)

    # ----------------------------------------------------------------- plans and orders
    def _adopt(self, verified: VerifiedSchedule, *, first: bool, fresh=(False, False)) -> None:
        """Take a new plan: paths, release rule, and (after a goal change) the stitch offsets.

        ``fresh``: vehicles restarted without their order; a new order numbers its nodes from 0.
        """
        self._plan_goal = verified.schedule.route.goal
        plan = order_releases(verified, spacing=self.spacing)
        rule = BaseRelease(plan.paths, verified.schedule.limits.min_separation)
        for v, view in enumerate(self._views):
            if not first:
                view.offset = 0 if fresh[v] else view.offset + 2 * view.node
                start = view.arcs[view.node]
            else:
                start = 0.0
            view.path = plan.paths[v]
            view.arcs = [start]
            for edge in view.path.edges:
                view.arcs.append(view.arcs[-1] + edge.length)
            view.node = 0
            view.elements = path_elements(self.graph, view, map_id=self.map_id)
        self._rule = rule
        if first:
            self._planned = plan.planned_duration
            self._provenance = provenance(verified.schedule, self._asked)
        record = {
            "event": "plan",
            **provenance(verified.schedule, self._asked),
            "planned_s": plan.planned_duration,
            "nodes": [len(p.nodes) for p in plan.paths],
        }
        if first:  # logged with the first order, where the run's time starts
            self._first_plan = record
        else:
            self.log.write({"t": self._now(), **record})

    def _now(self) -> float:
        """Seconds of the run: since the first order was sent (0 before it)."""
        return 0.0 if self._started_at is None else self.clock.now() - self._started_at

    def _maybe_begin(self) -> None:
        """The first orders, once the broker and both vehicles are there: the run's time starts."""
        if self._started_at is not None or self._broker_at is None or not all(v.heard for v in self._views):
            return
        self._started_at = self.clock.now()
        self._log_first_plan()
        for v in (0, 1):
            self._send(v, 0, self._rule.released[v])

    def _waits(self) -> dict:
        """Run seconds from the master's start to the broker, and from there to both vehicles heard."""
        broker, began = self._broker_at, self._started_at
        return {
            "broker_wait_s": None if broker is None else broker - self._began_at,
            "vehicle_wait_s": None if began is None or broker is None else began - broker,
        }

    def _log_first_plan(self) -> None:
        """The first plan's record, at the run's time 0, with the waits before it (once)."""
        if self._first_plan is not None:
            self.log.write({"t": 0.0, **self._first_plan, **self._waits()})
            self._first_plan = None

    def _publish(self, v: int, payload: bytes, *, resent: bool, record: dict) -> None:
        view = self._views[v]
        self._client.publish(view.identity.topic(Topic.ORDER), payload, qos=0)
        view.sent_at = time.monotonic()
        self._counts["orders"] += 1
        self._counts["resent"] += resent
        self.log.write({"t": self._now(), "event": "order", "vehicle": view.name, "resent": resent, **record})

    def _send(self, v: int, first: int, decision_point: int) -> None:
        view = self._views[v]
        order = order_message(
            view,
            first=first,
            decision_point=decision_point,
            horizon_m=self._horizons[v],
            order_id=f"{self.order_id}-{view.name}",
            timestamp=self.clock.timestamp(),
        )
        view.update += 1
        view.order = order
        view.resend_after = RESEND_INTERVAL_S
        view.lacking_since = None  # a new order: what the vehicle lacked is another
        view.record = {
            "update": view.update,
            "first": first,
            "decision_point": decision_point,
            "frontier_m": view.arcs[decision_point],
        }
        self._publish(v, order.to_json().encode(), resent=False, record=view.record)

    def _resend(self, v: int) -> None:
        """The latest order (update) again, under a new headerId (VDA 5050: one per message)."""
        view = self._views[v]
        if view.order is not None:
            view.header += 1
            header = {"header_id": view.header, "timestamp": self.clock.timestamp()}
            again = view.order.model_copy(update=header)
            self._publish(v, again.to_json().encode(), resent=True, record=view.record)

    # ----------------------------------------------------------------- MQTT
    def _connected(self, client) -> None:
        for topic in self._topics:
            client.subscribe(topic, qos=1)
        with self._lock:
            if self._started_at is None:
                if self._broker_at is None:
                    self._broker_at = self.clock.now()
                self._maybe_begin()
            else:  # reconnected (the broker restarted): the latest orders again
                for v in (0, 1):
                    self._resend(v)

    def _ignore(self, topic: str, reason: str, vehicle: str | None = None) -> None:
        self._counts["ignored"] += 1
        logger.warning("master: ignored a message on %s: %s", topic, reason)
        self.log.write(
            {"t": self._now(), "event": "ignored", "topic": topic, "vehicle": vehicle, "reason": reason}
        )

    def _on_message(self, client, userdata, message) -> None:
        taken = time.perf_counter()
        where = self._topics.get(message.topic)
        try:
            with self._lock:
                if where is None:
                    self._ignore(message.topic, "not a topic of this run's vehicles")
                elif where[1] == Topic.STATE:
                    self._take_state(where[0], message.topic, bytes(message.payload), taken)
                else:
                    self._take_connection(where[0], message.topic, bytes(message.payload))
        except Exception:  # a message must never stop the master: log it, keep the releases as they are
            logger.exception("master: a message on %s raised; ignored", message.topic)

    def _decode(self, v: int, topic: str, payload: bytes, model):
        from vda5050.errors import MessageValidationError
        from vda5050.serialization import decode

        view = self._views[v]
        try:
            message = decode(payload, model)
        except MessageValidationError as error:
            self._ignore(topic, f"malformed: {str(error)[:120]}", view.name)
            return None
        identity = (message.manufacturer, message.serial_number)
        if identity != (view.identity.manufacturer, view.identity.serial_number):
            self._ignore(topic, f"from {identity[0]}/{identity[1]}, not {view.name}", view.name)
            return None
        return message

    def _take_connection(self, v: int, topic: str, payload: bytes) -> None:
        from vda5050.model.connection import Connection

        message = self._decode(v, topic, payload, Connection)
        if message is None:
            return
        view = self._views[v]
        online = message.connection_state.value == "ONLINE"
        if online == view.online:
            return
        back = view.online is False  # None: the first news (a retained message), after the first order
        view.online = online
        self.log.write(
            {
                "t": self._now(),
                "event": "connection",
                "vehicle": view.name,
                "state": message.connection_state.value,
            }
        )
        if online:
            logger.info("master: %s is online", view.name)
            view.state_header = None  # a vehicle that restarted counts its headers afresh
            view.rejoined = back and self._started_at is not None  # its first state: kept its order?
            view.heard = True
            self._maybe_begin()
        elif view.arcs and view.node == len(view.arcs) - 1:
            logger.info("master: %s is %s at its goal", view.name, message.connection_state.value)
        else:
            logger.warning("master: %s is %s: no base is released", view.name, message.connection_state.value)

    def _not_taken(self, view: VehicleView, state) -> None:
        """Say that a vehicle still reports an older order than the one sent (three re-sends)."""
        held = reported_order(state)
        logger.warning(
            "master: %s has not taken its order (it reports %s after 4 sends): %s",
            view.name,
            held,
            NOT_TAKEN_WHY,
        )
        self.log.write({"t": self._now(), "event": "order-not-taken", "vehicle": view.name, "reports": held})

    def _report_errors(self, view: VehicleView, state) -> None:
        """A vehicle's new errors (an order it refused, say), said at once and logged, each once."""
        for kind, description in view.new_errors(state):
            logger.warning("master: %s reports %s: %s", view.name, kind, description)
            record = {
                "event": "vehicle-error",
                "vehicle": view.name,
                "type": kind,
                "description": description,
            }
            self.log.write({"t": self._now(), **record})

    def _take_state(self, v: int, topic: str, payload: bytes, taken: float) -> None:
        from vda5050.model.state import State

        state = self._decode(v, topic, payload, State)
        if state is None:
            return
        view = self._views[v]
        if self._started_at is None:  # it is there: the run begins once the other is too
            view.heard = True
            self._maybe_begin()
            return
        if view.state_header is not None and state.header_id <= view.state_header:
            self._ignore(topic, f"headerId {state.header_id} is not after {view.state_header}", view.name)
            return
        self._report_errors(view, state)
        if view.rejoined:
            view.rejoined = False
            placed = state.agv_position is not None or bool(state.last_node_id)
            if not state.order_id and placed:  # restarted: its order is gone
                self._recover(v, state)
                return
        expected = f"{self.order_id}-{view.name}"
        if state.order_id != expected or state.order_update_id < view.update:
            view.state_header = state.header_id
            if view.restart is not None:  # restarted: its new order comes with the re-plan
                return
            if time.monotonic() - view.sent_at >= view.resend_after:  # it lacks the latest order
                logger.debug("master: %s has not the latest order: sent again", view.name)
                self._resend(v)
                view.resend_after = min(2.0 * view.resend_after, RESEND_MAX_S)
                if view.resend_after == NOT_TAKEN_AFTER:  # said once per order
                    self._not_taken(view, state)
            if view.lacking_since is None:
                view.lacking_since = self.clock.now()
            elif self.clock.now() - view.lacking_since >= self.give_up_after and self._gave_up is None:
                self._gave_up = f"master: {view.name} {not_taken_message(state, self.give_up_after)}"
                logger.error("%s", self._gave_up)
            return
        view.resend_after = RESEND_INTERVAL_S
        view.lacking_since = None
        j = (state.last_node_sequence_id - view.offset) // 2
        if not (
            0 <= j <= self._rule.released[v]
            and (state.last_node_sequence_id - view.offset) % 2 == 0
            and state.last_node_id == self._node_id(v, j)
        ):
            self._ignore(
                topic,
                f"last node {state.last_node_id!r} (sequenceId {state.last_node_sequence_id}) is not a node "
                f"of {view.name}'s base",
                view.name,
            )
            return
        view.state_header = state.header_id
        view.node = max(view.node, j)
        view.driving = state.driving
        self.log.write(view.state_record(state, j, self._now()))
        released = self._release()
        if released:
            self._latencies.append(time.perf_counter() - taken)
        self._check_end()

    def _node_id(self, v: int, j: int) -> str:
        return path_node_id(self.graph, self._views[v].path, j)

    def _release(self) -> int:
        """Take the nodes reached into the rule and send the releases that follow; their count."""
        if self._goal is not None:
            self._maybe_replan()
            return 0
        # offline, or back and its first state not yet in (did it keep its order?): none released
        if not all(view.online is not False and not view.rejoined for view in self._views):
            return 0
        count = 0
        for v, view in enumerate(self._views):
            if view.node > self._rule.reached[v]:
                for vehicle, old, new in self._rule.reach(v, view.node):
                    self._send(vehicle, old, new)
                    count += 1
        return count

    def _check_end(self) -> None:
        if self._goal is None and all(
            view.node == len(view.path.nodes) - 1 and not view.driving for view in self._views
        ):
            if not self._done.is_set():
                self._end_time = self.clock.now()
            self._done.set()

    # ----------------------------------------------------------------- goals
    def request_goal(self, goal) -> None:
        """Ask for a new goal: both vehicles stop at their bases, then are re-planned from there.

        ``goal``: a Configuration on a junction; on a track graph both vehicles' positions
        (``"EDGE:s"``, a node's name, or an EdgePoint).

        Raises
        ------
        InputError
            ``goal`` is not on the track, or leaves the vehicles closer than the separation.
        """
        goal = live_goal(self.graph, goal)
        refusal = self._track.goal_refusal(goal, self.limits.min_separation)
        if refusal is not None:
            raise InputError(f"{refusal} (the separation the plan keeps)")
        with self._lock:
            self._goal = goal
            self._done.clear()
            self.log.write({"t": self._now(), "event": "goal", "goal": self._track.name(goal)})
            logger.info("master: new goal %s: holding both vehicles at their bases", goal)
            self._maybe_replan()

    def _recover(self, v: int, state) -> None:
        """A vehicle back without its order (restarted): hold the other, re-plan from where both stand."""
        view = self._views[v]
        try:
            view.restart = restart_place(self.graph, state)
        except InputError as error:
            topic = view.identity.topic(Topic.STATE)
            self._ignore(topic, f"back without its order at no place on the track: {error}", view.name)
            return
        view.driving = state.driving
        if self._goal is None:
            self._goal = self._plan_goal
        at = self._track.name(view.restart)
        self.log.write({"t": self._now(), "event": "restart", "vehicle": view.name, "at": at})
        logger.warning("master: %s is back without its order, at %s: re-planning", view.name, at)
        self._maybe_replan()

    def _maybe_replan(self) -> None:
        views = self._views
        if not all(
            (view.restart is not None or view.node == self._rule.released[v])
            and not view.driving
            and view.online is not False
            for v, view in enumerate(views)
        ):
            return
        start = self._track.start_of(tuple(view.standing(self.graph) for view in views))
        fresh = (views[0].restart is not None, views[1].restart is not None)
        for view in views:
            view.restart = None
        goal, self._goal = self._goal, None
        verified = self._track.plan_from_rest(
            self.limits, start, goal, method=self.method, margin=0.0, names=self.names
        )
        self._counts["replans"] += 1
        self.log.write({"t": self._now(), "event": "replan", "goal": self._track.name(goal)})
        self._adopt(verified, first=False, fresh=fresh)
        for v in (0, 1):
            self._send(v, 0, self._rule.released[v])
        self._check_end()

    # ----------------------------------------------------------------- running
    def run(self, *, timeout: float) -> LiveRun:
        """Connect, drive both vehicles to their goals, disconnect.

        Parameters
        ----------
        timeout : float
            Seconds of the run after which it ends unfinished.

        Returns
        -------
        LiveRun
            With its ``error`` when it ended early (see :class:`LiveOutcome`).
        """
        self.start()
        try:
            self.wait(timeout=timeout)
        finally:
            self.stop()
        return self.result()

    def start(self) -> LiveMaster:
        """Connect in the background (see :class:`~trajgen.live.BrokerLink`); returns itself at once.

        The first orders go out once the broker and both vehicles are there; an unreachable broker
        is retried until :meth:`wait` ends.
        """
        self._began_at = self.clock.now()
        self.link.start()
        return self

    def wait(self, *, timeout: float) -> bool:
        """Wait until both vehicles stand at their goals or ``timeout`` seconds of the run pass."""
        deadline = self.clock.now() + timeout
        while not self._done.is_set() and not self.link.failed.is_set() and self._gave_up is None:
            left = deadline - self.clock.now()
            if left <= 0.0:
                return False
            self._done.wait(min(self.clock.wall_seconds(left), 0.05))
        return True

    def stop(self) -> None:
        """Disconnect."""
        self.link.close()

    def result(self) -> LiveRun:
        """The run so far (see :class:`LiveRun`); logs its end."""
        with self._lock:
            now = self.clock.now()
            began = self._started_at if self._started_at is not None else now
            outcome = LiveOutcome.GOALS_REACHED if self._done.is_set() else LiveOutcome.TIMED_OUT
            if outcome is LiveOutcome.TIMED_OUT and self.link.failed.is_set():
                outcome = LiveOutcome.BROKER_FAILED
            elif outcome is LiveOutcome.TIMED_OUT and self._gave_up is not None:
                outcome = LiveOutcome.ORDER_NOT_TAKEN
            self._log_first_plan()
            latency = np.array(self._latencies, dtype=float)
            latency.flags.writeable = False
            run = LiveRun(
                outcome,
                (self._end_time if self._done.is_set() else now) - began,
                self._planned,
                self._counts["orders"],
                self._counts["resent"],
                self._counts["ignored"],
                self._counts["replans"],
                latency,
                dict(self._provenance),
                run_failure(
                    outcome,
                    self.link,
                    gave_up=self._gave_up,
                    broker_url=self.broker.url,
                    sent=self._started_at is not None,
                    silent=[view for view in self._views if not view.heard],
                ),
                self._waits(),
            )
            end = {"t": self._now(), "event": "end", "outcome": outcome.value, "makespan_s": run.makespan}
            if run.error is not None:
                end["error"] = run.error
            self.log.write(end)
            return run
