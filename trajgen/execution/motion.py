"""Each vehicle's motion along its path: the plan played on time, or Ruckig towards a target.

While a vehicle is on time and its frontier allows, its setpoints are the
plan's (:class:`PlanPlayer`). After a departure it re-times the rest of its own
path with Ruckig (:class:`VehicleMotion`): time-optimally, under its own
velocity, acceleration and jerk limits, to rest at its next reversal or its
frontier, whichever comes first, recomputed every cycle as the frontier moves.
Travel coordinates throughout (:mod:`trajgen.model.paths`); plain floats: this runs
every control cycle.
"""

from __future__ import annotations

import bisect
import math

import numpy as np
from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory

from limits import VehicleLimits
from trajgen.errors import ScheduleError
from trajgen.execution.braking_check import PathState
from trajgen.model.coordination import stopping_distance
from trajgen.model.graph_vehicle_path import GraphVehiclePath
from trajgen.model.paths import VehiclePath
from trajgen.model.pieces import kinematics_polynomials, schedule_pieces, split_at_values
from trajgen.verification import VerifiedSchedule

__all__ = ["AT_REST", "GraphPlanPlayer", "PlanPlayer", "VehicleMotion", "ruckig_jerk", "travel_state"]

#: Relative slack on the acceleration limit given to Ruckig (far below the 1e-6 the limits are checked to).
_SLACK = 1e-9
#: A piece that reaches a segment's end within this at one of its ends is not split there, metres.
_SPLIT_MARGIN = 1e-9
#: A vehicle slower than this is at rest, m/s.
AT_REST = 1e-6


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


class PlanPlayer:
    """A verified schedule as plain polynomial pieces of each vehicle's axis, evaluated every cycle.

    Parameters
    ----------
    starts : list of float, shape (m,)
        Each piece's start, seconds.
    duration : float
        The plan's makespan, seconds.
    axis : list of 2 lists of 5 floats per piece
        Each vehicle's polynomial on each piece (time since the piece's start), ascending powers.
    """

    __slots__ = ("axis", "duration", "starts")

    def __init__(self, starts: list[float], duration: float, axis: list[list[list[float]]]) -> None:
        self.starts = starts
        self.duration = duration
        self.axis = axis

    @classmethod
    def of(cls, verified: VerifiedSchedule) -> PlanPlayer:
        """The player of a verified schedule on a junction (its axis as the schedule's pieces give it)."""
        pieces = schedule_pieces(verified.schedule)
        return cls(
            [float(x) for x in pieces.start],
            float(verified.schedule.duration),
            [[[float(c) for c in row] for row in pieces.axis[v]] for v in (0, 1)],
        )

    def _polynomial(self, vehicle: int, t: float) -> tuple[float, float, float, float]:
        """The value and its three derivatives of ``vehicle``'s polynomial at ``t`` (clipped)."""
        t = min(max(t, 0.0), self.duration)
        k = max(bisect.bisect_right(self.starts, t) - 1, 0)
        u = t - self.starts[k]
        c0, c1, c2, c3, c4 = self.axis[vehicle][k]
        value = c0 + u * (c1 + u * (c2 + u * (c3 + u * c4)))
        if t >= self.duration:
            return value, 0.0, 0.0, 0.0
        velocity = c1 + u * (2.0 * c2 + u * (3.0 * c3 + u * 4.0 * c4))
        acceleration = 2.0 * c2 + u * (6.0 * c3 + u * 12.0 * c4)
        return value, velocity, acceleration, 6.0 * c3 + u * 24.0 * c4

    def state(self, vehicle: int, t: float) -> tuple[float, float, float, float]:
        """Axis (m), velocity, acceleration and jerk of ``vehicle`` at ``t`` (s, clipped to the plan)."""
        if not self.starts:
            return 0.0, 0.0, 0.0, 0.0
        return self._polynomial(vehicle, t)


