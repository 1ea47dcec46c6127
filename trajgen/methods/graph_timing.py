"""Timing a route on a track graph (docs/graphs.md).

The planner's route on a track graph moves one vehicle at a time. ``exact`` times it as it is: each
move rest to rest with the time-optimal S-curve (closed form) of its vehicle's limits, the other
vehicle standing; ``exact`` without jerk takes the trapezoids instead. Each vehicle's travel over
time is one piecewise cubic (:class:`~trajgen.model.graph_schedule.GraphSchedule`).
"""

from __future__ import annotations

import math

from limits import Limits
from topology import GraphRoute
from trajgen.errors import InputError
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.profiles import PiecewiseCubic, scurve_phases, trapezoid_phases
from trajgen.model.schedule import CubicKinematics

__all__ = ["check_graph_request", "moves_one_at_a_time"]


def check_graph_request(route: object, limits: object) -> tuple[GraphRoute, Limits]:
    """Return ``(route, limits)`` if a method can time them on a track graph, else raise InputError."""
    if not isinstance(route, GraphRoute):
        raise InputError(f"route must be a topology.GraphRoute, got {type(route).__name__}")
    if not isinstance(limits, Limits):
        raise InputError(f"limits must be a limits.Limits, got {type(limits).__name__}")
    if route.min_separation < limits.min_separation:
        raise InputError(
            f"the route was planned for a min_separation of {route.min_separation!r} m but the limits ask "
            f"{limits.min_separation!r} m: plan it with "
            f"plan_graph(..., min_separation={limits.min_separation!r})"
        )
    return route, limits


def moves_one_at_a_time(route: GraphRoute, limits: Limits, method, *, jerk: bool) -> GraphSchedule:
    """The route's moves one after the other, each rest to rest and time-optimal for its vehicle.

    Parameters
    ----------
    route : GraphRoute
    limits : Limits
    method : TimingMethod
        Recorded in the schedule.
    jerk : bool
        S-curves (jerk-limited) if True, else trapezoids.
    """
    check_graph_request(route, limits)
    paths = graph_paths(route)
    phases: tuple[list, list] = ([], [])
    for move in route.moves:
        if move.length <= 0.0:
            continue
        vehicle = limits.vehicles[move.vehicle]
        if jerk:
            moving = [
                (d, math.nan, value)
                for d, value in scurve_phases(
                    move.length, vehicle.max_velocity, vehicle.max_acceleration, vehicle.max_jerk
                )
            ]
        else:
            moving = [
                (d, value, 0.0)
                for d, value in trapezoid_phases(move.length, vehicle.max_velocity, vehicle.max_acceleration)
            ]
        phases[move.vehicle].extend(moving)
        phases[1 - move.vehicle].append((sum(d for d, _, _ in moving), 0.0, 0.0))  # the other stands
    profiles = tuple(PiecewiseCubic.from_phases(0.0, phases[v], end=paths[v].length) for v in range(2))
    return GraphSchedule(
        route,
        limits,
        method,
        paths,
        CubicKinematics(profiles),
        jerk_limited=jerk,  # type: ignore[arg-type]
    )
