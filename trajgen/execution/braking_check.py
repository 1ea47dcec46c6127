"""The braking check: whether the separation would hold if both vehicles started braking now.

Each vehicle's braking is bounded by two motions along its path: its
*service* braking from its commanded state (jerk-limited, at its
``max_acceleration`` and ``max_jerk``: the latest it can stop, computed with
Ruckig) and its *emergency* braking from its measured state (constant
``emergency_deceleration`` at once: the earliest). Between the two, the
vehicle is somewhere in a *tube* along its path. The check certifies that
at every instant the two tubes stay at least the required track distance
apart: time is cut into intervals, and on each the range a vehicle can
cover is widened by the most a motion of bounded acceleration can leave the
chord between its ends (``a * dt**2 / 8``), so nothing between the instants
is missed. That covers a leader stopping short in front of a follower (the
follower's service braking against the leader's emergency braking) and two
vehicles closing on each other (both at service braking).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory

from limits import VehicleLimits
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.model.paths import VehiclePath, set_distance

__all__ = ["BrakingCheck", "PathState", "ServiceBraking", "emergency_position"]

#: Time intervals tried in turn: a coarse pass is enough while the vehicles are far apart.
_REFINEMENTS = (1, 6, 40)
#: How often the finest pass may halve an interval that is not clear, for a hold (to 1/10,240 of the horizon).
_HALVINGS = 8
#: Below these a vehicle stands still (m/s, m/s²): it moves less than a micrometre while it brakes.
_STILL_VELOCITY = 1e-7
_STILL_ACCELERATION = 1e-6


@dataclass(frozen=True, slots=True)
class PathState:
    """A vehicle's state along its path: travel (m), its rate (m/s) and acceleration (m/s²)."""

    p: float
    v: float
    a: float


class ServiceBraking:
    """Jerk-limited braking to rest along a path (Ruckig's velocity interface, target v = a = 0).

    Parameters
    ----------
    limits : VehicleLimits
    """

    __slots__ = ("_generator", "_input", "_trajectory")

    def __init__(self, limits: VehicleLimits) -> None:
        self._generator = Ruckig(1)
        self._input = InputParameter(1)
        self._input.control_interface = ControlInterface.Velocity
        self._input.max_velocity = [limits.max_velocity]
        self._input.max_acceleration = [limits.max_acceleration]
        self._input.max_jerk = [limits.max_jerk]
        self._input.target_velocity = [0.0]
        self._input.target_acceleration = [0.0]
        self._trajectory = Trajectory(1)

    def trajectory(self, state: PathState) -> Trajectory:
        """Braking from ``state``; the returned trajectory is reused by the next call."""
        self._input.current_position = [state.p]
        self._input.current_velocity = [state.v]
        self._input.current_acceleration = [state.a]
        result = self._generator.calculate(self._input, self._trajectory)
        if result not in (Result.Working, Result.Finished):
            raise RuntimeError(f"ruckig could not plan a braking motion from {state}: {result}")
        return self._trajectory


def emergency_position(state: PathState, deceleration: float, t: float) -> float:
    """Travel ``t`` seconds into an emergency stop at constant ``deceleration`` (m/s²) from ``state``."""
    v = state.v
    if v == 0.0:
        return state.p
    t = min(t, abs(v) / deceleration)
    return state.p + v * t - math.copysign(0.5 * deceleration * t * t, v)


