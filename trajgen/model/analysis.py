"""Quantities derived from routes and schedules: lower bounds and travelled distances."""

from __future__ import annotations

import itertools

import numpy as np

from limits import Limits
from topology import Route
from topology.indexed import JUNCTION_INDEX, track_distance
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.profiles import rest_to_rest_time
from trajgen.model.schedule import Schedule

__all__ = ["class_lower_bound", "class_travel", "lower_bound", "travelled"]


def lower_bound(route: Route, limits: Limits) -> float:
    """The larger of the vehicles' own jerk-limited rest-to-rest times over their shortest paths, seconds.

    Ignores the other vehicle entirely, so no schedule from the route's start
    to its goal can be faster.
    """
    graph = route.track
    times = []
    for vehicle, (start, goal) in enumerate(zip(route.start, route.goal, strict=True)):
        vehicle_limits = limits.vehicles[vehicle]
        times.append(
            rest_to_rest_time(
                graph.distance(start, goal),
                vehicle_limits.max_velocity,
                vehicle_limits.max_acceleration,
                vehicle_limits.max_jerk,
            )
        )
    return max(times)


def class_travel(route: Route, min_separation: float) -> tuple[float, float]:
    """Least distance each vehicle drives on any motion in the route's homotopy class, metres.

    Every motion in the class passes the route's reduced region sequence in
    order (docs/planner.md, 'Homotopy classes'). Between two consecutive regions one vehicle
    crosses the junction while the other stays on its leg at least
    ``min_separation`` from it. Per vehicle, these checkpoints in order (at the
    junction; at least ``min_separation`` out on a leg), from its start to its
    goal, are met with least travel by moving, at each, only as far as it
    demands (on a half-line, projecting onto each successive interval is
    shortest).

    Parameters
    ----------
    route : Route
    min_separation : float
        Metres, >= 0.
    """
    keys = route.region_keys
    first, last = route.indexed_waypoints[0], route.indexed_waypoints[-1]
    out = []
    for vehicle in range(2):
        leg, s = first[2 * vehicle], first[2 * vehicle + 1]
        travel = 0.0
        for key, following in itertools.pairwise(keys):
            here = (key.first_leg, key.second_leg)[vehicle]
            there = (following.first_leg, following.second_leg)[vehicle]
            if leg == JUNCTION_INDEX:
                leg = here
            if here != there:  # this vehicle crosses the junction onto its next leg
                travel += s
                leg, s = there, 0.0
            elif s < min_separation:  # the other crosses: keep clear of the junction
                travel += min_separation - s
                s = min_separation
        travel += float(track_distance(leg, s, last[2 * vehicle], last[2 * vehicle + 1]))
        out.append(travel)
    return out[0], out[1]


def class_lower_bound(route: Route, limits: Limits) -> float:
    """A lower bound on the makespan of every motion in the route's homotopy class, seconds.

    The larger of :func:`lower_bound` and, per vehicle, the least time to drive
    its :func:`class_travel` from rest to rest under its velocity and
    acceleration limits (valid whatever the reversals: the speed ``|v|`` rises
    and falls at most at ``max_acceleration``). Used to skip a class that
    cannot beat a schedule already in hand.
    """
    travel = class_travel(route, max(route.min_separation, limits.min_separation))
    bounds = [
        rest_to_rest_time(distance, vehicle.max_velocity, vehicle.max_acceleration)
        for distance, vehicle in zip(travel, limits.vehicles, strict=True)
    ]
    return max(lower_bound(route, limits), *bounds)


def travelled(schedule: Schedule, period: float = 0.01):
    """Each vehicle's travelled distance over time and the track positions it passes.

    Parameters
    ----------
    schedule : Schedule
    period : float, optional
        Sample period, seconds.

    Returns
    -------
    (t, distance, leg, s)
        ``t`` shape (n,); ``distance``, ``leg``, ``s`` shape (2, n): odometer
        (metres, never decreasing), leg index and distance from the junction.
    """
    state = schedule.sample(period)
    if isinstance(schedule, GraphSchedule):  # its travel is kept: no need to add up the steps
        return state.t, state.travel, state.edge, state.s
    step = track_distance(state.leg[:, :-1], state.s[:, :-1], state.leg[:, 1:], state.s[:, 1:])
    distance = np.concatenate([np.zeros((2, 1)), np.cumsum(step, axis=1)], axis=1)
    return state.t, distance, state.leg, state.s