class GraphPlanPlayer(PlanPlayer):
    """A verified schedule on a track graph, played as each vehicle's axis.

    The schedule's pieces give each vehicle's travel; they are split where a path's segment ends,
    and on each piece the axis is the travel signed by that segment's heading (it grows along the
    first move and runs back after each reversal, :class:`GraphVehiclePath`). The segment is the
    one at the piece's middle, never a travel value's round-off next to a reversal.
    """

    __slots__ = ()

    def __init__(self, verified: VerifiedSchedule) -> None:
        schedule = verified.schedule
        parts = []
        for section in schedule.sections:
            times, travel, intervals = kinematics_polynomials(section.kinematics)
            parts.append((section.start_time + times, travel, intervals))
        ends = np.concatenate([p[0][:-1] for p in parts] + [parts[-1][0][-1:]])
        travel = np.concatenate([p[1] for p in parts], axis=1)
        intervals = np.concatenate([p[2] for p in parts], axis=1)
        paths = tuple(GraphVehiclePath.from_path(path, schedule.track) for path in schedule.paths)
        bounds = tuple(path.starts[1:] for path in paths)
        starts, lengths, travel, _ = split_at_values(ends, travel, intervals, bounds, margin=_SPLIT_MARGIN)
        axis: list[list[list[float]]] = [[] for _ in paths]
        for v, path in enumerate(paths):
            for k in range(starts.size):
                row = [float(c) for c in travel[v, k]]
                if not path.headings:
                    axis[v].append([path.axis(0.0), 0.0, 0.0, 0.0, 0.0])
                    continue
                u = 0.5 * float(lengths[k])
                middle = row[0] + u * (row[1] + u * (row[2] + u * (row[3] + u * row[4])))
                segment = path.segment(middle)
                heading = path.headings[segment]
                coefficients = [heading * c for c in row]
                coefficients[0] += path.axis_starts[segment] - heading * path.starts[segment]
                axis[v].append(coefficients)
        super().__init__([float(x) for x in starts], float(schedule.duration), axis)


