"""The online executor: plays a verified schedule and recovers with Ruckig when reality departs from it.

Each control cycle :meth:`Executor.step` takes both vehicles' measured states
and returns their setpoints for the end of the cycle. The executor knows
nothing of faults to come; it sees measurements and requests (a new goal, a
speed limit).

* **Following**: while both vehicles are within the tolerances of the plan,
  the setpoints are the verified schedule's.
* **Recovering**: on a departure (or a request) it replans with the
  topological planner from the measured configuration, keeping the homotopy
  class (on a Y the way round the configuration circle; on more legs the
  class whose region sequence continues the current route's) unless the
  other class is shorter by ``hysteresis`` metres of travel, and drives
  each vehicle with Ruckig from its current state towards a *hold point*: the next reversal of
  its path, or how far the route lets it go while the other vehicle is
  where it is (so a vehicle whose partner is late brakes and waits).
* **The braking invariant**: whatever the mode, a setpoint pair is issued
  only if :class:`~trajgen.online.braking.BrakingCheck` certifies that if
  both vehicles started braking at once (each anywhere between its service
  braking and its emergency stop) the measured track distance would stay at
  least ``min_separation + position_margin`` (or the current distance, if a
  fault left them closer: then the vehicles may only part). Otherwise the
  vehicle that is further ahead of the route brakes, or both do. Safety does
  not depend on the plan or on the optimizer.
"""

from __future__ import annotations

import bisect
import collections
import logging
import math
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory

from limits import Limits, VehicleLimits
from topology import JUNCTION_INDEX, Configuration, Position, Route, StarGraph, plan, reduce_regions
from topology.indexed import separation as indexed_separation
from topology.options import Option
from topology.route import Homotopy, WayRound
from trajgen.errors import InputError, ScheduleError
from trajgen.methods import make_schedule
from trajgen.online.braking import BrakingCheck, PathState
from trajgen.paths import Coordination, VehiclePath, set_distance
from trajgen.pieces import schedule_pieces
from trajgen.schedule import TimingMethod, check_period
from trajgen.summary import class_name
from trajgen.verify import VerifiedSchedule, certify, require_verified

__all__ = [
    "SEPARATION_TOLERANCE",
    "Command",
    "Event",
    "Executor",
    "GoalDecision",
    "Mode",
    "Setpoint",
    "VehicleState",
    "continues_class",
    "default_hysteresis",
    "execution_margin",
    "plan_for_execution",
    "ruckig_jerk",
    "schedule_waypoints",
]

logger = logging.getLogger(__name__)

#: Shortest and longest control period, seconds.
PERIOD_RANGE = (0.002, 0.1)
#: A vehicle within this travel of a point is at it, metres; slower than this speed is at rest, m/s.
_AT = 1e-6
_REST = 1e-6
#: A measured speed below this is at rest, m/s.
_AT_REST = 1e-3
#: Both vehicles at rest short of their goals this long (s): the executor replans with the planner.
STUCK_AFTER = 1.0
#: Track distance by which the separation may be missed (round-off of a schedule parked at the leg's end), m.
SEPARATION_TOLERANCE = 1e-7
#: Relative slack on the acceleration limit given to Ruckig (far below the 1e-6 the limits are checked to).
_SLACK = 1e-9


class Mode(Option):
    """What the executor is doing."""

    FOLLOWING = "following"  #: playing the verified schedule
    RECOVERING = "recovering"  #: Ruckig motion along a replanned route
    DONE = "done"  #: both vehicles at rest at their goals


@dataclass(frozen=True, slots=True)
class VehicleState:
    """A vehicle's measured state.

    Attributes
    ----------
    leg : int
        Leg index in the track's order, ``JUNCTION_INDEX`` (-1) at the junction.
    s : float
        Distance from the junction, metres.
    velocity, acceleration : float
        Along the vehicle's axis, m/s and m/s².
    """

    leg: int
    s: float
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True, slots=True)
class Setpoint:
    """A vehicle's setpoint for the end of a cycle.

    Attributes
    ----------
    axis, velocity, acceleration, jerk : float
        On the vehicle's signed axis: m, m/s, m/s², m/s³.
    leg : int
        Leg index (``JUNCTION_INDEX`` at the junction).
    s : float
        Distance from the junction, metres.
    branch : int
        The leg the vehicle takes when it next passes the junction (its own leg if it turns back there).
    """

    axis: float
    velocity: float
    acceleration: float
    jerk: float
    leg: int
    s: float
    branch: int


@dataclass(frozen=True, slots=True)
class Command:
    """What one :meth:`Executor.step` returns.

    Attributes
    ----------
    time : float
        The time the setpoints are for, seconds since the executor started.
    setpoints : tuple of 2 Setpoint
    mode : Mode
    braking : tuple of 2 bool
        Whether each vehicle was made to brake by the braking check this cycle.
    certified : bool
        Whether the braking check passed for these setpoints; ``False`` when both vehicles brake (the
        motion the previous cycle's check certified, not checked again).
    """

    time: float
    setpoints: tuple[Setpoint, Setpoint]
    mode: Mode
    braking: tuple[bool, bool]
    certified: bool = True


@dataclass(frozen=True, slots=True)
class Event:
    """Something the executor did: a mode change, a replan, a decision on a request.

    Attributes
    ----------
    time : float
        Seconds since the executor started.
    kind : str
        ``recover``, ``replan``, ``restart`` (a vehicle off its setpoints restarts from where it is),
        ``switch-class``, ``goal-accepted``, ``goal-refused``, ``speed-limit``, ``done``.
    detail : str
    """

    time: float
    kind: str
    detail: str


@dataclass(frozen=True, slots=True)
class GoalDecision:
    """The executor's answer to a goal request.

    Attributes
    ----------
    accepted : bool
    reason : str
        Why it was refused (empty when accepted).
    """

    accepted: bool
    reason: str = ""


