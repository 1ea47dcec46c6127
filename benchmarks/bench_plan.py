"""Throughput of ``topology.plan`` over 10,000 seeded random queries.

Run: ``python benchmarks/bench_plan.py [--queries N] [--seed S]``.
Prints the median, mean and 99th percentile time per plan in microseconds,
measured one query at a time with ``time.perf_counter_ns`` on one core.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from topology import Configuration, YGraph, plan
from trajgen.progress import progress
from trajgen.scenario.sampling import random_position


def random_queries(count: int, seed: int):
    """``count`` valid (graph, start, goal, min_separation) tuples, seeded."""
    rng = random.Random(seed)
    queries = []
    while len(queries) < count:
        graph = YGraph({name: rng.uniform(0.5, 50.0) for name in "ABC"})
        separation = rng.uniform(0.0, graph.shortest_leg)
        start = Configuration(random_position(rng, graph), random_position(rng, graph))
        goal = (
            start.swapped()
            if rng.random() < 0.2
            else Configuration(random_position(rng, graph), random_position(rng, graph))
        )
        if min(graph.separation(start), graph.separation(goal)) < max(separation, 1e-9):
            continue
        queries.append((graph, start, goal, separation))
    return queries


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queries", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args()
    queries = random_queries(args.queries, args.seed)
    for graph, start, goal, separation in queries[:200]:  # warm-up
        plan(graph, start, goal, min_separation=separation)
    times_us = []
    clock = time.perf_counter_ns
    for graph, start, goal, separation in progress(queries, description="plan queries"):
        begin = clock()  # the bar's own cost is outside the timed call
        plan(graph, start, goal, min_separation=separation)
        times_us.append((clock() - begin) / 1000.0)
    times_us.sort()
    print(f"plan() over {len(queries)} seeded random queries (seed {args.seed}):")
    print(f"  median {statistics.median(times_us):8.2f} us per plan (target <= 20 us)")
    print(f"  mean   {statistics.fmean(times_us):8.2f} us")
    print(f"  p99    {times_us[int(0.99 * len(times_us))]:8.2f} us")
    print(f"  throughput {1e6 / statistics.fmean(times_us):,.0f} plans/s")


if __name__ == "__main__":
    main()