class VehicleMotion:
    """One vehicle's Ruckig generators along its path (travel coordinates).

    A trajectory to a target is reused from cycle to cycle while the target stays the same and
    the vehicle's state is the one it produced; anything else recalculates it from the state.

    Parameters
    ----------
    limits : VehicleLimits
    """

    __slots__ = (
        "_braking",
        "_braking_input",
        "_elapsed",
        "_goal",
        "_input",
        "_limits",
        "_output",
        "_ruckig",
        "trajectory",
    )

    def __init__(self, limits: VehicleLimits) -> None:
        self._limits = limits
        self._ruckig = Ruckig(1)
        self._input = InputParameter(1)
        self._input.max_velocity = [limits.max_velocity]
        # a hair of slack: a state braking at exactly the limit stays solvable
        self._input.max_acceleration = [limits.max_acceleration * (1.0 + _SLACK)]
        self._input.max_jerk = [limits.max_jerk]
        self._input.target_velocity = [0.0]
        self._input.target_acceleration = [0.0]
        self.trajectory = Trajectory(1)
        self._braking = Trajectory(1)
        self._braking_input = InputParameter(1)
        self._braking_input.control_interface = ControlInterface.Velocity
        self._braking_input.max_velocity = [math.inf]
        self._braking_input.max_acceleration = [limits.max_acceleration * (1.0 + _SLACK)]
        self._braking_input.max_jerk = [limits.max_jerk]
        self._braking_input.target_velocity = [0.0]
        self._braking_input.target_acceleration = [0.0]
        self._goal: float | None = None
        self._output: PathState | None = None
        self._elapsed = 0.0

    def set_speed_limit(self, speed: float) -> None:
        """Cap the vehicle's speed at ``speed`` m/s from the next calculation."""
        self._input.max_velocity = [speed]
        self._goal = None

    @property
    def speed_limit(self) -> float:
        """The speed the vehicle is held to, m/s."""
        return float(self._input.max_velocity[0])

    def toward(self, state: PathState, target: float, period: float) -> tuple[PathState, float]:
        """The state ``period`` seconds along the time-optimal motion from ``state`` to rest at ``target``.

        Returns
        -------
        (PathState, float)
            The next state and the jerk over the cycle, m/s³.

        Raises
        ------
        ScheduleError
            Ruckig found no motion.
        """
        if self._goal != target or state is not self._output:
            self._input.current_position = [state.p]
            self._input.current_velocity = [state.v]
            self._input.current_acceleration = [state.a]
            self._input.target_position = [target]
            result = self._ruckig.calculate(self._input, self.trajectory)
            if result not in (Result.Working, Result.Finished):
                raise ScheduleError(f"Ruckig found no motion from {state} to {target!r} m: {result}")
            self._goal, self._elapsed = target, 0.0
        self._elapsed += period
        t = min(self._elapsed, self.trajectory.duration)
        (p,), (v,), (a,) = self.trajectory.at_time(t)
        jerk = ruckig_jerk(self.trajectory, t) if t < self.trajectory.duration else 0.0
        if t >= self.trajectory.duration:
            p, v, a = target, 0.0, 0.0
        self._output = PathState(p, v, a)
        return self._output, jerk

    def overshoots(self, target: float) -> bool:
        """Whether the motion last calculated runs past ``target`` or backs up (it cannot stop in time)."""
        extrema = self.trajectory.position_extrema[0]
        return extrema.max > target + 1e-9

    def brake(self, state: PathState, period: float) -> tuple[PathState, float]:
        """The state ``period`` seconds into service braking from ``state`` (to rest, never backing up)."""
        self._goal = None
        if state.v <= AT_REST and state.a <= 0.0:
            return PathState(state.p, 0.0, 0.0), 0.0
        self._braking_input.current_position = [state.p]
        self._braking_input.current_velocity = [state.v]
        self._braking_input.current_acceleration = [state.a]
        result = self._ruckig.calculate(self._braking_input, self._braking)
        if result not in (Result.Working, Result.Finished):
            raise ScheduleError(f"Ruckig found no braking motion from {state}: {result}")
        t = min(period, self._braking.duration)
        (p,), (v,), (a,) = self._braking.at_time(t)
        if t >= self._braking.duration or v <= 0.0:
            return PathState(max(p, state.p), 0.0, 0.0), 0.0
        return PathState(p, v, a), ruckig_jerk(self._braking, t)

    def restart(self, measured: PathState, command: PathState, tip: float, tolerance: float) -> PathState:
        """A state to restart from at the measured travel, within the limits, that stops by ``tip``.

        The measured velocity and acceleration are taken where they differ from the commanded
        ones beyond ``tolerance`` (m/s: a stop, a slow drive); else the commanded ones go on (a
        position correction, or a drive closing a gap, does not change the motion asked of it).
        A state that could not stop by ``tip`` (the next reversal or frontier, metres of travel)
        gives way to one that can: coasting at its speed, else the commanded motion. A drive
        closing a gap measures a transient speed and acceleration; kept, they could carry the
        vehicle past its reversal or frontier, which the commanded motion would not.
        """
        p = measured.p
        if abs(measured.v - command.v) <= tolerance:
            measured = PathState(p, command.v, command.a)
        seed = self._within_limits(measured)
        if self._stops_by(seed, tip):
            return seed
        commanded = self._within_limits(PathState(p, command.v, command.a))
        for candidate in (
            PathState(p, seed.v, 0.0),
            commanded,
            PathState(p, commanded.v, min(commanded.a, 0.0)),
        ):
            if candidate.v <= seed.v and self._stops_by(candidate, tip):
                return candidate
        return seed

    def _within_limits(self, state: PathState) -> PathState:
        """``state`` with its velocity in ``[0, speed limit]`` and an acceleration it can zero within it."""
        top = self.speed_limit
        velocity = min(max(state.v, 0.0), top)
        most_acceleration = self._limits.max_acceleration
        acceleration = min(max(state.a, -most_acceleration), most_acceleration)
        room = top - velocity if acceleration > 0.0 else velocity
        most = math.sqrt(max(2.0 * self._limits.max_jerk * room, 0.0))  # a must reach 0 within [0, top]
        return PathState(state.p, velocity, min(max(acceleration, -most), most))

    def _stops_by(self, state: PathState, limit: float) -> bool:
        """Whether jerk-limited service braking from ``state`` comes to rest by travel ``limit``."""
        if limit == math.inf:
            return True
        return state.p + stopping_distance(state.v, state.a, self._limits) <= limit + 1e-9


def travel_state(path: VehiclePath, p: float, velocity: float, acceleration: float) -> PathState:
    """A state along ``path`` from axis velocity and acceleration (m/s, m/s²) at travel ``p``."""
    heading = path.heading(p)
    return PathState(p, heading * velocity, heading * acceleration)
