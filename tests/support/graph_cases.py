"""Track-graph cases shared by the tests.

The examples' verified schedules, seeded random routes on trees and graphs with loops, and small
scenarios written out.
"""

from __future__ import annotations

import dataclasses
import functools

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.grid_oracle import random_case
from topology import InfeasibleError, TrackGraph, plan_graph
from trajgen import certify
from trajgen.methods import make_schedule
from trajgen.scenario import load_scenario

#: The example graph scenarios.
EXAMPLES = REPO / "examples" / "graphs"


@functools.cache
def verified_example(name: str, method: str):
    """The example ``name``'s scenario and its verified schedule by ``method``, once per process.

    Several test files use the same schedules (the optimal H takes seconds); all are immutable.
    """
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    return scenario, certify(make_schedule(scenario.route(), scenario.limits, method=method))


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


#: agv2 starts 1 µm inside the separation from J1: it backs off 1 µm while agv1 passes, and returns.
TINY_BACK_OFF = """
[track.nodes]
J1 = [0.0, 0.0]
J2 = [8.0, 0.0]
A = [0.0, 6.0]
B = [-5.0, -4.0]
C = [8.0, 6.0]
D = [13.0, -4.0]
[track.edges]
a = { from = "J1", to = "A" }
b = { from = "J1", to = "B", length = 6.5 }
m = { from = "J1", to = "J2" }
c = { from = "J2", to = "C" }
e = { from = "J2", to = "D", length = 6.5 }
[safety]
min_separation = 1.5
[[vehicle]]
name = "agv1"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "A"
goal = "D"
[[vehicle]]
name = "agv2"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "b:1.499999"
goal = "b:1.499999"
"""

#: agv1 follows agv2 onto edge e and parks exactly the separation behind it.
CONVOY = """
[track]
nodes = { W = [0.0, 0.0], J = [10.0, 0.0], E = [20.0, 0.0], S = [10.0, 5.0] }
[track.edges]
w = { from = "W", to = "J" }
e = { from = "J", to = "E" }
s = { from = "J", to = "S" }
[safety]
min_separation = 1.5
[[vehicle]]
name = "agv1"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "w:2"
goal = "e:5.5"
[[vehicle]]
name = "agv2"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "w:5"
goal = "e:7"
"""
