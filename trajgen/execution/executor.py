"""The online executor: keeps the verified plan's paths and its order at every conflict, lets time stretch.

Each control cycle :meth:`Executor.step` takes every vehicle's measured state
and returns their setpoints for the end of the cycle. What the plan fixes is
kept: each vehicle's path (:mod:`trajgen.model.paths`) and, at every conflict of
the coordination diagram of each pair of vehicles, who passes first
(:mod:`trajgen.execution.conflicts`).
Time is free:

* **Frontier.** Each cycle each vehicle gets the farthest travel it may come
  to rest at: short of every conflict it follows, with any other vehicle, where
  its leader could still come to rest (from the leader's earliest rest point on).
* **Motion** (:mod:`trajgen.execution.motion`). A vehicle on time follows the plan
  while its service braking ends before its frontier; once it departs (a stop,
  a slow drive, a lag, a jump, a frontier that binds), Ruckig drives it
  time-optimally to rest at its next reversal or its frontier, recomputed every
  cycle, so a waiting follower starts the moment its leader moves on.
* **Safety** (:mod:`trajgen.execution.safety_guard`). The braking invariant is checked
  every cycle, independently: a follower holds where its next setpoint would
  break it, and if nothing can be certified both brake hard (reported).
* **Only a goal change re-plans** (:mod:`trajgen.execution.goals`): both brake to
  rest, then the planner plans from where they stand.

The argument (separation, no deadlock, what a stop costs) is in docs/online.md.
"""

from __future__ import annotations

import collections
import dataclasses
import logging
import math
import warnings
from collections.abc import Sequence

from limits import Limits
from topology import Configuration
from trajgen.errors import InputError, ScheduleError, TrajgenError
from trajgen.execution.braking_check import PathState
from trajgen.execution.conflicts import PlanConflicts
from trajgen.execution.locate import locate_on_path
from trajgen.execution.messages import (
    PERIOD_RANGE,
    Command,
    Event,
    GoalDecision,
    Mode,
    Setpoint,
    VehicleState,
    checked_names,
    checked_number,
    checked_period,
)
from trajgen.execution.motion import AT_REST, VehicleMotion
from trajgen.execution.safety_guard import SafetyGuard
from trajgen.execution.tracks import execution_track
from trajgen.model.coordination import CoordinationDiagram, earliest_rest, stopping_distance
from trajgen.model.graph_vehicle_path import GraphVehiclePath
from trajgen.model.paths import VehiclePath
from trajgen.model.summary import both_or_all
from trajgen.scenario.naming import check_vehicle_index
from trajgen.verification import VerifiedSchedule, require_verified
from trajgen.verification.braking_rule import BRAKING_RULE_TOLERANCE

__all__ = ["PERIOD_RANGE", "Command", "Event", "Executor", "GoalDecision", "Mode", "Setpoint", "VehicleState"]

logger = logging.getLogger(__name__)

#: A vehicle within this travel of a point is at it, metres.
_AT = 1e-6