def ruckig_jerk(trajectory: Trajectory, t: float) -> float:
    """Jerk of a one-axis Ruckig trajectory at time ``t``, m/s³ (its phases have constant jerk)."""
    profile = trajectory.profiles[0][0]
    brake = profile.brake
    if t < brake.duration:
        elapsed = 0.0
        for duration, jerk in zip(brake.t, brake.j, strict=False):
            elapsed += duration
            if t < elapsed:
                return jerk
    t -= brake.duration
    elapsed = 0.0
    for duration, jerk in zip(profile.t, profile.j, strict=True):
        elapsed += duration
        if t < elapsed:
            return jerk
    return 0.0


class _Plan:
    """A verified schedule as plain polynomial pieces per vehicle (evaluated every cycle)."""

    __slots__ = ("axis", "duration", "legs", "s_offset", "s_sign", "starts")

    def __init__(self, verified: VerifiedSchedule) -> None:
        pieces = schedule_pieces(verified.schedule)
        self.starts = [float(x) for x in pieces.start]
        self.duration = float(verified.schedule.duration)
        self.axis = [[[float(c) for c in row] for row in pieces.axis[v]] for v in (0, 1)]
        self.legs = [[int(x) for x in pieces.leg[v]] for v in (0, 1)]
        self.s_offset = [[float(x) for x in pieces.s_offset[v]] for v in (0, 1)]
        self.s_sign = [[float(x) for x in pieces.s_sign[v]] for v in (0, 1)]

    def state(self, vehicle: int, t: float) -> tuple[float, float, float, float, int, float]:
        """Axis, velocity, acceleration, jerk, leg, s of ``vehicle`` at time ``t`` (clipped to the plan)."""
        t = min(max(t, 0.0), self.duration)
        k = max(bisect.bisect_right(self.starts, t) - 1, 0)
        u = t - self.starts[k]
        c0, c1, c2, c3, c4 = self.axis[vehicle][k]
        axis = c0 + u * (c1 + u * (c2 + u * (c3 + u * c4)))
        velocity = c1 + u * (2.0 * c2 + u * (3.0 * c3 + u * 4.0 * c4))
        acceleration = 2.0 * c2 + u * (6.0 * c3 + u * 12.0 * c4)
        jerk = 6.0 * c3 + u * 24.0 * c4
        s = max(self.s_offset[vehicle][k] + self.s_sign[vehicle][k] * axis, 0.0)
        leg = self.legs[vehicle][k] if s > 0.0 else JUNCTION_INDEX
        return axis, velocity, acceleration, jerk, leg, s


def schedule_waypoints(schedule) -> list[tuple[int, float, int, float]]:
    """Both vehicles' positions along a schedule, dense enough to trace their paths and coordination.

    Every piece boundary, every instant a vehicle comes to rest and turns (a root of its velocity),
    and four points inside each piece; indexed configurations ``(leg1, s1, leg2, s2)``.
    """
    pieces = schedule_pieces(schedule)
    times = [0.0, schedule.duration]
    for k in range(pieces.count):
        start, length = float(pieces.start[k]), float(pieces.length[k])
        times.extend(start + length * f for f in (0.0, 0.2, 0.4, 0.6, 0.8))
        for v in (0, 1):
            c = pieces.axis[v, k]
            derivative = [i * c[i] for i in range(len(c) - 1, 0, -1)]  # highest power first
            while derivative and abs(derivative[0]) <= 1e-300:
                derivative.pop(0)
            if len(derivative) > 1:
                for root in np.roots(derivative):
                    if abs(root.imag) <= 1e-12 and 0.0 < root.real < length:
                        times.append(start + float(root.real))
    times = np.unique(np.clip(times, 0.0, schedule.duration))
    state = schedule.state(times)
    return [
        (int(state.leg[0, i]), float(state.s[0, i]), int(state.leg[1, i]), float(state.s[1, i]))
        for i in range(times.size)
    ]


def _steady_stop(state: PathState, stop: float, deceleration: float, period: float) -> PathState:
    """``period`` seconds on from ``state``, braking at constant ``deceleration`` (m/s²) to ``stop``.

    Returns
    -------
    PathState
    """
    if period * deceleration >= state.v:
        return PathState(stop, 0.0, -deceleration)
    return PathState(
        min(state.p + state.v * period - 0.5 * deceleration * period * period, stop),
        state.v - deceleration * period,
        -deceleration,
    )


class _Motion:
    """One vehicle's Ruckig generator along its path (position interface, travel coordinates).

    A trajectory is followed from cycle to cycle while its target stays the same and the vehicle's
    setpoint is the one it produced; any change recalculates it from the current setpoint.
    """

    __slots__ = ("elapsed", "generator", "goal", "input", "output", "trajectory")

    def __init__(self, limits: VehicleLimits) -> None:
        self.generator = Ruckig(1)
        self.input = InputParameter(1)
        self.input.max_velocity = [limits.max_velocity]
        # a hair of slack: a state braking at exactly the limit towards a reversal stays solvable
        self.input.max_acceleration = [limits.max_acceleration * (1.0 + _SLACK)]
        self.input.max_jerk = [limits.max_jerk]
        self.input.target_velocity = [0.0]
        self.input.target_acceleration = [0.0]
        self.trajectory = Trajectory(1)
        self.goal: tuple[float, float] | None = None
        self.output: PathState | None = None
        self.elapsed = 0.0

    def forget(self) -> None:
        """Recalculate at the next call (the limits changed)."""
        self.goal = None

    def next_state(
        self, state: PathState, target: float, period: float, arrival: float = 0.0
    ) -> tuple[PathState, float]:
        """The state ``period`` seconds along the time-optimal motion from ``state`` to ``target``.

        The motion ends at rest, with acceleration ``arrival`` (m/s²): 0 to stop, ``-max_acceleration``
        to turn at a reversal without waiting (the axis keeps decelerating through v = 0).

        Raises
        ------
        ScheduleError
            Ruckig found no motion.
        """
        if self.goal != (target, arrival) or state is not self.output:
            inp = self.input
            inp.current_position = [state.p]
            inp.current_velocity = [state.v]
            inp.current_acceleration = [state.a]
            inp.target_position = [target]
            inp.target_acceleration = [arrival]
            try:
                result = self.generator.calculate(inp, self.trajectory)
            except RuckigError as error:
                self.goal = None
                raise ScheduleError(
                    f"ruckig could not plan a motion from {state} to {target!r} m: {error}"
                ) from None
            if result not in (Result.Working, Result.Finished):
                self.goal = None
                raise ScheduleError(f"ruckig could not plan a motion from {state} to {target!r} m: {result}")
            self.goal = (target, arrival)
            self.elapsed = 0.0
        self.elapsed += period
        t = min(self.elapsed, self.trajectory.duration)
        (p,), (v,), (a,) = self.trajectory.at_time(t)
        jerk = ruckig_jerk(self.trajectory, t) if t < self.trajectory.duration else 0.0
        self.output = PathState(p, v, a)
        return self.output, jerk


