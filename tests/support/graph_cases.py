"""Seeded random track-graph cases shared by the tests: feasible routes on trees and graphs with loops."""

from __future__ import annotations

import dataclasses

from limits import Limits, VehicleLimits
from tests.support.grid_oracle import random_case
from topology import InfeasibleError, TrackGraph, plan_graph


def random_routes(count: int, first_seed: int):
    """Seeded random track graphs (trees and graphs with loops) with a feasible route, two unequal AGVs."""
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    faster = dataclasses.replace(agv, max_velocity=1.4, max_jerk=2.0)
    found = 0
    for seed in range(first_seed, first_seed + 20 * count):
        case = random_case(seed, loops=seed % 2 == 1)
        if case is None:
            continue
        edges, start, goal, separation = case
        try:
            route = plan_graph(TrackGraph.from_edges(edges), start, goal, min_separation=separation)
        except InfeasibleError:
            continue
        yield seed, route, Limits((agv, faster), separation)
        found += 1
        if found == count:
            return
