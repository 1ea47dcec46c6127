"""How planning on a track graph grows: time and critical points for 10, 50, 200 and 500 edges.

Run: ``python benchmarks/bench_graph.py [--repeats R] [--seed S]``.

Each layout is a grid of aisles (junctions on a square lattice joined to their neighbours, edges
4 to 10 m) with dead-end spurs up to the number of edges, so it has many loops. The two vehicles
swap the ends of the first and the last edge, 1.5 m apart. Printed per size: nodes, the
critical points before the search, the pairs the search expanded, the route's length, and the
median and worst time of ``plan_graph`` over the repeats (the track is built once, outside the
timing), measured with ``time.perf_counter`` on one core.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from topology import TrackGraph, plan_graph

SIZES = (10, 50, 200, 500)


def aisles(edge_count: int, seed: int) -> dict[str, tuple[str, str, float]]:
    """A grid of aisles with spurs, ``edge_count`` edges in all (lengths on a 0.5 m grid)."""
    rng = random.Random(f"aisles-{edge_count}-{seed}")
    side = 1
    while 2 * side * (side - 1) + side < edge_count:
        side += 1
    edges: dict[str, tuple[str, str, float]] = {}
    for i in range(side):
        for j in range(side):
            for name, (k, m) in (("h", (i + 1, j)), ("v", (i, j + 1))):
                if k < side and m < side and len(edges) < edge_count:
                    edges[f"{name}{i}-{j}"] = (f"N{i}-{j}", f"N{k}-{m}", rng.randint(8, 20) * 0.5)
    spur = 0
    while len(edges) < edge_count:
        i, j = rng.randrange(side), rng.randrange(side)
        edges[f"s{spur}"] = (f"N{i}-{j}", f"S{spur}", rng.randint(6, 16) * 0.5)
        spur += 1
    return edges


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="plans per size (default 5)")
    parser.add_argument("--seed", type=int, default=0, help="layout seed (default 0)")
    args = parser.parse_args()
    print(
        f"{'edges':>6} {'nodes':>6} {'critical':>9} {'searched':>9} {'route m':>8} "
        f"{'median ms':>10} {'worst ms':>9}"
    )
    for size in SIZES:
        edges = aisles(size, args.seed)
        track = TrackGraph.from_edges(edges)
        first, last = next(iter(edges)), list(edges)[-1]
        start, goal = (f"{first}:1", f"{last}:1"), (f"{last}:1", f"{first}:1")
        times = []
        for _ in range(args.repeats):
            began = time.perf_counter()
            route = plan_graph(track, start, goal, min_separation=1.5)
            times.append(1000 * (time.perf_counter() - began))
        print(
            f"{size:6d} {len(track.nodes):6d} {route.critical_points:9d} {route.searched:9d} "
            f"{route.length:8.1f} {statistics.median(times):10.1f} {max(times):9.1f}"
        )


if __name__ == "__main__":
    main()
