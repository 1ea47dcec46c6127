"""A junction's route timed on its track graph against the junction's own timing (issue 49, item 3).

Run: ``python benchmarks/bench_junction_on_graph.py [--random N] [--seed S]``.

Each scenario's route (the paper's planner) is written on the junction's track graph
(:func:`~trajgen.model.junction_route.junction_graph_route`: its straight pieces as moves, joint
where both vehicles move) and timed there by each method (``schedule_graph``), beside the junction's
own timing of the same route (``schedule``). Both are verified. Printed per set and method: how
many verified, the median and range of the makespan on the graph over the junction's, and the
median time to compute each (the junction's optimal NLP store as it is: a shape not yet built is
built in the first scenario that needs it).

Sets (limits 1.0 m/s, 0.5 m/s², 1.0 m/s³, separation 1.5 m): the three swaps on legs
(10, 10, 10) m (equal legs: uniform layouts), the three swaps on (12, 8, 15) m, ``--random``
seeded random start/goal pairs on (12, 8, 15) m, and as many on 4-leg and 8-leg stars of equal
10 m legs. This is the measurement issue 50 asks for before the two optimal formulations merge.

Each ``optimal`` is its method as a user gets it: the junction's is free within the route's
homotopy class (it may dodge shallower than the route, or skip a retraction) and picks the faster
of the two classes; the graph's keeps the route's paths (to the legs' ends where Baldi's route goes
there) and picks the fastest of the route's class and of the planner's other classes on the track
graph. So the two may end in different classes.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from limits import Limits, VehicleLimits
from topology import Configuration, Position, StarGraph, plan
from topology.errors import SeparationError
from trajgen import verify
from trajgen.methods import METHODS
from trajgen.model.junction_route import junction_graph_route

METHOD_NAMES = ("exact", "toppra", "optimal")
VEHICLE = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
LIMITS = Limits(vehicles=(VEHICLE, VEHICLE), min_separation=1.5)


def _swaps(lengths: dict[str, float]):
    track = StarGraph(lengths)
    names = list(lengths)
    for a, b in zip(names, names[1:] + names[:1], strict=True):
        start = Configuration(Position(a, lengths[a]), Position(b, lengths[b]))
        yield plan(track, start, start.swapped(), min_separation=1.5)


def _random(lengths: dict[str, float], count: int, rng: random.Random):
    track = StarGraph(lengths)
    names = list(lengths)
    made = 0
    while made < count:
        legs = [rng.choice(names) for _ in range(4)]
        places = [Position(leg, rng.uniform(0.5, lengths[leg])) for leg in legs]
        try:
            route = plan(track, Configuration(*places[:2]), Configuration(*places[2:]), min_separation=1.5)
        except SeparationError:
            continue
        made += 1
        yield route


def _timed(make, *args):
    begin = time.perf_counter()
    schedule = make(*args)
    return schedule, time.perf_counter() - begin


def _measure(routes) -> dict[str, list[tuple[float, float, float, bool, bool]]]:
    """Per method: (makespan on the graph / the junction's, seconds on each, verified, fell back)."""
    rows: dict[str, list] = {name: [] for name in METHOD_NAMES}
    for route in routes:
        on_graph = junction_graph_route(route)
        for name in METHOD_NAMES:
            method = METHODS.create(name)
            junction, junction_s = _timed(method.schedule, route, LIMITS)
            graph, graph_s = _timed(method.schedule_graph, on_graph, LIMITS)
            verified = verify(junction).passed and verify(graph).passed
            fell_back = graph.fallback_reason is not None or junction.fallback_reason is not None
            rows[name].append((graph.duration / junction.duration, graph_s, junction_s, verified, fell_back))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=10, help="random scenarios per random set")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    uneven = {"A": 12.0, "B": 8.0, "C": 15.0}
    sets = {
        "swaps, equal 10 m legs": list(_swaps({"A": 10.0, "B": 10.0, "C": 10.0})),
        "swaps, legs 12/8/15 m": list(_swaps(uneven)),
        "random, legs 12/8/15 m": list(_random(uneven, args.random, rng)),
        "random, 4 equal legs": list(_random({n: 10.0 for n in "NWSE"}, args.random, rng)),
        "random, 8 equal legs": list(_random({n: 10.0 for n in "ABCDEFGH"}, args.random, rng)),
    }
    print(
        f"{'set':>24} {'method':>8} {'n':>3} {'verified':>8} {'fallbacks':>9} "
        f"{'graph/junction median':>21} {'[min, max]':>17} {'graph s':>8} {'junction s':>10}"
    )
    for label, routes in sets.items():
        for name, rows in _measure(routes).items():
            ratios = [row[0] for row in rows]
            print(
                f"{label:>24} {name:>8} {len(rows):>3} {sum(row[3] for row in rows):>8} "
                f"{sum(row[4] for row in rows):>9} {statistics.median(ratios):>21.4f} "
                f"{f'[{min(ratios):.4f}, {max(ratios):.4f}]':>17} "
                f"{statistics.median(row[1] for row in rows):>8.3f} "
                f"{statistics.median(row[2] for row in rows):>10.3f}"
            )


if __name__ == "__main__":
    main()