class BrakingCheck:
    """Certifies that both vehicles braking now keep a track distance.

    Parameters
    ----------
    limits : tuple of 2 VehicleLimits
    emergency : tuple of 2 float
        Emergency deceleration of each vehicle, m/s².
    track : tuple of float, shape (k,), or GraphMetric
        A junction's legs (3 to 8), metres, whose paths are :class:`~trajgen.model.paths.VehiclePath`;
        or a track graph's metric, whose paths are
        :class:`~trajgen.model.graph_vehicle_path.GraphVehiclePath`.
    """

    __slots__ = ("_braking", "_emergency", "_lengths", "_metric", "_pad_acceleration")

    def __init__(
        self,
        limits: tuple[VehicleLimits, VehicleLimits],
        emergency: tuple[float, float],
        track: tuple[float, ...] | GraphMetric,
    ) -> None:
        self._braking = (ServiceBraking(limits[0]), ServiceBraking(limits[1]))
        self._emergency = emergency
        self._metric = track if isinstance(track, GraphMetric) else None
        self._lengths = None if self._metric is not None else tuple(track)
        self._pad_acceleration = tuple(
            max(lim.max_acceleration, e) for lim, e in zip(limits, emergency, strict=True)
        )

    def _sweep(self, path, low: float, high: float) -> tuple[tuple, float]:
        """The track ``path`` covers while its travel runs over ``[low, high]``, and its overrun.

        The overrun: metres the vehicle may be beyond those stretches (past a clipped end of its
        path's end segments).
        """
        if self._lengths is None:
            return path.sweep(low, high), path.overrun(low, high)
        return path.sweep(low, high, self._lengths), path.overrun(low, high, self._lengths)

    def _apart(self, first: tuple[tuple, float], second: tuple[tuple, float]) -> float:
        """A sound track distance between two swept sets and their overruns, metres."""
        (stretches_a, overrun_a), (stretches_b, overrun_b) = first, second
        gap = (
            set_distance(stretches_a, stretches_b)
            if self._metric is None
            else self._metric.set_distance(stretches_a, stretches_b)
        )
        return gap - overrun_a - overrun_b

    def service(self, vehicle: int) -> ServiceBraking:
        """The service braking of ``vehicle`` (0 or 1)."""
        return self._braking[vehicle]

    def clearance(
        self,
        paths: tuple[VehiclePath, VehiclePath] | tuple[GraphVehiclePath, GraphVehiclePath],
        commanded: tuple[PathState, PathState],
        measured: tuple[PathState, PathState],
        required: float,
        *,
        refine: bool = False,
    ) -> bool:
        """Whether the braking tubes stay at least ``required`` metres apart until both are at rest.

        Parameters
        ----------
        paths : tuple of 2 VehiclePath, or of 2 GraphVehiclePath on a track graph
        commanded : tuple of 2 PathState
            The states about to be commanded (service braking starts there).
        measured : tuple of 2 PathState
            The measured states (emergency braking starts there).
        required : float
            Track distance to keep, metres.
        refine : bool, optional
            Halve the finest pass's unclear intervals (:meth:`_intervals_clear`): for a hold, which
            must not be refused for the intervals' pessimism. New motion is certified without, and
            that pessimism is the room a later hold has.
        """
        trajectories = [
            braking.trajectory(state) for braking, state in zip(self._braking, commanded, strict=True)
        ]
        durations = [t.duration for t in trajectories]
        ends = [t.at_time(d)[0][0] for t, d in zip(trajectories, durations, strict=True)]
        horizon = max(
            *durations,
            *(abs(m.v) / e for m, e in zip(measured, self._emergency, strict=True)),
        )
        # the extra acceleration a measured state may carry beyond the limits widens the pad
        # a vehicle at rest in both states does not move at all: no pad
        # a vehicle at rest in both states (to the drive's noise) does not move at all: no pad, so a
        # plan with no clearance, where a vehicle waits exactly the separation away, can be certified
        pads = [
            max(pad, abs(c.a), abs(m.a))
            if abs(c.v) > _STILL_VELOCITY or abs(c.a) > _STILL_ACCELERATION or abs(m.v) > _STILL_VELOCITY
            else 0.0
            for pad, c, m in zip(self._pad_acceleration, commanded, measured, strict=True)
        ]
        for count in _REFINEMENTS:
            halvings = _HALVINGS if refine and count == _REFINEMENTS[-1] else 0
            if self._intervals_clear(
                paths, trajectories, durations, ends, measured, required, horizon, count, pads, halvings
            ):
                return True
        return False

    def _bounds(self, trajectories, durations, ends, measured, t: float) -> list[tuple[float, float]]:
        """Each vehicle's travel range at ``t``: between its emergency and its service braking."""
        bounds = []
        for vehicle in (0, 1):
            if t >= durations[vehicle]:
                upper = ends[vehicle]
            else:
                (upper,), _, _ = trajectories[vehicle].at_time(t)
            lower = emergency_position(measured[vehicle], self._emergency[vehicle], t)
            bounds.append((min(lower, upper), max(lower, upper)))
        return bounds

    def _intervals_clear(
        self, paths, trajectories, durations, ends, measured, required, horizon, count, pads, halvings
    ) -> bool:
        """Whether ``count`` equal intervals of ``[0, horizon]`` are clear.

        An interval that is not clear is halved, up to ``halvings`` times: an
        interval's sweep is pessimistic by about the distance both vehicles drive over it, so tubes that
        pass within a millimetre of the separation are told apart from a real conflict, with a few
        more evaluations only where they are close. Where the tubes meet at an instant, the conflict
        is real and the check ends there.
        """
        step = horizon / count
        previous = self._bounds(trajectories, durations, ends, measured, 0.0)
        for k in range(1, count + 1):
            bounds = self._bounds(trajectories, durations, ends, measured, k * step)
            pending = [((k - 1) * step, k * step, previous, bounds, halvings)]
            while pending:
                start, end, first, last, left = pending.pop()
                width = end - start
                sets = []
                for vehicle in (0, 1):
                    pad = pads[vehicle] * width * width / 8.0
                    low = min(first[vehicle][0], last[vehicle][0]) - pad
                    high = max(first[vehicle][1], last[vehicle][1]) + pad
                    sets.append(self._sweep(paths[vehicle], low, high))
                if self._apart(sets[0], sets[1]) >= required:
                    continue
                if not left:
                    return False
                middle = 0.5 * (start + end)
                between = self._bounds(trajectories, durations, ends, measured, middle)
                at_middle = [self._sweep(paths[v], between[v][0], between[v][1]) for v in (0, 1)]
                if self._apart(at_middle[0], at_middle[1]) < required:
                    return False  # not the intervals' pessimism: the tubes meet at that instant
                pending.append((middle, end, between, last, left - 1))
                pending.append((start, middle, first, between, left - 1))
            previous = bounds
        return True
