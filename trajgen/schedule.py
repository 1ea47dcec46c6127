"""Schedules: the two vehicles' motion over time along a planned route.

A :class:`Schedule` is a sequence of :class:`Section` s in time. Within a
section each vehicle's *signed axis* (its odometer along its own path,
positive in the direction of its first move, decreasing when it reverses)
maps monotonically onto the track, so the track position at any time follows
from the axis value. Methods:

- ``exact``: the planner's route followed exactly; along each straight piece
  of the route (in the plane of the two axes) a time-optimal jerk-limited
  rest-to-rest S-curve under both vehicles' limits scaled to the piece.
- ``toppra``: corners rounded where safe, then TOPPRA (velocity and
  acceleration limits; jerk not limited). See :mod:`trajgen.toppra_timing`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from limits import Limits
from topology import Configuration, Route
from topology.errors import InputError
from topology.graph import _finite_real
from topology.options import Option
from trajgen.profiles import PiecewiseCubic, scurve_phases, trapezoid_phases

__all__ = [
    "AxisMap",
    "Method",
    "RouteAxes",
    "Schedule",
    "ScheduleState",
    "Section",
    "check_period",
    "exact_schedule",
    "make_schedule",
    "route_axes",
]

logger = logging.getLogger(__name__)

_AT_JUNCTION = -1


class Method(Option):
    """How a route is turned into a schedule."""

    EXACT = "exact"  #: the route exactly, one straight piece at a time, jerk-limited S-curves
    TOPPRA = "toppra"  #: rounded corners where safe, TOPPRA velocity/acceleration-limited timing
    OPTIMAL = "optimal"  #: time-optimal jerk-limited schedule in the route's homotopy class (CasADi)


def check_period(period: float) -> float:
    """Return a sample period in seconds if it is finite and > 0, else raise InputError."""
    value = _finite_real(period, "sample period (seconds)", InputError)
    if value <= 0.0:
        raise InputError(f"sample period must be > 0 s, got {value!r}")
    return value


# -- the route in the plane of the two signed axes ---------------------------------------------------


@dataclass(frozen=True, slots=True)
class RouteAxes:
    """The route's waypoints expressed on the vehicles' signed axes.

    Attributes
    ----------
    axes : ndarray, shape (n, 2)
        Signed axis of vehicle 1 and vehicle 2 at each waypoint, metres.
    legs : ndarray of int, shape (n - 1, 2)
        Leg index of each vehicle in each segment (-1: parked at the junction).
    s_start : ndarray, shape (n - 1, 2)
        Distance from the junction at the start of each segment, metres.
    outward : ndarray of int, shape (n - 1, 2)
        ``ds/daxis`` of each vehicle in each segment: +1, -1 (0 if it does not move).
    """

    axes: np.ndarray
    legs: np.ndarray
    s_start: np.ndarray
    outward: np.ndarray


def route_axes(route: Route) -> RouteAxes:
    """Signed axes of both vehicles along a route (positive: direction of first move)."""
    tuples = route._tuples
    n = len(tuples)
    axes = np.zeros((n, 2))
    legs = np.full((max(n - 1, 0), 2), _AT_JUNCTION, dtype=int)
    s_start = np.zeros((max(n - 1, 0), 2))
    outward = np.zeros((max(n - 1, 0), 2), dtype=int)
    for vehicle in range(2):
        heading = 0  # +1 moving outward, -1 inward (toward the junction), in the current leg
        heading_leg = _AT_JUNCTION
        sign = 1  # axis direction relative to the vehicle's current direction of travel
        started = False
        for k in range(n - 1):
            leg_a, s_a = tuples[k][2 * vehicle], tuples[k][2 * vehicle + 1]
            leg_b, s_b = tuples[k + 1][2 * vehicle], tuples[k + 1][2 * vehicle + 1]
            leg = leg_a if leg_a != _AT_JUNCTION else leg_b
            legs[k, vehicle] = leg
            s_start[k, vehicle] = s_a
            step = s_b - s_a
            if step == 0.0:
                axes[k + 1, vehicle] = axes[k, vehicle]
                continue
            direction = 1 if step > 0 else -1
            if started:
                through_junction = heading == -1 and direction == 1 and leg != heading_leg
                if direction != heading and not through_junction:
                    sign = -sign  # the vehicle reverses
            started = True
            heading, heading_leg = direction, leg
            # axis moves by sign * |step|; ds/daxis = direction * sign
            axes[k + 1, vehicle] = axes[k, vehicle] + sign * abs(step)
            outward[k, vehicle] = direction * sign
    return RouteAxes(axes=axes, legs=legs, s_start=s_start, outward=outward)


def straight_pieces(axes: np.ndarray) -> list[tuple[int, int]]:
    """Maximal runs of route segments along one direction of the axis plane.

    Returns
    -------
    list of (first waypoint, last waypoint)
        Waypoint index ranges; the vehicles come to rest at every range end.
    """
    pieces: list[tuple[int, int]] = []
    n = len(axes)
    k = 0
    while k < n - 1:
        direction = axes[k + 1] - axes[k]
        end = k + 1
        while end < n - 1:
            following = axes[end + 1] - axes[end]
            cross = direction[0] * following[1] - direction[1] * following[0]
            scale = np.linalg.norm(direction) * np.linalg.norm(following)
            if abs(cross) > 1e-12 * scale or float(np.dot(direction, following)) <= 0.0:
                break
            end += 1
        pieces.append((k, end))
        k = end
    return pieces


# -- sections and schedules ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class AxisMap:
    """Where one vehicle is on the track as a function of its signed axis, within one section.

    Sub-ranges of the axis, each on one leg, in the order the vehicle drives
    them; ``s = s_start + outward * (axis - axis_start)``.

    Attributes
    ----------
    axis_start, axis_end : ndarray, shape (r,)
        Axis at the start and end of each sub-range, metres.
    legs : ndarray of int, shape (r,)
        Leg index (-1: at the junction).
    s_start : ndarray, shape (r,)
        Distance from the junction at ``axis_start``, metres.
    outward : ndarray of int, shape (r,)
        ``ds/daxis``: +1, -1, or 0 when the vehicle does not move.
    """

    axis_start: np.ndarray
    axis_end: np.ndarray
    legs: np.ndarray
    s_start: np.ndarray
    outward: np.ndarray

    def locate(self, axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Leg index and distance from the junction for axis values, shape (n,) each.

        A value outside every sub-range (round-off at the ends) takes the
        nearest sub-range; ``s`` is clipped at 0 (the junction). With a single
        sub-range the vehicle stays on one leg, where the affine map holds for
        every axis value (it may drive back and forth).
        """
        axis = np.asarray(axis, dtype=float)
        if len(self.legs) == 1:
            s = np.maximum(self.s_start[0] + self.outward[0] * (axis - self.axis_start[0]), 0.0)
            return np.where(s > 0.0, self.legs[0], _AT_JUNCTION), s
        low = np.minimum(self.axis_start, self.axis_end)
        high = np.maximum(self.axis_start, self.axis_end)
        gap = np.maximum(low[:, None] - axis[None, :], 0.0) + np.maximum(axis[None, :] - high[:, None], 0.0)
        r = np.argmin(gap, axis=0)
        s = self.s_start[r] + self.outward[r] * (np.clip(axis, low[r], high[r]) - self.axis_start[r])
        s = np.maximum(s, 0.0)
        legs = np.where(s > 0.0, self.legs[r], _AT_JUNCTION)
        return legs, s


