"""Quantities derived from routes and schedules: lower bounds and travelled distances."""

from __future__ import annotations

import numpy as np

from limits import Limits
from topology import Route
from topology.indexed import track_distance
from trajgen.profiles import rest_to_rest_time
from trajgen.schedule import Schedule

__all__ = ["lower_bound", "travelled"]


def lower_bound(route: Route, limits: Limits) -> float:
    """The larger of the vehicles' own jerk-limited rest-to-rest times over their shortest paths, seconds.

    Ignores the other vehicle entirely, so no schedule from the route's start
    to its goal can be faster.
    """
    graph = route.graph
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
    step = track_distance(state.leg[:, :-1], state.s[:, :-1], state.leg[:, 1:], state.s[:, 1:])
    distance = np.concatenate([np.zeros((2, 1)), np.cumsum(step, axis=1)], axis=1)
    return state.t, distance, state.leg, state.s
