"""Makespans of exact, toppra and optimal schedules against the lower bound (issue 4 sets a-d).

Run: ``python benchmarks/bench_optimal.py [--random N] [--nodes N] [--skip-refinement]``.

Sets (limits 1.0 m/s, 0.5 m/s², 1.0 m/s³, separation 1.5 m unless stated):
(a) the three swaps on legs (10, 10, 10) m; (b) the three swaps on (12, 8, 15) m;
(c) 50 seeded random start/goal pairs on (12, 8, 15) m; (d) set (c) with the
second vehicle limited to 0.7 m/s, 0.35 m/s², 0.6 m/s³.

Per scenario: makespans of exact, toppra, optimal and the lower bound (larger
of the two vehicles' own jerk-limited rest-to-rest times over their shortest
paths), optimal/exact, optimal/lower bound, the solve time (including the
one-time NLP build for the first query of each region-sequence shape, marked
``*``), whether it fell back, and the change of the optimal makespan when the
number of nodes per phase is doubled.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

from tqdm import tqdm

from topology import plan
from trajgen import Exact, Optimal, SolverCache, Toppra, lower_bound, verify
from trajgen.methods.optimal import DEFAULT_NODES, Source
from trajgen.progress import progress
from trajgen.scenario.sampling import reference_sets


def emit(line: str) -> None:
    """Print a result row above the progress bar, at once (also into a pipe)."""
    tqdm.write(line)
    sys.stdout.flush()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=50, help="random pairs in sets c and d (50)")
    parser.add_argument("--nodes", type=int, default=DEFAULT_NODES, help=f"nodes per phase ({DEFAULT_NODES})")
    parser.add_argument("--skip-refinement", action="store_true", help="do not re-solve with doubled nodes")
    args = parser.parse_args()
    rows = []
    header = (
        f"{'set':>3} {'scenario':>11} {'exact':>7} {'toppra':>7} {'optimal':>8} {'lower':>7} "
        f"{'opt/ex':>6} {'opt/lb':>6} {'solve ms':>9} {'fallback':>8} {'2N change':>9}"
    )
    print(header)
    # one cache per grid, large enough for every shape of the sets: each shape is built once
    optimal = Optimal(nodes=args.nodes, cache=SolverCache(maxsize=128))
    refined = Optimal(nodes=2 * args.nodes, cache=SolverCache(maxsize=128))
    cases = [
        (reference, scenario) for reference in reference_sets(args.random) for scenario in reference.scenarios
    ]
    for reference, (name, start, goal) in progress(cases, description="scenarios"):
        label, limits = reference.label, reference.limits
        route = plan(reference.track, start, goal, min_separation=limits.min_separation)
        exact = Exact().schedule(route, limits)
        timed = Toppra().schedule(route, limits)
        best = optimal.schedule(route, limits)
        bound = lower_bound(route, limits)
        info = best.info
        change = float("nan")
        if not args.skip_refinement and best.fallback_reason is None:
            fine = refined.schedule(route, limits)
            if fine.fallback_reason is None:
                change = abs(fine.duration - best.duration) / best.duration
        passed = all(verify(s).passed for s in (exact, timed, best))
        rows.append(
            (
                label,
                name,
                exact.duration,
                timed.duration,
                best.duration,
                bound,
                info.solve_time,
                info.built,
                best.fallback_reason,
                change,
                passed,
                info.solver.value if info.solver else "none",
                info.source,
            )
        )
        emit(
            f"{label:>3} {name:>11} {exact.duration:7.2f} {timed.duration:7.2f} {best.duration:8.3f} "
            f"{bound:7.2f} {best.duration / exact.duration:6.3f} {best.duration / bound:6.3f} "
            f"{1e3 * info.solve_time:8.0f}{'*' if info.built else ' '} "
            f"{'yes' if best.fallback_reason else 'no':>8} {100 * change:8.3f}%"
        )
    swaps_rows = [r for r in rows if r[0] in "ab"]
    solve = [r[6] for r in rows]
    solve_cached = [r[6] for r in rows if not r[7]]
    changes = [r[9] for r in rows if r[9] == r[9]]
    print()
    print(f"scenarios: {len(rows)}; all schedules verified: {all(r[10] for r in rows)}")
    print(f"swaps: optimal/exact max {max(r[4] / r[2] for r in swaps_rows):.3f} (target <= 0.5)")
    ordered = sum(r[5] <= r[4] * (1 + 1e-9) and r[4] <= r[2] * (1 + 1e-9) for r in rows)
    print(f"lower bound <= optimal <= exact: {ordered} of {len(rows)}")
    print(f"fallbacks: {sum(r[8] is not None for r in rows)} (target 0)")
    print(
        f"solve time: median {1e3 * statistics.median(solve):.0f} ms, worst {1e3 * max(solve):.0f} ms "
        f"(targets 150 ms, 1000 ms); without the one-time builds: median "
        f"{1e3 * statistics.median(solve_cached):.0f} ms, worst {1e3 * max(solve_cached):.0f} ms "
        f"({len(solve) - len(solve_cached)} builds)"
    )
    if changes:
        print(
            f"doubling nodes ({args.nodes} -> {2 * args.nodes}): makespan change max "
            f"{100 * max(changes):.3f} %, median {100 * statistics.median(changes):.3f} % "
            f"over {len(changes)} scenarios (target < 0.5 %)"
        )
    solved_by: dict[str, int] = {}
    for row in rows:
        key = row[11] if row[12] is Source.NLP else f"{row[11]}, exact faster"
        solved_by[key] = solved_by.get(key, 0) + 1
    print("solved by: " + ", ".join(f"{name} {count}" for name, count in sorted(solved_by.items())))
    for reason in {r[8] for r in rows if r[8]}:
        print(f"fallback reason: {reason}")


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