def execution_margin(scenario, position_margin: float) -> float:
    """The position margin an executor can keep for ``scenario``, metres: at most ``position_margin``.

    The plan needs twice the margin on top of the separation (:func:`plan_for_execution`), which must
    fit the shortest leg and the start and goal; where it does not, the margin shrinks (to 0 when the
    separation is the shortest leg).
    """
    track = scenario.track
    room = min(track.shortest_leg, track.separation(scenario.start), track.separation(scenario.goal))
    return max(0.0, min(position_margin, 0.5 * (room - scenario.limits.min_separation)))


def plan_for_execution(
    scenario, *, method: TimingMethod | str | None = None, position_margin: float = 0.05
) -> VerifiedSchedule:
    """The verified schedule an :class:`Executor` plays for ``scenario``.

    Planned for the separation ``min_separation + 2 * margin``, with the margin of
    :func:`execution_margin`: the executor keeps ``min_separation + margin`` under its braking
    check, and the second margin lets the plan pass that check where it runs closest.
    """
    margin = execution_margin(scenario, position_margin)
    separation = scenario.limits.min_separation + 2.0 * margin
    limits = Limits(scenario.limits.vehicles, separation)
    route = plan(scenario.track, scenario.start, scenario.goal, min_separation=separation)
    return certify(make_schedule(route, limits, method=method))


def default_hysteresis(graph: StarGraph) -> float:
    """The executor's default hysteresis on ``graph``, metres of travel: ``0.4 (L_0 + ... + L_{k-1})``.

    On a Y that is 10 % of the perimeter ``4 (L_0 + L_1 + L_2)`` of the configuration circle (and
    computed so); on more legs the same share of the leg lengths, whatever ``k``.

    Examples
    --------
    >>> from topology import StarGraph
    >>> default_hysteresis(StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}))
    16.0
    """
    if graph.cycle is not None:
        return 0.1 * graph.cycle.perimeter
    return 0.4 * math.fsum(graph.lengths)


def continues_class(current: Route, candidate: Route) -> bool:
    """Whether ``candidate``, planned from a point along ``current`` to its goal, stays in its class.

    True when, after some prefix of ``current``'s reduced region sequence (the part driven), the
    candidate's regions reduce to exactly ``current``'s: driving the prefix and then ``candidate`` is
    homotopic to ``current`` (ALGORITHM.md section 6). Used on four or more legs, where no way round
    a circle tells the classes apart.

    Parameters
    ----------
    current : Route
        The route being driven.
    candidate : Route
        A route from where the vehicles are now to ``current``'s goal.
    """
    keys = current.region_keys
    rest = candidate.region_keys
    return any(reduce_regions(keys[:driven] + rest) == keys for driven in range(len(keys) + 1))