class Kinematics:
    """Interface of a section's motion: both vehicles' signed-axis kinematics over local time."""

    duration: float

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """Axis, velocity, acceleration, jerk of both vehicles; shape (2, 4, n). ``t`` in [0, duration]."""
        raise NotImplementedError


@dataclass(frozen=True, slots=True)
class CubicKinematics(Kinematics):
    """Both vehicles as piecewise cubics (constant jerk between breakpoints)."""

    vehicles: tuple[PiecewiseCubic, PiecewiseCubic]

    @property
    def duration(self) -> float:
        return max(self.vehicles[0].duration, self.vehicles[1].duration)

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        return np.stack([profile.evaluate(t) for profile in self.vehicles])


@dataclass(frozen=True, slots=True)
class Section:
    """A stretch of a schedule in which each vehicle's axis maps monotonically onto the track.

    Attributes
    ----------
    start_time : float
        Seconds from the start of the schedule.
    kinematics : Kinematics
        Motion of both signed axes over the section's local time.
    maps : tuple of 2 AxisMap
        Axis -> track position, per vehicle.
    """

    start_time: float
    kinematics: Kinematics
    maps: tuple[AxisMap, AxisMap]

    @property
    def duration(self) -> float:
        """Seconds."""
        return self.kinematics.duration