class Executor:
    """Plays a verified schedule in closed loop, keeping its paths and its order, letting time stretch.

    Parameters
    ----------
    verified : VerifiedSchedule
        The plan (from :func:`~trajgen.execution.goals.schedule_for_execution`, which keeps the clearance
        the margins need).
    period : float, optional
        Control period, seconds (0.002 to 0.1).
    min_separation : float or None, optional
        The separation to keep, metres; ``None``: the schedule's.
    position_tolerance, velocity_tolerance : float, optional
        How far a measured state may be from the setpoints (m, m/s) and still be on them.
    position_margin : float, optional
        Metres the conflicts keep beyond the separation: the largest position correction (a
        ``jump``) absorbed without braking.
    latency : float, optional
        How late a drive may follow its setpoints, seconds: a vehicle within the tolerances of any
        setpoint of that window is on them.
    names : tuple of str, optional
        The vehicles' names, one per vehicle, as the events call them (default "vehicle 1", ...).
    """

    def __init__(
        self,
        verified: VerifiedSchedule,
        *,
        period: float = 0.01,
        min_separation: float | None = None,
        position_tolerance: float = 0.05,
        velocity_tolerance: float = 0.05,
        position_margin: float = 0.05,
        latency: float = 0.2,
        names: tuple[str, ...] | None = None,
    ) -> None:
        verified = require_verified(verified, "Executor")
        schedule = verified.schedule
        self.names = checked_names(names, schedule.limits.count)
        period = checked_period(period)
        self.position_tolerance = checked_number(position_tolerance, "position_tolerance (m)")
        self.velocity_tolerance = checked_number(velocity_tolerance, "velocity_tolerance (m/s)")
        self.latency = checked_number(latency, "latency (s)")
        self.position_margin = checked_number(position_margin, "position_margin (m)", zero=True)
        if min_separation is None:
            min_separation = schedule.limits.min_separation
        if not (
            isinstance(min_separation, (int, float))
            and math.isfinite(min_separation)
            and 0.0 <= min_separation <= schedule.limits.min_separation
        ):
            raise InputError(
                "min_separation must be between 0 m and the schedule's "
                f"{schedule.limits.min_separation!r} m, got {min_separation!r}"
            )
        self._track = execution_track(schedule)
        #: The track: a junction's StarGraph, or a TrackGraph.
        self.graph = self._track.graph
        vehicles = schedule.limits.vehicles
        if not schedule.jerk_limited:
            # a plan that does not limit jerk (toppra) changes its acceleration at once: re-timed and
            # braking, its vehicles do so too, or a hold from a high acceleration would overspeed
            vehicles = tuple(
                dataclasses.replace(v, max_jerk=max(v.max_jerk, v.max_acceleration / period))
                for v in vehicles
            )
        #: The limits the executor drives within: the schedule's (with a jerk of ``max_acceleration /
        #: period`` for a plan that does not limit jerk) and the separation it keeps.
        self.limits: Limits = Limits(vehicles, float(min_separation))
        self.period = period
        self._guard = SafetyGuard(self.limits, self.graph)
        count = self.limits.count
        self._motions = tuple(VehicleMotion(vehicle) for vehicle in self.limits.vehicles)
        self._emergency = tuple(v.emergency_braking for v in self.limits.vehicles)
        window = math.ceil(self.latency / period) + 1
        self._recent = tuple(collections.deque(maxlen=window) for _ in range(count))
        self._time = 0.0
        self.events: list[Event] = []
        self.replans = 0
        self.rejected_goals = 0
        self.emergency_brakes = 0
        self.holds = 0
        self._next_goal: Configuration | None = None
        self._frontiers = (math.inf,) * count
        self._rebased = [-math.inf] * count
        self._load(verified, axis_start=None, orientation=(None,) * count)

    def _load(self, verified: VerifiedSchedule, *, axis_start, orientation) -> None:
        """Take ``verified`` as the plan: its paths, conflicts and clock; both vehicles on it.

        ``axis_start`` and ``orientation``: each vehicle's axis value and ``(leg, ds / d axis)`` where it
        stands, so the new paths continue its own axis (``None``: the plan's).
        """
        schedule = verified.schedule
        self.schedule = schedule
        self._route = schedule.route
        self._goal = schedule.route.goal
        loaded = self._track.load(verified, axis_start=axis_start, orientation=orientation)
        self._plan = loaded.player
        count = self.limits.count
        self._plan_axis0 = [self._plan.state(v, 0.0)[0] for v in range(count)]
        self._paths = loaded.paths
        # the plan's axis grows in each vehicle's first move (+1 heading at the start); the paths keep the
        # vehicles' own axes, which may run the other way after a re-plan
        self._axis_sign = [p.headings[0] if p.headings else 1 for p in self._paths]
        self._axis_base = [p.axis(0.0) for p in self._paths]
        separation = self.limits.min_separation + self.position_margin
        self._conflicts = PlanConflicts(schedule, loaded.diagram_paths, loaded.times, separation)
        self._plan_time = 0.0
        self._on_plan = [True] * count
        self._command = [PathState(0.0, 0.0, 0.0) for _ in range(count)]
        self._travel = [0.0] * count
        for recent in self._recent:
            recent.clear()
        self._mode = Mode.FOLLOWING

    # -- state -----------------------------------------------------------------------------------
    @property
    def mode(self) -> Mode:
        """What the executor is doing now."""
        return self._mode

    @property
    def time(self) -> float:
        """Seconds since the executor started (cycles stepped times the period)."""
        return self._time

    @property
    def route(self):
        """The route being driven (a Route, or a GraphRoute): the plan's (a new goal's after a re-plan)."""
        return self._route

    @property
    def paths(self) -> tuple[VehiclePath, ...] | tuple[GraphVehiclePath, ...]:
        """Every vehicle's path of the plan, in travel coordinates."""
        return self._paths

    @property
    def diagrams(self) -> tuple[tuple[tuple[int, int], CoordinationDiagram], ...]:
        """The plan's coordination diagram of each pair of vehicles: ``((i, j), diagram)``."""
        return self._conflicts.diagrams

    @property
    def goal(self):
        """The goal the vehicles are driving to (a Configuration, or an EdgePoint each on a track graph)."""
        return self._goal

    @property
    def travel(self) -> tuple[float, ...]:
        """Each vehicle's measured travel along its path at the last cycle, metres."""
        return tuple(self._travel)

    @property
    def axis_signs(self) -> tuple[int, ...]:
        """Each vehicle's own axis against the plan's (+1 or -1): the plan's velocity times this is its."""
        return tuple(self._axis_sign)

    @property
    def frontiers(self) -> tuple[float, ...]:
        """Each vehicle's frontier at the last cycle, metres of its travel (``inf``: none binds it)."""
        return self._frontiers

    def on_plan(self, vehicle: int) -> bool:
        """Whether ``vehicle`` (its index) still follows the plan's clock."""
        return self._on_plan[vehicle]

    # -- requests --------------------------------------------------------------------------------
    def request_goal(self, vehicle: int, position) -> GoalDecision:
        """A new goal for ``vehicle`` (its index, 0 for vehicle 1): taken once all rest, or refused with why.

        ``position``: a :class:`~topology.Position` on a junction; on a track graph an
        :class:`~topology.EdgePoint`, ``"EDGE:s"`` or a node's name.
        """
        check_vehicle_index(vehicle, self.limits.count)
        try:
            candidate = self._track.goal_with(self._next_goal or self._goal, vehicle, position)
        except InputError as error:
            return self._refuse(f"goal {position} of {self.names[vehicle]}: {error}")
        required = self.limits.min_separation + 2.0 * self.position_margin
        reason = self._track.goal_refusal(candidate, required)
        if reason is not None:
            why = "separation + twice the position margin: each vehicle may stand that far off its goal"
            return self._refuse(f"{self.names[vehicle]}: {reason} ({why})")
        self._next_goal = candidate
        self._log(
            "goal-accepted",
            f"new goal {self._track.name(candidate[vehicle])} for {self.names[vehicle]}: "
            f"{both_or_all(self.limits.count)} stop, then re-plan",
        )
        return GoalDecision(True)

    def request_speed_limit(self, vehicle: int, speed: float) -> None:
        """Limit ``vehicle``'s speed to ``speed`` m/s (at most its ``max_velocity``) from the next cycle."""
        check_vehicle_index(vehicle, self.limits.count)
        top = self.limits.vehicles[vehicle].max_velocity
        if not (isinstance(speed, (int, float)) and math.isfinite(speed) and 0.0 < speed <= top):
            raise InputError(
                f"speed limit of vehicle {vehicle + 1} must be > 0 and <= {top!r} m/s, got {speed!r}"
            )
        self._motions[vehicle].set_speed_limit(float(speed))
        self._leave_plan(vehicle, f"speed limit {speed:g} m/s")
        self._log("speed-limit", f"{self.names[vehicle]} held to {speed:g} m/s")

    # -- the cycle -------------------------------------------------------------------------------
    def step(self, states: Sequence[VehicleState], *more: VehicleState) -> Command:
        """One control cycle: the measured states now (one per vehicle), the setpoints one period later.

        ``step(first, second)``, the form before 0.7, is deprecated: pass one sequence.

        Raises
        ------
        InputError
            Not one VehicleState per vehicle, or a state off the track (naming the vehicle).
        """
        if more:
            warnings.warn(
                "Executor.step(first, second) is deprecated since trajgen 0.7: pass the states as one "
                "sequence, step((first, second))",
                DeprecationWarning,
                stacklevel=2,
            )
            states = (states, *more)
        if isinstance(states, VehicleState | str) or not isinstance(states, Sequence):
            raise InputError(
                f"states must be a sequence of VehicleStates, one per vehicle, got {states!r:.80}"
            )
        if len(states) != self.limits.count:
            raise InputError(f"states: expected {self.limits.count}, one per vehicle, got {len(states)}")
        measured = tuple(self._track.check_state(state, k) for k, state in enumerate(states, start=1))
        along = self._locate(measured)
        if along is None:
            return self._emergency_stop(measured, "a vehicle is off its path beyond the margins")
        count = self.limits.count
        for v in range(count):
            if self._departed(v, along[v]):
                self._leave_plan(v, f"{self.names[v]} is off its setpoints", rebase=along[v])
        if self._next_goal is not None:
            return self._stop_for_goal(measured, along)
        earliest = [
            earliest_rest(s.p, s.v, self._emergency[v], self._paths[v].next_stop(s.p, 0.0))
            for v, s in enumerate(along)
        ]
        frontiers = self._conflicts.frontiers(earliest)
        self._frontiers = frontiers
        proposals = [self._propose(v, frontiers[v]) for v in range(count)]
        if any(self._on_plan):
            self._plan_time += self.period
        return self._issue(measured, along, proposals)

    # -- motion ----------------------------------------------------------------------------------
    def _propose(self, v: int, frontier: float) -> tuple[PathState, float, float | None]:
        """The next state of ``v`` (travel), its jerk, and its axis setpoint if it is the plan's."""
        path = self._paths[v]
        if self._on_plan[v]:
            axis, velocity, acceleration, jerk = self._plan_state(v, self._plan_time + self.period)
            p = path.travel_at_axis(axis, self._command[v].p, velocity)
            heading = path.heading(p)
            state = PathState(p, heading * velocity, heading * acceleration)
            # the plan itself ends at the path's end; it brakes as it was planned to, which the verifier
            # certified to BRAKING_RULE_TOLERANCE: within the margin the conflicts keep, if there is one
            if self._stops_by(
                v,
                state,
                frontier + max(_AT, min(BRAKING_RULE_TOLERANCE, self.position_margin)),
                jerk_limited=True,
            ):
                return state, heading * jerk, axis
            self._leave_plan(v, f"{self.names[v]} meets its frontier at {frontier:.3f} m")
        limit = min(frontier, path.length)
        command = self._command[v]
        motion = self._motions[v]
        at_rest = command.v <= AT_REST and abs(command.a) <= AT_REST
        target = min(limit, path.next_stop(command.p, _AT if at_rest else 0.0))
        if target <= command.p + _AT and at_rest:
            return PathState(command.p, 0.0, 0.0), 0.0, None  # waits at its frontier or reversal
        if not self._stops_by(v, command, target):
            state, jerk = motion.brake(command, self.period)  # it can no longer stop there: as soon as it can
            return state, jerk, None
        state, jerk = motion.toward(command, target, self.period)
        if motion.overshoots(target):
            state, jerk = motion.brake(command, self.period)
        return state, jerk, None

    def _plan_state(self, v: int, t: float) -> tuple[float, float, float, float]:
        """The plan's axis (in the vehicle's own axis), velocity, acceleration and jerk at ``t``."""
        axis, velocity, acceleration, jerk = self._plan.state(v, t)
        sign = self._axis_sign[v]
        moved = self._axis_base[v] + sign * (axis - self._plan_axis0[v])
        return moved, sign * velocity, sign * acceleration, sign * jerk

    def _stops_by(self, v: int, state: PathState, limit: float, *, jerk_limited: bool = True) -> bool:
        """Whether service braking from ``state`` comes to rest by travel ``limit``.

        ``jerk_limited=False``: the braking of a plan that does not limit jerk (``v^2 / 2 A``).
        """
        if limit == math.inf:
            return True
        distance = stopping_distance(state.v, state.a, self.limits.vehicles[v], jerk_limited=jerk_limited)
        return state.p + distance <= limit + 1e-9

    def _issue(self, measured, along, proposals) -> Command:
        """Certify the proposals (holding followers or braking hard if need be) and issue them."""
        required = self._guard.required(measured)
        states = [proposal[0] for proposal in proposals]
        holding = [False] * len(states)
        certified = self._guard.certifies(self._paths, states, along, required)
        if not certified:
            for order in self._hold_orders():
                trial = list(states)
                for v in order:
                    trial[v] = self._motions[v].brake(self._command[v], self.period)[0]
                if self._guard.certifies(self._paths, trial, along, required, hold=True):
                    certified = True
                    for v in order:
                        holding[v] = True
                        proposals[v] = (*self._motions[v].brake(self._command[v], self.period), None)
                        self._leave_plan(v, f"{self.names[v]} holds: the braking check")
                    self.holds += 1
                    break
        if not certified:
            waiting = self._wait_where_they_stand(measured, along, required)
            if waiting is not None:
                return waiting
            return self._emergency_stop(measured, "no setpoints keep the braking invariant")
        return self._emit(proposals, tuple(holding), certified=True)

    def _wait_where_they_stand(self, measured, along, required) -> Command | None:
        """Vehicles at rest short of their setpoints hold where they stand, if that is certified.

        A drive braked to rest before its setpoint (a lag, then an emergency stop) leaves the
        setpoint ahead of it; the check takes the vehicle anywhere between the two, which can be
        closer to the other than either is. Holding it where it stands, and restarting from there,
        is the way out; else the emergency brake would hold both for ever.
        """
        count = self.limits.count
        still = [
            v
            for v in range(count)
            if self._command[v].v <= AT_REST
            and abs(measured[v].velocity) <= self.velocity_tolerance * 0.02
            and abs(self._command[v].p - along[v].p) > 1e-9
        ]
        if not still:
            return None
        trial = [self._motions[v].brake(self._command[v], self.period)[0] for v in range(count)]
        for v in still:
            trial[v] = PathState(along[v].p, 0.0, 0.0)
        if not self._guard.certifies(self._paths, trial, along, required, hold=True):
            return None
        proposals = []
        for v in range(count):
            if v in still:
                reason = f"{self.names[v]} waits where it stands: the braking check"
                self._leave_plan(v, reason, rebase=trial[v])
                proposals.append((self._command[v], 0.0, None))
            else:
                proposals.append((*self._motions[v].brake(self._command[v], self.period), None))
        self.holds += 1
        return self._emit(proposals, (True,) * count, certified=True)

    def _hold_orders(self) -> tuple[tuple[int, ...], ...]:
        """Which vehicles to hold first: each follower of a conflict not yet passed, then those, then all.

        The one with less room to its frontier first: a vehicle that leads now and follows only at a
        later conflict keeps going, its follower waits.
        """
        followers = self._conflicts.followers(self._travel)
        followers.sort(key=lambda v: (self._frontiers[v] - self._travel[v], v))
        orders = [(v,) for v in followers] + [tuple(sorted(followers)), tuple(range(self.limits.count))]
        return tuple(order for order in dict.fromkeys(orders) if order)

    def _emit(self, proposals, holding, *, certified: bool, emergency: bool = False) -> Command:
        self._time += self.period
        setpoints = []
        count = self.limits.count
        for v in range(count):
            state, jerk, axis = proposals[v]
            self._command[v] = state
            leg, s, heading, on_path, branch = self._paths[v].place(state.p)
            if axis is None:
                axis = on_path
            self._recent[v].append((axis, heading * state.v))
            setpoints.append(
                Setpoint(axis, heading * state.v, heading * state.a, heading * jerk, leg, s, branch)
            )
        if self._mode is not Mode.DONE and all(
            self._command[v].p >= self._paths[v].length - _AT
            and self._command[v].v <= AT_REST
            and abs(self._travel[v] - self._paths[v].length) <= self.position_tolerance
            for v in range(count)
        ):
            self._mode = Mode.DONE
            self._log("done", f"{both_or_all(count)} vehicles at their goals")
        return Command(
            self._time,
            tuple(setpoints),
            self._mode,
            holding,
            certified,
            emergency,
            self._frontiers,
        )

    def _emergency_stop(self, measured, reason: str) -> Command:
        """Every vehicle brakes as hard as it can (the plant applies its emergency brakes)."""
        self.emergency_brakes += 1
        self._log("emergency", reason)
        count = self.limits.count
        self._on_plan = [False] * count
        proposals = []
        for v in range(count):
            command = self._command[v]
            proposals.append((*self._motions[v].brake(command, self.period), None))
        if self._mode is Mode.DONE:
            self._mode = Mode.RETIMING
        return self._emit(proposals, (True,) * count, certified=False, emergency=True)

    # -- a new goal ------------------------------------------------------------------------------
    def _stop_for_goal(self, measured, along) -> Command:
        """Every vehicle brakes to rest on its path; once all are, plan from there to the new goal."""
        count = self.limits.count
        if self._mode is not Mode.STOPPING:
            self._on_plan = [False] * count
            self._mode = Mode.STOPPING
        at_rest = all(
            self._command[v].v <= AT_REST and abs(measured[v].velocity) <= self.velocity_tolerance * 0.02
            for v in range(count)
        )
        if at_rest:
            goal, self._next_goal = self._next_goal, None
            start = self._track.start_of(tuple(self._track.position(state) for state in measured))
            try:
                verified = self._track.plan_from_rest(
                    self.limits,
                    start,
                    goal,
                    method=self.schedule.method,
                    margin=self.position_margin,
                    names=self.names,
                )
            except (TrajgenError, ScheduleError) as error:
                self.rejected_goals += 1
                self._log(
                    "goal-refused",
                    f"no plan from {self._track.name(start)} to {self._track.name(goal)}: {error}",
                )
            else:
                # where each vehicle stands (the plan starts there), not its setpoint: no offset carried on
                axes = [self._paths[v].axis(along[v].p) for v in range(count)]
                orientation = [self._track.orientation(self._paths[v], along[v].p) for v in range(count)]
                self.replans += 1
                self._load(verified, axis_start=axes, orientation=orientation)
                kind = self._track.describe(verified.schedule.route)
                self._log(
                    "replan",
                    f"new goal: from {self._track.name(start)} to {self._track.name(goal)}, {kind}, "
                    f"{verified.schedule.duration:.3f} s planned",
                )
                along = self._locate(measured) or along
        proposals = [(*self._motions[v].brake(self._command[v], self.period), None) for v in range(count)]
        if self._mode is Mode.STOPPING:
            return self._emit(proposals, (True,) * count, certified=True)
        return self._issue(measured, along, proposals)

    # -- measurements ----------------------------------------------------------------------------
    def _locate(self, measured) -> tuple[PathState, ...] | None:
        """Every measured state in travel coordinates, or ``None`` if one is off its path."""
        slack = self.position_tolerance + self.position_margin
        out = []
        for v, state in enumerate(measured):
            here = locate_on_path(
                self._track, self._paths[v], state, self._command[v].p, self._travel[v], slack
            )
            if here is None:
                return None
            out.append(here)
            self._travel[v] = here.p
        return tuple(out)

    def _departed(self, v: int, state: PathState) -> bool:
        """Whether ``v`` is off every setpoint of the last ``latency`` seconds (a drive may follow late)."""
        recent = self._recent[v]
        if not recent or self._time - self._rebased[v] < self.latency:
            return False  # a restart shows in the measurements only after the drive's latency
        _, _, heading, axis, _ = self._paths[v].place(state.p)
        velocity = heading * state.v
        tol_p, tol_v = self.position_tolerance, self.velocity_tolerance
        last_axis, last_velocity = recent[-1]
        if abs(axis - last_axis) <= tol_p and abs(velocity - last_velocity) <= tol_v:
            return False  # on the last setpoint: the usual case, checked first
        return not any(abs(axis - q) <= tol_p and abs(velocity - w) <= tol_v for q, w in recent)

    def _leave_plan(self, v: int, reason: str, *, rebase: PathState | None = None) -> None:
        """``v`` leaves the plan's clock for Ruckig; ``rebase``: restart from this measured state."""
        if self._on_plan[v]:
            self._on_plan[v] = False
            self._log("retime", reason)
        if self._mode is Mode.FOLLOWING:
            self._mode = Mode.RETIMING
        if rebase is not None:
            self._command[v] = self._seed(v, rebase)
            self._recent[v].clear()
            self._rebased[v] = self._time

    def _seed(self, v: int, state: PathState) -> PathState:
        """A state to restart from at the measured travel (:meth:`VehicleMotion.restart`)."""
        tip = min(self._paths[v].next_stop(state.p, 0.0), self._frontiers[v])
        return self._motions[v].restart(state, self._command[v], tip, self.velocity_tolerance)

    # -- helpers ---------------------------------------------------------------------------------
    def _refuse(self, reason: str) -> GoalDecision:
        self.rejected_goals += 1
        self._log("goal-refused", reason)
        return GoalDecision(False, reason)

    def _log(self, kind: str, detail: str) -> None:
        self.events.append(Event(self._time, kind, detail))
        logger.info("t=%.3f s %s: %s", self._time, kind, detail)
