"""What verifying a plan costs on plant layouts: combs of equal aisles beside combs of random aisles.

Run: ``python benchmarks/bench_verify_graph.py [--aisles 20 50 100] [--repeats R]``.

A comb: a main line of ``n`` equal 5 m pieces with an aisle of 10 m at every node (``2 n - 1``
edges); its random twin draws each length from 4 to 16 m (seed 0). Two vehicles (1.5 m/s,
0.5 m/s², 1 m/s³, 2 m apart) swap the ends of the first and the last aisle. Printed per layout:
edges, the planner's time (once), the exact plan's makespan, and the median over the repeats of
``verify`` (the braking rule included: exact plans for execution) and of the rule alone,
timed with ``time.perf_counter`` on one core; the track and the plan are made outside the timing.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from limits import Limits, VehicleLimits
from topology import TrackGraph, plan_graph
from trajgen import Exact, verify
from trajgen.verification.braking_rule import braking_rule_failures

LIMITS = Limits(vehicles=(VehicleLimits(1.5, 0.5, 1.0),) * 2, min_separation=2.0)


def comb(aisles: int, *, uniform: bool, seed: int = 0) -> TrackGraph:
    """A main line with an aisle at each of its ``aisles`` nodes: equal lengths, or random ones."""
    rng = random.Random(f"comb-{aisles}-{seed}")
    edges: dict[str, tuple[str, str, float]] = {}
    for i in range(aisles):
        edges[f"t{i}"] = (f"M{i}", f"T{i}", 10.0 if uniform else rng.randint(8, 32) * 0.5)
        if i:
            edges[f"m{i}"] = (f"M{i - 1}", f"M{i}", 5.0 if uniform else rng.randint(8, 32) * 0.5)
    return TrackGraph.from_edges(edges)


def _median_ms(work, schedule, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work(schedule)
        times.append(time.perf_counter() - start)
    return 1000.0 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--aisles", type=int, nargs="+", default=[20, 50, 100], help="aisles per comb")
    parser.add_argument("--repeats", type=int, default=3, help="timings per layout (default 3)")
    args = parser.parse_args()
    print(f"{'layout':>14} {'edges':>6} {'plan s':>7} {'makespan s':>11} {'verify ms':>10} {'rule ms':>8}")
    for aisles in args.aisles:
        for uniform in (True, False):
            track = comb(aisles, uniform=uniform)
            start = time.perf_counter()
            route = plan_graph(track, ("T0", f"T{aisles - 1}"), (f"T{aisles - 1}", "T0"), min_separation=2.0)
            planned = time.perf_counter() - start
            schedule = Exact().schedule_graph(route, LIMITS)
            report = verify(schedule)
            if not report.passed:
                raise SystemExit(f"the plan fails verification: {report.failures[0]}")
            verify_ms = _median_ms(verify, schedule, args.repeats)
            rule_ms = _median_ms(braking_rule_failures, schedule, args.repeats)
            name = f"comb-{aisles}-{'equal' if uniform else 'random'}"
            print(
                f"{name:>14} {track.edge_count:>6} {planned:>7.2f} {schedule.duration:>11.1f} "
                f"{verify_ms:>10.1f} {rule_ms:>8.1f}"
            )


if __name__ == "__main__":
    main()