class Executor:
    """Runs a verified schedule in closed loop, recovering from departures with Ruckig.

    Parameters
    ----------
    verified : VerifiedSchedule
        The plan (:func:`trajgen.certify`); its route and limits are the executor's.
    period : float, optional
        Control period, seconds, 0.002 to 0.1 (default 0.01).
    position_tolerance : float, optional
        Largest departure from the setpoint along the track before the executor recovers, metres (0.05).
    velocity_tolerance : float, optional
        Largest departure from the setpoint's velocity, m/s (0.05).
    position_margin : float, optional
        Added to the minimum separation in the braking check, metres (0.05): a measured position may be
        off by this much (localisation) and the true separation still holds.
    hysteresis : float or None, optional
        Travel, metres, by which the other homotopy class must be shorter before a replan switches to it;
        ``None``: :func:`default_hysteresis`, ``0.4 (L_0 + ... + L_{k-1})`` (40 % of the leg lengths'
        sum; on a Y, 10 % of the perimeter of the configuration circle).
    latency : float, optional
        How late a drive may follow its setpoints, seconds (0.2): a vehicle within the tolerances of
        any setpoint of that window is on track, not departed.
    min_separation : float or None, optional
        The separation to keep, metres; ``None``: the schedule's. A plan computed with a larger
        separation (:func:`plan_for_execution`) leaves the braking check room to pass while following.
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
        hysteresis: float | None = None,
        latency: float = 0.2,
    ) -> None:
        verified = require_verified(verified, "Executor")
        schedule = verified.schedule
        period = check_period(period)
        if not PERIOD_RANGE[0] <= period <= PERIOD_RANGE[1]:
            raise InputError(
                f"control period must be {PERIOD_RANGE[0]:g} to {PERIOD_RANGE[1]:g} s, got {period!r}"
            )
        for name, value in (
            ("position_tolerance (m)", position_tolerance),
            ("velocity_tolerance (m/s)", velocity_tolerance),
            ("latency (s)", latency),
        ):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
                raise InputError(f"{name} must be a finite number > 0, got {value!r}")
        if not (
            isinstance(position_margin, (int, float))
            and math.isfinite(position_margin)
            and position_margin >= 0
        ):
            raise InputError(f"position_margin (m) must be a finite number >= 0, got {position_margin!r}")
        self.graph = schedule.route.graph
        if min_separation is None:
            min_separation = schedule.limits.min_separation
        if not (
            isinstance(min_separation, (int, float))
            and math.isfinite(min_separation)
            and 0.0 <= min_separation <= schedule.limits.min_separation
        ):
            raise InputError(
                "min_separation must be between 0 m and the schedule's "
                f"{schedule.limits.min_separation!r} m, "
                f"got {min_separation!r}"
            )
        self.limits: Limits = Limits(schedule.limits.vehicles, float(min_separation))
        self.period = period
        self.position_tolerance = float(position_tolerance)
        self.velocity_tolerance = float(velocity_tolerance)
        self.position_margin = float(position_margin)
        self.latency = float(latency)
        window = math.ceil(self.latency / period) + 1
        self._recent = (collections.deque(maxlen=window), collections.deque(maxlen=window))
        if hysteresis is None:
            hysteresis = default_hysteresis(self.graph)
        if not (isinstance(hysteresis, (int, float)) and math.isfinite(hysteresis) and hysteresis >= 0.0):
            raise InputError(f"hysteresis (m) must be a finite number >= 0, got {hysteresis!r}")
        self.hysteresis = float(hysteresis)
        vehicles = self.limits.vehicles
        self._check = BrakingCheck(vehicles, tuple(v.emergency_braking for v in vehicles), self.graph.lengths)
        self._motions = (_Motion(vehicles[0]), _Motion(vehicles[1]))
        self._speed = [v.max_velocity for v in vehicles]
        self._plan: _Plan | None = _Plan(verified)
        self.schedule = schedule
        self._route: Route = schedule.route
        self._goal: Configuration = schedule.route.goal
        waypoints = schedule_waypoints(schedule)
        self._paths = tuple(
            VehiclePath.from_waypoints(waypoints, v, axis_start=self._plan.state(v, 0.0)[0]) for v in (0, 1)
        )
        self._coordination = Coordination.from_waypoints(waypoints)
        self._mode = Mode.FOLLOWING
        self._time = 0.0
        self._plan_time = 0.0
        self._travel = [0.0, 0.0]  # measured travel along the current paths
        self._command = [PathState(0.0, 0.0, 0.0), PathState(0.0, 0.0, 0.0)]
        self._pending: str | None = None
        self._next_goal: Configuration | None = None
        self._idle = 0
        self._restarted = [-math.inf, -math.inf]
        self._restarting = [False, False]
        self.events: list[Event] = []
        self.replans = 0
        self.rejected_goals = 0

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
    def route(self) -> Route:
        """The route being driven: the schedule's, or the last replanned one."""
        return self._route

    @property
    def paths(self) -> tuple[VehiclePath, VehiclePath]:
        """Both vehicles' paths along :attr:`route`, in travel coordinates."""
        return self._paths

    @property
    def goal(self) -> Configuration:
        """The goal both vehicles are driving to."""
        return self._goal

    def motion(self, vehicle: int) -> tuple[InputParameter, Trajectory, float]:
        """The Ruckig input and trajectory ``vehicle`` (0 or 1) follows, and how far along it is (s).

        Travel coordinates (metres along the vehicle's path); for inspection and tests.
        """
        motion = self._motions[vehicle]
        return motion.input, motion.trajectory, motion.elapsed

    # -- requests --------------------------------------------------------------------------------
    def request_goal(self, vehicle: int, position: Position) -> GoalDecision:
        """Ask for a new goal of ``vehicle`` (0 or 1); taken at the next cycle, or refused with a reason."""
        if vehicle not in (0, 1):
            raise InputError(f"vehicle must be 0 or 1, got {vehicle!r}")
        try:
            position = self.graph.check(position)
        except InputError as error:
            return self._refuse(f"goal {position} of vehicle {vehicle + 1}: {error}")
        goal = list(self._next_goal or self._goal)
        goal[vehicle] = position
        candidate = Configuration(*goal)
        apart = self.graph.separation(candidate)
        required = self.limits.min_separation + self.position_margin
        if apart < required:
            return self._refuse(
                f"goal {position} of vehicle {vehicle + 1} is {apart:.3f} m from the other vehicle's goal "
                f"{goal[1 - vehicle]}: expected at least {required:.3f} m (separation + position margin)"
            )
        self._next_goal = candidate
        self._log(
            "goal-accepted",
            f"new goal {position} for vehicle {vehicle + 1}: both vehicles stop, then the route changes",
        )
        return GoalDecision(True)

    def request_speed_limit(self, vehicle: int, speed: float) -> None:
        """Limit ``vehicle``'s speed to ``speed`` m/s (at most its ``max_velocity``) from the next cycle."""
        if vehicle not in (0, 1):
            raise InputError(f"vehicle must be 0 or 1, got {vehicle!r}")
        top = self.limits.vehicles[vehicle].max_velocity
        if not (isinstance(speed, (int, float)) and math.isfinite(speed) and 0.0 < speed <= top):
            raise InputError(
                f"speed limit of vehicle {vehicle + 1} must be > 0 and <= {top!r} m/s, got {speed!r}"
            )
        self._speed[vehicle] = float(speed)
        self._motions[vehicle].input.max_velocity = [float(speed)]
        self._motions[vehicle].forget()
        self._pending = f"speed limit {speed:g} m/s for vehicle {vehicle + 1}"
        self._log("speed-limit", self._pending)

    # -- the cycle -------------------------------------------------------------------------------
    def step(self, first: VehicleState, second: VehicleState) -> Command:
        """One control cycle: the measured states now, the setpoints for one period later.

        Parameters
        ----------
        first, second : VehicleState
            Measured states of vehicle 1 and vehicle 2.

        Returns
        -------
        Command
        """
        measured = (self._checked(first, 1), self._checked(second, 2))
        if self._next_goal is not None:
            # a new goal may need a vehicle to turn back: both first brake to rest along the route they
            # are on (the motion the braking check has certified), then the route changes
            if self._mode is not Mode.RECOVERING:
                self._recover(measured, "a new goal: both vehicles stop before the route changes")
            if all(
                abs(self._command[v].v) <= _REST and abs(measured[v].velocity) <= _AT_REST for v in (0, 1)
            ):
                self._goal, self._next_goal = self._next_goal, None
                self._recover(measured, f"new goal {self._goal}", new_goal=True)
        elif self._pending is not None:
            reason, self._pending = self._pending, None
            self._recover(measured, reason)
        elif self._mode is Mode.FOLLOWING:
            command = self._follow(measured)
            if command is not None:
                return command
        elif self._mode is Mode.DONE and not self._at_goal(measured):
            self._recover(measured, "a vehicle left its goal")
        return self._drive(measured)

    # -- following -------------------------------------------------------------------------------
    def _follow(self, measured) -> Command | None:
        plan = self._plan
        now = [plan.state(v, self._plan_time) for v in (0, 1)]
        for v in (0, 1):
            axis, velocity, _, _, leg, s = now[v]
            path = self._paths[v]
            p_plan = path.project(leg, s, self._command[v].p)
            p_meas = path.project(
                measured[v].leg, measured[v].s, p_plan if p_plan is not None else 0.0, self.position_tolerance
            )
            if p_meas is None or p_plan is None:
                self._recover(measured, f"vehicle {v + 1} is off its planned path")
                return None
            if self._departed(v, path.axis(p_meas), measured[v].velocity):
                self._recover(measured, f"vehicle {v + 1} is off its planned motion")
                return None
            self._travel[v] = p_meas
        t_next = self._plan_time + self.period
        states = [plan.state(v, t_next) for v in (0, 1)]
        commanded, measured_path = [], []
        for v in (0, 1):
            axis, velocity, acceleration, jerk, leg, s = states[v]
            path = self._paths[v]
            p = path.project(leg, s, self._travel[v])
            if p is None:  # cannot happen for a verified plan; recover rather than guess
                self._recover(measured, f"the plan left vehicle {v + 1}'s path")
                return None
            heading = path.heading(p)
            commanded.append(PathState(p, heading * velocity, heading * acceleration))
            measured_path.append(
                PathState(self._travel[v], heading * measured[v].velocity, heading * measured[v].acceleration)
            )
        if not self._check.clearance(
            self._paths, tuple(commanded), tuple(measured_path), self._required(measured)
        ):
            self._recover(measured, "the plan failed the braking check")
            return None
        self._plan_time = t_next
        self._time += self.period
        setpoints = []
        for v in (0, 1):
            axis, velocity, acceleration, jerk, leg, s = states[v]
            self._command[v] = commanded[v]
            self._recent[v].append((axis, velocity))
            setpoints.append(
                Setpoint(
                    axis,
                    velocity,
                    acceleration,
                    jerk,
                    leg,
                    s,
                    self._branch(v, commanded[v].p, commanded[v].v),
                )
            )
        if t_next >= plan.duration - 1e-12:
            self._mode = Mode.DONE
            self._log("done", "the plan is complete")
        return Command(self._time, tuple(setpoints), self._mode, (False, False))

    # -- recovering ------------------------------------------------------------------------------
    def _recover(self, measured, reason: str, *, new_goal: bool = False, fresh: bool = False) -> None:
        """Replan from the measured configuration and continue with Ruckig.

        The planner's routes from the measured configuration give both homotopy classes. Where both
        vehicles are still on their paths and the goal is unchanged, the rest of the current route is in
        the current class too, and usually far shorter (the planner's route first retracts onto the
        boundary circle, where a vehicle is at the end of a leg): the shorter of the two in the kept
        class is driven. The other class is taken only if it is shorter by ``hysteresis`` metres.
        """
        if self._mode is not Mode.RECOVERING:
            self._log("recover", reason)
        self._mode = Mode.RECOVERING
        self._plan = None
        old_paths = self._paths
        on_path = [
            old_paths[v].project(measured[v].leg, measured[v].s, self._command[v].p, self.position_tolerance)
            for v in (0, 1)
        ]
        remainder = None
        if not new_goal and not fresh and None not in on_path:
            remainder = sum(path.length - p for path, p in zip(old_paths, on_path, strict=True))
        configuration = Configuration(*(self._position(state) for state in measured))
        keep = min(self.limits.min_separation + self.position_margin, self.graph.separation(configuration))
        route = self._choose_route(configuration, keep, remainder)
        self.replans += 1
        if route is None:
            self._log("replan", f"{reason}: the rest of the current route kept ({remainder:.3f} m of travel)")
            for v in (0, 1):
                self._reseed(v, measured[v], on_path[v], old_paths[v])
            return
        self._log("replan", f"{reason}: new route, {self._describe(route)}")
        seeds, new_paths = [], []
        for v in (0, 1):
            old = old_paths[v]
            p_old = on_path[v]
            if p_old is None:
                p_old = self._command[v].p
            axis = old.axis(p_old)
            orientation = old.outward(p_old) * old.heading(p_old)
            path = VehiclePath.from_route(route, v, axis_start=axis, orientation=orientation)
            new_paths.append(path)
            heading_old = old.heading(self._command[v].p)
            if abs(p_old - self._command[v].p) <= self.position_tolerance:  # continue the setpoints
                v_axis, a_axis = heading_old * self._command[v].v, heading_old * self._command[v].a
            else:
                v_axis, a_axis = measured[v].velocity, measured[v].acceleration
                self._restarted[v] = self._time
            heading = path.heading(0.0)
            seeds.append(self._seed(v, 0.0, heading * v_axis, heading * a_axis))
        for recent in self._recent:
            recent.clear()  # travel coordinates change with the paths
        self._route = route
        self._paths = tuple(new_paths)
        self._coordination = Coordination.from_route(route)
        self._command = seeds
        self._travel = [0.0, 0.0]

    def _departed(self, v: int, axis: float, velocity: float) -> bool:
        """Whether a measured axis (m) and axis velocity (m/s) of ``v`` match none of its recent setpoints.

        Compared on the axis, which runs on smoothly through reversals (the travel's velocity flips
        there). The window is the setpoints of the last ``latency`` seconds: a drive that follows late
        is on track.
        """
        recent = self._recent[v]
        if not recent or self._time - self._restarted[v] < self.latency:
            return False  # a restart shows in the measurements only after the drive's latency
        tol_p, tol_v = self.position_tolerance, self.velocity_tolerance
        last_axis, last_velocity = recent[-1]
        if abs(axis - last_axis) <= tol_p and abs(velocity - last_velocity) <= tol_v:
            return False
        return not any(abs(axis - q) <= tol_p and abs(velocity - w) <= tol_v for q, w in recent)

    def _seed(self, v: int, p: float, velocity: float, acceleration: float) -> PathState:
        """A setpoint to restart from: the measured state, its velocity and acceleration within the limits.

        A vehicle stopped by a fault may measure more than ``max_acceleration``; the setpoints never
        ask for it.
        """
        limits = self.limits.vehicles[v]
        top_v = self._speed[v]
        velocity = min(max(velocity, -top_v), top_v)
        acceleration = min(max(acceleration, -limits.max_acceleration), limits.max_acceleration)
        # the acceleration must be brought to 0 within the speed limit: v + a|a|/(2j) inside [-top, top]
        room = top_v - velocity if acceleration > 0.0 else top_v + velocity
        most = math.sqrt(max(2.0 * limits.max_jerk * room, 0.0))
        acceleration = min(max(acceleration, -most), most)
        return PathState(p, velocity, acceleration)

    def _reseed(self, v: int, measured: VehicleState, p: float, path: VehiclePath) -> None:
        """Continue ``v`` on its path from its setpoint, or from its measured state if it is far from it."""
        heading = path.heading(p)
        v_meas = heading * measured.velocity
        if self._departed(v, path.axis(p), measured.velocity):
            self._command[v] = self._seed(v, p, v_meas, heading * measured.acceleration)
            self._recent[v].clear()
            self._restarted[v] = self._time
        self._travel[v] = p

    def _choose_route(
        self, configuration: Configuration, keep: float, remainder: float | None
    ) -> Route | None:
        """The route to drive from ``configuration``: ``None`` to keep the rest of the current one.

        Parameters
        ----------
        configuration : Configuration
            Where the vehicles are.
        keep : float
            Separation the new route keeps, metres.
        remainder : float or None
            Travel left on the current route, metres, or ``None`` if it cannot be continued.
        """
        paper = plan(self.graph, configuration, self._goal, min_separation=keep)
        try:
            other = plan(self.graph, configuration, self._goal, min_separation=keep, homotopy=Homotopy.OTHER)
        except InputError:
            other = None
        if self.graph.cycle is not None:  # a Y: the classes are the two ways round the circle
            current = self._route.way_round.value
            if self._route.way_round is WayRound.NONE or other is None:
                same, different = paper, other
            else:
                same_way = paper.way_round is self._route.way_round
                same, different = (paper, other) if same_way else (other, paper)
        else:  # more legs: the class of the candidate that continues the current route's regions
            current = "the current class"
            continues = other is not None and continues_class(self._route, other)
            if continues and not continues_class(self._route, paper):
                same, different = other, paper
            else:
                same, different = paper, other
        kept = min(same.length, remainder) if remainder is not None else same.length
        if different is not None and different.length < kept - self.hysteresis:
            self._log(
                "switch-class",
                f"{class_name(different)} ({different.length:.3f} m) is shorter than "
                f"{current} ({kept:.3f} m) by more than the hysteresis {self.hysteresis:.3f} m",
            )
            return different
        if remainder is not None and remainder <= same.length:
            return None
        return same

    def _drive(self, measured) -> Command:
        """A recovering (or done) cycle: Ruckig towards each vehicle's hold point, under the braking check."""
        travel = [
            self._paths[v].project(
                measured[v].leg, measured[v].s, self._command[v].p, self.position_tolerance
            )
            for v in (0, 1)
        ]
        if None in travel:
            self._recover(measured, f"vehicle {travel.index(None) + 1} is off its route")
            travel = [0.0, 0.0]
        paths = self._paths
        measured_path = []
        for v in (0, 1):
            p = travel[v]
            self._travel[v] = p
            heading = paths[v].heading(p)
            measured_path.append(
                PathState(p, heading * measured[v].velocity, heading * measured[v].acceleration)
            )
        for v in (0, 1):  # a vehicle far from its setpoints restarts from where it is
            if self._departed(v, paths[v].axis(travel[v]), measured[v].velocity):
                if not self._restarting[v]:  # log the first restart of a departure, not every one
                    self._log(
                        "restart",
                        f"vehicle {v + 1} is {abs(self._command[v].p - travel[v]):.3f} m from its setpoint "
                        f"at {measured[v].velocity:+.3f} m/s: Ruckig from where it is",
                    )
                self._restarting[v] = True
                self._command[v] = self._seed(v, measured_path[v].p, measured_path[v].v, measured_path[v].a)
                self._recent[v].clear()
                self._restarted[v] = self._time
            elif self._time - self._restarted[v] >= self.latency:
                self._restarting[v] = False
        for v in (0, 1):  # turning at a reversal: the travel runs on, so its velocity and acceleration flip
            c = self._command[v]
            if abs(c.v) <= _REST and c.a < 0.0 and any(abs(c.p - r) <= 1e-9 for r in paths[v].stops):
                self._command[v] = PathState(c.p, -c.v, -c.a)
        required = self._required(measured)
        targets = [self._target(v, measured_path, required) for v in (0, 1)]
        wanted = [self._within_stops(v, targets[v]) for v in (0, 1)]
        braking = [False, False]
        choice = self._safe_choice(wanted, measured_path, required)
        for v in (0, 1):
            if choice[v]:
                braking[v] = True
                wanted[v] = self._brake(v)
        if self._next_goal is not None:  # stopping for a new goal
            choice = (True, True)
            braking = [True, True]
            wanted = [self._brake(v) for v in (0, 1)]
        # both braking is the motion the previous cycle certified; it is not checked again (cycle time)
        certified = choice != (True, True)
        self._time += self.period
        setpoints = []
        for v in (0, 1):
            state, jerk = wanted[v]
            self._command[v] = state
            path = paths[v]
            heading = path.heading(state.p)
            axis = path.axis(state.p)
            self._recent[v].append((axis, heading * state.v))
            leg, s = path.locate(state.p)
            setpoints.append(
                Setpoint(
                    axis,
                    heading * state.v,
                    heading * state.a,
                    heading * jerk,
                    leg,
                    s,
                    self._branch(v, state.p, state.v),
                )
            )
        if self._mode is Mode.RECOVERING and all(
            abs(self._command[v].p - paths[v].length) <= _AT
            and abs(self._command[v].v) <= _REST
            and abs(measured_path[v].p - paths[v].length) <= self.position_tolerance
            for v in (0, 1)
        ):
            self._mode = Mode.DONE
            self._log("done", "both vehicles at their goals")
        idle = all(abs(self._command[v].v) <= _REST and abs(measured[v].velocity) <= _REST for v in (0, 1))
        self._idle = self._idle + 1 if idle and self._mode is Mode.RECOVERING else 0
        if self._idle * self.period >= STUCK_AFTER:
            # both at rest short of their goals: the coordination along this route is stuck, so the
            # planner's route from here (which keeps the separation all along) takes over
            self._idle = 0
            self._recover(measured, f"both vehicles waited {STUCK_AFTER:g} s", fresh=True)
        return Command(self._time, tuple(setpoints), self._mode, tuple(braking), certified)

    def _within_stops(self, v: int, target: float) -> tuple[PathState, float]:
        """Ruckig's next state towards ``target``, never through a reversal of the path or past its ends.

        At a reversal the vehicle arrives at rest still decelerating (``-max_acceleration`` along its
        travel), so it turns at once as a schedule does. A target that moved back (the other vehicle
        fell behind) can leave no time to stop at it: the motion then overshoots and comes back, which
        is fine on a leg but not through a reversal: then the reversal itself is the target, and if
        even that cannot be reached at rest the setpoint stops there (a last resort that a plan never
        needs).
        """
        path = self._paths[v]
        command = self._command[v]
        motion = self._motions[v]
        high = min(path.next_stop(command.p, 1e-9 if abs(command.v) <= _REST else 0.0), path.length)
        turning = high < path.length
        top_a = self.limits.vehicles[v].max_acceleration
        if turning and target >= high:
            # arrive braking as hard as allowed, else as hard as a steady stop from here would
            distance = high - command.p
            steady = command.v * command.v / (2.0 * distance) if distance > 0.0 and command.v > 0.0 else 0.0
            if abs(steady - top_a) <= 1e-6 * top_a and command.a <= -top_a * (1.0 - 1e-6):
                # braking at the limit straight into the reversal (as a schedule does): on the
                # boundary of what Ruckig can solve, so the constant deceleration is continued exactly
                return _steady_stop(command, high, steady, self.period), 0.0
            for arrival in (-top_a, -min(steady, top_a)):
                if arrival == 0.0:
                    break
                try:
                    state = motion.next_state(command, high, self.period, arrival)
                except ScheduleError:  # no motion arrives decelerating like this
                    continue
                extrema = motion.trajectory.position_extrema[0]
                if extrema.min >= min(command.p, high) - 1e-9 and extrema.max <= high + 1e-9:
                    return state
            target = high
        on_path = command.p <= path.length + 1e-9
        if on_path and target <= command.p + 1e-12 and abs(command.v) <= _REST:
            return self._brake(v)  # at rest at or past its target: it waits (it never backs up)
        state = motion.next_state(command, target, self.period)
        extrema = motion.trajectory.position_extrema[0]
        if on_path and (extrema.min < min(command.p, target) - 1e-9 or target < command.p):
            return self._brake(v)  # the way there would back up: brake instead, and wait
        if extrema.max > high + 1e-9 and target < high:
            state = motion.next_state(command, high, self.period)
        if turning and state[0].p > high:  # last resort: the setpoint stops at the reversal
            logger.warning("vehicle %d could not stop at its reversal at %.6f m; held there", v + 1, high)
            return PathState(high, 0.0, 0.0), 0.0
        return state

    def _target(self, v: int, measured_path, required: float) -> float:
        """Where ``v`` may drive to now: its next reversal, or the route's hold point given the other.

        The hold point lets ``v`` run ahead of the route by the other's braking distance (so both can move
        at once), but only to a point where ``v`` could wait while the other drives on along the route
        until the route catches up with ``v``; otherwise ``v`` holds where the route has it now (backing up
        to it if need be). How ``v`` gets there safely is the braking check's business.
        """
        path = self._paths[v]
        command = self._command[v]
        at_rest = abs(command.v) <= _REST
        stop = path.next_stop(command.p, 1e-9 if at_rest else 0.0)
        other = 1 - v
        other_travel = measured_path[other].p
        target = min(stop, self._coordination.hold(v, other_travel + self._slack(other)), path.length)
        if target > command.p:
            need = self._need(v, target)
            if need > other_travel:
                lengths = self.graph.lengths
                own = path.sweep(target, target, lengths)
                theirs = self._paths[other].sweep(other_travel, need, lengths)
                if set_distance(own, theirs) < required:
                    target = max(min(self._coordination.hold(v, other_travel), target), command.p)
        return target

    def _need(self, v: int, travel: float) -> float:
        """The other vehicle's travel at the first route point where ``v`` has travelled ``travel``."""
        own = self._coordination.first if v == 0 else self._coordination.second
        other = self._coordination.second if v == 0 else self._coordination.first
        k = bisect.bisect_left(own, travel)
        if k <= 0:
            return other[0]
        if k >= len(own):
            return other[-1]
        span = own[k] - own[k - 1]
        return other[k - 1] + (other[k] - other[k - 1]) * (travel - own[k - 1]) / span

    def _slack(self, vehicle: int) -> float:
        """How far a vehicle may plan ahead of the other: the other's braking distance from top speed."""
        limits = self.limits.vehicles[vehicle]
        speed = self._speed[vehicle]
        return speed * speed / (2.0 * limits.max_acceleration) + speed * limits.max_acceleration / (
            2.0 * limits.max_jerk
        )

    def _safe_choice(self, wanted, measured_path, required: float) -> tuple[bool, bool]:
        """Which vehicles must brake so that the braking check passes: (False, False) if none."""
        desired = tuple(state for state, _ in wanted)
        measured_path = tuple(measured_path)
        if self._check.clearance(self._paths, desired, measured_path, required):
            return (False, False)
        # brake the vehicle further ahead of the route first
        ahead = [desired[v].p - self._coordination.hold(v, measured_path[1 - v].p) for v in (0, 1)]
        order = (0, 1) if ahead[0] >= ahead[1] else (1, 0)
        for v in order:
            trial = list(desired)
            trial[v] = self._brake(v)[0]
            if self._check.clearance(self._paths, tuple(trial), measured_path, required):
                return (v == 0, v == 1)
        return (True, True)

    def _brake(self, v: int) -> tuple[PathState, float]:
        """The next state of ``v`` under service braking from its last setpoint (to rest, never reversing)."""
        command = self._command[v]
        if abs(command.v) <= _REST:
            return PathState(command.p, 0.0, 0.0), 0.0
        trajectory = self._check.service(v).plan(command)
        t = min(self.period, trajectory.duration)
        (p,), (velocity,), (a,) = trajectory.at_time(t)
        if velocity * command.v <= 0.0:  # at rest within this cycle: it stays there
            return PathState(p, 0.0, 0.0), 0.0
        jerk = ruckig_jerk(trajectory, t) if t < trajectory.duration else 0.0
        return PathState(p, velocity, a), jerk

    # -- helpers ---------------------------------------------------------------------------------
    def _refuse(self, reason: str) -> GoalDecision:
        self.rejected_goals += 1
        self._log("goal-refused", reason)
        return GoalDecision(False, reason)

    def _required(self, measured) -> float:
        """Track distance the braking check keeps: separation + margin (less if a fault left them closer)."""
        apart = indexed_separation((measured[0].leg, measured[0].s, measured[1].leg, measured[1].s))
        # closer than that after a fault: they may only part (to round-off: no ratchet cycle after cycle)
        return min(self.limits.min_separation + self.position_margin - SEPARATION_TOLERANCE, apart - 1e-12)

    def _at_goal(self, measured) -> bool:
        return all(
            abs(measured[v].s - self._goal[v].s) <= self.position_tolerance
            and (
                measured[v].leg == self._leg_index(self._goal[v]) or measured[v].s <= self.position_tolerance
            )
            for v in (0, 1)
        )

    def _leg_index(self, position: Position) -> int:
        return JUNCTION_INDEX if position.leg is None else self.graph.index(position.leg)

    def _position(self, state: VehicleState) -> Position:
        if state.leg == JUNCTION_INDEX or state.s <= 0.0:
            return Position(None, 0.0)
        return Position(self.graph.names[state.leg], min(state.s, self.graph.lengths[state.leg]))

    def _branch(self, v: int, p: float, velocity: float = 1.0) -> int:
        """The leg ``v`` takes when it next passes the junction, going forward (``velocity >= 0``) or back."""
        path = self._paths[v]
        if not path.legs:
            return path.home[0]
        k = path.segment(p)
        if velocity >= 0.0:
            if path.s_to[k] == 0.0 and k + 1 < len(path.legs):
                return path.legs[k + 1]
        elif path.s_from[k] == 0.0 and k > 0:
            return path.legs[k - 1]
        return path.legs[k]

    def _checked(self, state: VehicleState, number: int) -> VehicleState:
        if not isinstance(state, VehicleState):
            raise InputError(f"vehicle {number} state must be a VehicleState, got {type(state).__name__}")
        for name in ("s", "velocity", "acceleration"):
            value = getattr(state, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise InputError(f"vehicle {number} measured {name} must be a finite number, got {value!r}")
        count = self.graph.leg_count
        if state.leg != JUNCTION_INDEX and not 0 <= state.leg < count:
            raise InputError(
                f"vehicle {number} measured leg must be a leg index 0 to {count - 1} of the {count} legs "
                f"or {JUNCTION_INDEX} (the junction), got {state.leg!r}"
            )
        top = self.graph.lengths[state.leg] if state.leg != JUNCTION_INDEX else 0.0
        if state.s < 0.0 or state.s > top + 1e-6:
            raise InputError(
                f"vehicle {number} measured s {state.s!r} m is off leg {state.leg!r}: expected 0 to {top!r} m"
            )
        if state.s > top:
            return VehicleState(state.leg, top, state.velocity, state.acceleration)
        return state

    def _describe(self, route: Route) -> str:
        kind = f"way round {route.way_round.value}" if route.graph.cycle is not None else class_name(route)
        return f"{len(route.waypoints)} waypoints, {route.length:.3f} m of travel, {kind}"

    def _log(self, kind: str, detail: str) -> None:
        self.events.append(Event(self._time, kind, detail))
        logger.info("t=%.3f s %s: %s", self._time, kind, detail)
