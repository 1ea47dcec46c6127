"""Time to produce each schedule (exact, toppra) for the swap and 100 seeded random scenarios.

Run: ``python benchmarks/bench_schedule.py [--scenarios N] [--seed S]``.
Times are per scenario, planning included, verification excluded (printed
separately), after one warm-up call (the first import of TOPPRA takes ~1 s).
Every schedule is also verified; the script fails if any does not pass.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from limits import ILLUSTRATIVE_LIMITS
from topology import YGraph
from trajgen import METHODS, TimingMethod, default_scenario, make_schedule, verify
from trajgen.progress import progress
from trajgen.scenario.sampling import random_scenarios


def scenarios(count: int, seed: int):
    rng = random.Random(seed)
    out = []
    for k in range(count):
        track = YGraph({name: rng.uniform(4.0, 20.0) for name in "ABC"})
        out += random_scenarios(1, seed=seed * 1000 + k, track=track, limits=ILLUSTRATIVE_LIMITS)
    return out


def timed(scenario, method: TimingMethod):
    begin = time.perf_counter()
    route = scenario.route()
    schedule = make_schedule(route, scenario.limits, method=method)
    elapsed = time.perf_counter() - begin
    begin = time.perf_counter()
    report = verify(schedule)
    return schedule, report, elapsed, time.perf_counter() - begin


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=100)
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    swap = default_scenario()
    randoms = scenarios(args.scenarios, args.seed)
    failures = 0
    print(
        f"{'method':>7} {'set':>14} {'median ms':>10} {'max ms':>8} {'verify ms':>10} "
        f"{'makespan s (median)':>20}"
    )
    for method_class in METHODS:
        method = method_class()
        timed(swap, method)  # warm-up
        for label, batch in (("swap", [swap] * 5), (f"{len(randoms)} random", randoms)):
            results = [timed(s, method) for s in progress(batch, description=f"{method.name}, {label}")]
            failures += sum(not report.passed for _, report, _, _ in results)
            produce = [1e3 * r[2] for r in results]
            check = [1e3 * r[3] for r in results]
            makespan = statistics.median(r[0].duration for r in results)
            print(
                f"{method.name:>7} {label:>14} {statistics.median(produce):10.2f} {max(produce):8.2f} "
                f"{statistics.median(check):10.2f} {makespan:20.2f}"
            )
    print("targets: exact <= 5 ms median, toppra <= 50 ms median per scenario")
    print(
        "each schedule is verified once: optimal and toppra verify their own results (inside their time), "
        "so their verify column is the look-up of that report"
    )
    print(f"verification failures: {failures}")
    if failures:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
