"""The route in the plane of the two vehicles' signed axes, and the motion along its straight pieces.

Shared by the timing methods: the route's waypoints on each vehicle's signed
axis (odometer along its own path, positive in the direction of its first
move), the maximal straight pieces of that polyline (where both vehicles come
to rest in ``exact``), the axis-to-track maps of a run of segments, and the
time-optimal rest-to-rest motion along one straight piece.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import JUNCTION_INDEX, Route
from trajgen.model.paths import MOVE_RESOLUTION
from trajgen.model.profiles import PiecewiseCubic, scurve_phases, trapezoid_phases
from trajgen.model.schedule import AxisMap
from trajgen.model.values import ArrayValue, readonly

__all__ = ["RouteAxes", "piece_maps", "piece_profiles", "route_axes", "straight_pieces"]


@dataclass(frozen=True, slots=True, eq=False)
class RouteAxes(ArrayValue):
    """The route's waypoints expressed on the vehicles' signed axes.

    Attributes
    ----------
    axes : ndarray, shape (n, 2)
        Signed axis of vehicle 1 and vehicle 2 at each waypoint, metres.
    legs : ndarray of int, shape (n - 1, 2)
        Leg index of each vehicle in each segment (``JUNCTION_INDEX``: parked at the junction).
    s_start : ndarray, shape (n - 1, 2)
        Distance from the junction at the start of each segment, metres.
    outward : ndarray of int, shape (n - 1, 2)
        ``ds/daxis`` of each vehicle in each segment: +1, -1 (0 if it does not move).
    parked : tuple of 2 AxisMap
        Maps of a route that does not move at all (one waypoint).
    """

    axes: np.ndarray
    legs: np.ndarray
    s_start: np.ndarray
    outward: np.ndarray
    parked: tuple[AxisMap, AxisMap]

    def __post_init__(self) -> None:
        for name, dtype in (("axes", float), ("legs", int), ("s_start", float), ("outward", int)):
            object.__setattr__(self, name, readonly(getattr(self, name), dtype))


def route_axes(route: Route) -> RouteAxes:
    """Signed axes of both vehicles along a route (positive: direction of first move)."""
    tuples = route.indexed_waypoints
    n = len(tuples)
    axes = np.zeros((n, 2))
    legs = np.full((max(n - 1, 0), 2), JUNCTION_INDEX, dtype=int)
    s_start = np.zeros((max(n - 1, 0), 2))
    outward = np.zeros((max(n - 1, 0), 2), dtype=int)
    for vehicle in range(2):
        heading = 0  # +1 moving outward, -1 inward (toward the junction), in the current leg
        heading_leg = JUNCTION_INDEX
        sign = 1  # axis direction relative to the vehicle's current direction of travel
        started = False
        for k in range(n - 1):
            leg_a, s_a = tuples[k][2 * vehicle], tuples[k][2 * vehicle + 1]
            leg_b, s_b = tuples[k + 1][2 * vehicle], tuples[k + 1][2 * vehicle + 1]
            leg = leg_a if leg_a != JUNCTION_INDEX else leg_b
            legs[k, vehicle] = leg
            s_start[k, vehicle] = s_a
            step = s_b - s_a
            if step == 0.0:
                axes[k + 1, vehicle] = axes[k, vehicle]
                continue
            direction = 1 if step > 0 else -1
            # round-off of the planner (a few 1e-14 m) is no move of its own: it neither sets the axis's
            # positive direction nor reverses it (VehiclePath ignores it too)
            if abs(step) > MOVE_RESOLUTION:
                if started:
                    through_junction = heading == -1 and direction == 1 and leg != heading_leg
                    if direction != heading and not through_junction:
                        sign = -sign  # the vehicle reverses
                started = True
                heading, heading_leg = direction, leg
            # axis moves by sign * |step|; ds/daxis = direction * sign
            axes[k + 1, vehicle] = axes[k, vehicle] + sign * abs(step)
            outward[k, vehicle] = direction * sign
    first = tuples[0]
    parked = (AxisMap.parked(0.0, first[0], first[1]), AxisMap.parked(0.0, first[2], first[3]))
    return RouteAxes(axes=axes, legs=legs, s_start=s_start, outward=outward, parked=parked)


def straight_pieces(axes: np.ndarray) -> list[tuple[int, int]]:
    """Maximal runs of route segments along one direction of the axis plane.

    Parameters
    ----------
    axes : ndarray, shape (n, 2)
        Waypoints on the signed axes, metres.

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


def piece_maps(axes: RouteAxes, first: int, last: int) -> tuple[AxisMap, AxisMap]:
    """Axis maps of both vehicles over waypoints ``first..last`` of a route (``last > first``)."""
    maps = []
    for vehicle in range(2):
        moving = [k for k in range(first, last) if axes.outward[k, vehicle] != 0]
        if not moving:  # parked for the whole section
            s = float(axes.s_start[first, vehicle])
            leg = int(axes.legs[first, vehicle]) if s > 0 else JUNCTION_INDEX
            maps.append(AxisMap.parked(float(axes.axes[first, vehicle]), leg, s))
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


def _progress_limits(delta: np.ndarray, limits: Limits) -> tuple[float, float, float]:
    """Velocity, acceleration and jerk limits on the progress fraction along a piece moving by ``delta``."""
    v = a = j = np.inf
    for vehicle, move in enumerate(np.abs(delta)):
        if move > 0.0:
            vehicle_limits = limits.vehicles[vehicle]
            v = min(v, vehicle_limits.max_velocity / move)
            a = min(a, vehicle_limits.max_acceleration / move)
            j = min(j, vehicle_limits.max_jerk / move)
    return float(v), float(a), float(j)


#: Metres below which a vehicle's share of a straight piece is round-off, not a move.
_NO_MOVE = 1e-12


def piece_profiles(
    start: np.ndarray, end: np.ndarray, limits: Limits, *, jerk: bool = True
) -> tuple[PiecewiseCubic, ...]:
    """Every vehicle's axis along one straight piece, rest to rest, time-optimal under the scaled limits.

    Parameters
    ----------
    start, end : ndarray, shape (m,)
        Axes (or travels) of the m vehicles at the piece's ends, metres.
    limits : Limits
    jerk : bool
        S-curve (jerk-limited) if True, else trapezoid (velocity and acceleration only).
    """
    # a share of less than a picometre (a planner's round-off, down to 5e-324 m) is no move: its limits
    # on the progress would overflow; its profile still ends exactly at ``end`` (spread over the piece),
    # unless no share moves: then every vehicle rests where it is, under a picometre from ``end``
    delta = np.where(np.abs(end - start) < _NO_MOVE, 0.0, end - start)
    if not np.any(delta):  # nothing moves (start is the goal): at rest, zero duration
        return tuple(PiecewiseCubic.from_phases(float(value), []) for value in start)
    v, a, j = _progress_limits(delta, limits)
    if jerk:
        phases = [(d, np.nan, value) for d, value in scurve_phases(1.0, v, a, j)]
    else:
        phases = [(d, value, 0.0) for d, value in trapezoid_phases(1.0, v, a)]
    profiles = []
    for vehicle in range(len(start)):
        scaled = [(d, acc * delta[vehicle], jk * delta[vehicle]) for d, acc, jk in phases]
        profiles.append(PiecewiseCubic.from_phases(float(start[vehicle]), scaled, end=float(end[vehicle])))
    return tuple(profiles)
