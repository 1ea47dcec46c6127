"""A seeded random campaign over a wide range of scenarios: verification failures, fallbacks, worst times.

Run: ``python benchmarks/bench_campaign.py [--scenarios 300] [--seed 9]``.

Scenarios from :func:`trajgen.scenario.sampling.campaign_scenarios` (legs 0.5-5000 m,
independent limits 0.05-5 m/s, 0.05-5 m/s², 0.05-20 m/s³, separations up to
the shortest leg, swaps and random goals), each scheduled by every registered
method and verified. Prints the failures (target 0), the fallbacks per method,
the worst and median schedule and verify times, and the peak memory.
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import statistics
import time

from tqdm import tqdm

from trajgen import METHODS, Optimal, SolverCache, make_schedule, verify
from trajgen.progress import progress
from trajgen.scenario.sampling import campaign_scenarios


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=300)
    parser.add_argument("--seed", type=int, default=9)
    args = parser.parse_args()
    methods = [cls() if cls is not Optimal else Optimal(cache=SolverCache(maxsize=128)) for cls in METHODS]
    failures, fallbacks = 0, {m.name: 0 for m in methods}
    times = {m.name: [] for m in methods}
    verify_times = []
    longest = (0.0, "")
    scenarios = campaign_scenarios(args.scenarios, seed=args.seed)
    for scenario in progress(scenarios, description="scenarios"):
        route = scenario.route()
        for method in methods:
            began = time.perf_counter()
            schedule = make_schedule(route, scenario.limits, method=method)
            times[method.name].append(time.perf_counter() - began)
            began = time.perf_counter()
            report = verify(dataclasses.replace(schedule))  # a fresh object: timed, not looked up
            verify_times.append(time.perf_counter() - began)
            fallbacks[method.name] += schedule.fallback_reason is not None
            longest = max(longest, (schedule.duration, f"{scenario.source} {method.name}"))
            if not report.passed:
                failures += 1
                tqdm.write(f"FAILED {scenario.source} {method.name}: {report.failures[:2]}")  # above the bar
    print(f"{args.scenarios} scenarios x {len(methods)} methods (seed {args.seed})")
    print(f"verification failures: {failures} (target 0)")
    print("fallbacks: " + ", ".join(f"{name} {count}" for name, count in fallbacks.items()))
    for name, values in times.items():
        print(
            f"{name:>8}: median {1e3 * statistics.median(values):7.1f} ms, worst {1e3 * max(values):7.1f} ms"
        )
    median, worst = 1e3 * statistics.median(verify_times), 1e3 * max(verify_times)
    print(f"  verify: median {median:7.1f} ms, worst {worst:7.1f} ms")
    print(f"longest schedule: {longest[0]:.1f} s ({longest[1]})")
    print(f"peak memory: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")


if __name__ == "__main__":
    main()