@dataclass(frozen=True, slots=True)
class ScheduleState:
    """States of both vehicles at sample times.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times, seconds.
    axis, velocity, acceleration, jerk : ndarray, shape (2, n)
        Per vehicle: signed axis (m), its velocity (m/s), acceleration (m/s²), jerk (m/s³).
    leg : ndarray of int, shape (2, n)
        Leg index (0, 1, 2 in the track's order) or -1 at the junction.
    s : ndarray, shape (2, n)
        Distance from the junction, metres.
    """

    t: np.ndarray
    axis: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    leg: np.ndarray
    s: np.ndarray


@dataclass(frozen=True, slots=True)
class Schedule:
    """A timed motion of both vehicles along a route.

    Attributes
    ----------
    route : Route
        The planner's route (its homotopy class is the schedule's).
    limits : Limits
        The vehicle limits and separation it was computed for.
    method : Method
        How it was computed.
    sections : tuple of Section
        Consecutive in time, the first at t = 0.
    jerk_limited : bool
        Whether the method limits jerk (``toppra`` does not).
    notes : tuple of str
        What the method did that a user should know (e.g. corners rounded).
    fallback_reason : str or None
        Set when a method could not deliver and this is the ``exact``
        schedule in its place; says why.
    info : object or None
        Method diagnostics (e.g. :class:`trajgen.optimal.OptimalInfo`).
    """

    route: Route
    limits: Limits
    method: Method
    sections: tuple[Section, ...]
    jerk_limited: bool
    notes: tuple[str, ...] = ()
    fallback_reason: str | None = None
    info: object = field(default=None, compare=False)
    _starts: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_starts", np.array([section.start_time for section in self.sections]))

    @property
    def duration(self) -> float:
        """Makespan: time until both vehicles are at rest at the goal, seconds."""
        last = self.sections[-1]
        return last.start_time + last.duration

    def state(self, t) -> ScheduleState:
        """States of both vehicles at times ``t`` (seconds, clipped to [0, duration]).

        Parameters
        ----------
        t : float or array_like, shape (n,)
        """
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        index = np.clip(np.searchsorted(self._starts, t, side="right") - 1, 0, len(self.sections) - 1)
        kin = np.zeros((2, 4, t.size))
        leg = np.zeros((2, t.size), dtype=int)
        s = np.zeros((2, t.size))
        for k, section in enumerate(self.sections):
            mask = index == k
            if not mask.any():
                continue
            local = np.clip(t[mask] - section.start_time, 0.0, section.duration)
            values = section.kinematics.evaluate(local)
            kin[:, :, mask] = values
            for vehicle in range(2):
                leg[vehicle, mask], s[vehicle, mask] = section.maps[vehicle].locate(values[vehicle, 0])
        return ScheduleState(t, kin[:, 0], kin[:, 1], kin[:, 2], kin[:, 3], leg, s)

    def sample(self, period: float) -> ScheduleState:
        """States every ``period`` seconds from t = 0, plus a last sample exactly at the goal."""
        period = check_period(period)
        count = int(np.floor(self.duration / period + 1e-9))
        times = np.arange(count + 1) * period
        if self.duration - times[-1] > 1e-9 * max(1.0, self.duration):
            times = np.append(times, self.duration)
        else:
            times[-1] = self.duration
        return self.state(times)

    def configuration_at(self, t: float) -> Configuration:
        """The two vehicles' positions at time ``t`` as a Configuration."""
        from topology import Position

        state = self.state(t)
        graph = self.route.graph
        positions = []
        for v in range(2):
            leg, s = int(state.leg[v, 0]), float(state.s[v, 0])
            if leg >= 0 and 0.0 < s - graph.lengths[leg] <= 1e-6:
                s = graph.lengths[leg]  # round-off at a leg's end; larger overruns still raise
            positions.append(Position(graph.names[leg] if leg >= 0 else None, s))
        return Configuration(*positions)


def _piece_maps(axes: RouteAxes, first: int, last: int) -> tuple[AxisMap, AxisMap]:
    """Axis maps of both vehicles over waypoints first..last of a route."""
    maps = []
    for vehicle in range(2):
        moving = [k for k in range(first, last) if axes.outward[k, vehicle] != 0]
        if not moving:  # parked for the whole section
            k = first
            leg = axes.legs[k, vehicle] if axes.s_start[k, vehicle] > 0 else _AT_JUNCTION
            value = axes.axes[first, vehicle]
            maps.append(
                AxisMap(
                    np.array([value]),
                    np.array([value]),
                    np.array([leg]),
                    np.array([axes.s_start[k, vehicle]]),
                    np.array([0]),
                )
            )
            continue
        maps.append(
            AxisMap(
                axis_start=axes.axes[moving, vehicle],
                axis_end=axes.axes[[k + 1 for k in moving], vehicle],
                legs=axes.legs[moving, vehicle],
                s_start=axes.s_start[moving, vehicle],
                outward=axes.outward[moving, vehicle],
            )
        )
    return maps[0], maps[1]


def _scaled_limits(delta: np.ndarray, limits: Limits, *, jerk: bool) -> tuple[float, float, float | None]:
    """Limits on the progress fraction along a straight piece moving the axes by ``delta``."""
    v = a = j = np.inf
    for vehicle, move in enumerate(np.abs(delta)):
        if move > 0.0:
            vehicle_limits = limits.vehicles[vehicle]
            v = min(v, vehicle_limits.max_velocity / move)
            a = min(a, vehicle_limits.max_acceleration / move)
            j = min(j, vehicle_limits.max_jerk / move)
    return float(v), float(a), (float(j) if jerk else None)


def piece_profiles(
    start: np.ndarray, end: np.ndarray, limits: Limits, *, jerk: bool = True
) -> tuple[PiecewiseCubic, PiecewiseCubic]:
    """Both axes along one straight piece, rest to rest, time-optimal under the scaled limits.

    Parameters
    ----------
    start, end : ndarray, shape (2,)
        Axes of both vehicles at the piece's ends, metres.
    jerk : bool
        S-curve (jerk-limited) if True, else trapezoid (velocity and acceleration only).
    """
    delta = end - start
    v, a, j = _scaled_limits(delta, limits, jerk=jerk)
    if jerk:
        phases = [(d, np.nan, value) for d, value in scurve_phases(1.0, v, a, j)]
    else:
        phases = [(d, value, 0.0) for d, value in trapezoid_phases(1.0, v, a)]
    profiles = []
    for vehicle in range(2):
        scaled = [(d, acc * delta[vehicle], jk * delta[vehicle]) for d, acc, jk in phases]
        profiles.append(PiecewiseCubic.from_phases(float(start[vehicle]), scaled, end=float(end[vehicle])))
    return profiles[0], profiles[1]


def exact_schedule(route: Route, limits: Limits, *, jerk: bool = True) -> Schedule:
    """The route followed exactly, one straight piece at a time, rest to rest.

    Parameters
    ----------
    route : Route
    limits : Limits
    jerk : bool, optional
        Jerk-limited S-curves (default). ``False`` gives velocity/acceleration
        limited trapezoids, the reference that ``toppra`` must never be slower than.
    """
    axes = route_axes(route)
    sections = []
    clock = 0.0
    for first, last in straight_pieces(axes.axes) or [(0, 0)]:
        profiles = piece_profiles(axes.axes[first], axes.axes[last], limits, jerk=jerk)
        maps = _piece_maps(axes, first, last) if last > first else _parked_maps(route)
        section = Section(clock, CubicKinematics(profiles), maps)
        sections.append(section)
        clock += section.duration
    return Schedule(route, limits, Method.EXACT, tuple(sections), jerk_limited=jerk)


def _parked_maps(route: Route) -> tuple[AxisMap, AxisMap]:
    """Axis maps for a route that does not move (start is goal on the boundary)."""
    c = route._tuples[0]
    return tuple(
        AxisMap(
            np.zeros(1), np.zeros(1), np.array([c[2 * v]]), np.array([c[2 * v + 1]]), np.zeros(1, dtype=int)
        )
        for v in range(2)
    )  # type: ignore[return-value]


def make_schedule(route: Route, limits: Limits, *, method: Method | str = Method.OPTIMAL) -> Schedule:
    """Time-parameterize a route with the chosen method (unverified; see :func:`trajgen.verify.verify`).

    The default, ``optimal``, is the fastest jerk-limited schedule in the route's
    homotopy class (or the ``exact`` schedule, flagged, if its solvers fail).
    """
    method = Method.lookup(method) if not isinstance(method, Method) else method
    if method is Method.EXACT:
        return exact_schedule(route, limits)
    if method is Method.OPTIMAL:
        from trajgen.optimal import optimal_schedule

        return optimal_schedule(route, limits)
    from trajgen.toppra_timing import toppra_schedule

    return toppra_schedule(route, limits)
