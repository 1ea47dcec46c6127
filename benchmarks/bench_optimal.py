"""Makespans of exact, toppra and optimal against the lower bound; NLP build, load and solve times.

Run: ``python benchmarks/bench_optimal.py [--random N] [--nodes N] [--skip-refinement] [--braking]``.

Sets (limits 1.0 m/s, 0.5 m/s², 1.0 m/s³, separation 1.5 m unless stated):
(a) the three swaps on legs (10, 10, 10) m; (b) the three swaps on (12, 8, 15) m;
(c) 50 seeded random start/goal pairs on (12, 8, 15) m; (d) set (c) with the
second vehicle limited to 0.7 m/s, 0.35 m/s², 0.6 m/s³.

The optimal method is timed three ways over the same scenarios, in this order:

1. **cold**: an empty disk store (a new temporary folder) and an empty cache: every NLP shape is
   built (transcribed and differentiated) the first time a scenario needs it, then kept;
2. **load**: a new, empty cache over the store that pass 1 filled: every shape is loaded from disk;
3. **warm**: the cache of pass 2 again, every shape in memory, the solves it remembers forgotten
   (:meth:`~trajgen.SolverCache.forget_solutions`): the solve time alone.

Per scenario (pass 3): makespans of exact, toppra, optimal and the lower bound (larger of the two
vehicles' own jerk-limited rest-to-rest times over their shortest paths), optimal/exact,
optimal/lower bound, the solve time, whether it fell back, and the change of the optimal
makespan when the number of nodes per phase is doubled. Then the build and load times per shape
and the solve-time medians of each pass. The schedules of the three passes must be identical
(checked: a built and a loaded NLP compute alike). ``--braking`` solves with the braking rule
(as plans for the online executor are made).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time

from tqdm import tqdm

from topology import plan
from trajgen import Exact, Optimal, SolverCache, Toppra, lower_bound, verify
from trajgen.methods.optimal import DEFAULT_NODES, NlpOrigin, NlpStore, Source
from trajgen.progress import progress
from trajgen.scenario.sampling import reference_sets


def emit(line: str) -> None:
    """Print a result row above the progress bar, at once (also into a pipe)."""
    tqdm.write(line)
    sys.stdout.flush()


def _pass(cases, method: Optimal, description: str):
    """Schedule every case with ``method``; the schedules and each one's wall time (s)."""
    out = []
    for reference, (_, start, goal) in progress(cases, description=description):
        route = plan(reference.track, start, goal, min_separation=reference.limits.min_separation)
        began = time.perf_counter()
        schedule = method.schedule(route, reference.limits)
        out.append((route, schedule, time.perf_counter() - began))
    return out


def _prepared(cache: SolverCache, origin: NlpOrigin) -> list[float]:
    """Seconds each NLP in ``cache`` took to prepare, of those that came from ``origin``."""
    return [entry.seconds for entry in cache.compiled() if entry.origin is origin]


def _figures(values: list[float]) -> str:
    if not values:
        return "none"
    return (
        f"median {1e3 * statistics.median(values):.0f} ms, worst {1e3 * max(values):.0f} ms "
        f"({len(values)} shapes)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=50, help="random pairs in sets c and d (50)")
    parser.add_argument("--nodes", type=int, default=DEFAULT_NODES, help=f"nodes per phase ({DEFAULT_NODES})")
    parser.add_argument("--skip-refinement", action="store_true", help="do not re-solve with doubled nodes")
    parser.add_argument("--braking", action="store_true", help="with the braking rule in the NLP")
    args = parser.parse_args()
    cases = [
        (reference, scenario) for reference in reference_sets(args.random) for scenario in reference.scenarios
    ]
    with tempfile.TemporaryDirectory(prefix="bench-optimal-nlp-") as folder:
        store = NlpStore(folder)
        cold_cache = SolverCache(maxsize=256, store=store)
        cold = _pass(cases, Optimal(nodes=args.nodes, braking_rule=args.braking, cache=cold_cache), "cold")
        store.flush()
        warm_cache = SolverCache(maxsize=256, store=store)
        method = Optimal(nodes=args.nodes, braking_rule=args.braking, cache=warm_cache)
        loaded = _pass(cases, method, "load")
        warm_cache.forget_solutions()  # else pass 3 repeats pass 2's solves from memory
        warm = _pass(cases, method, "warm")
        stored = sum(path.stat().st_size for path in store.files())
        built, load_times = _prepared(cold_cache, NlpOrigin.BUILT), _prepared(warm_cache, NlpOrigin.LOADED)
    refined = Optimal(nodes=2 * args.nodes, braking_rule=args.braking, cache=SolverCache(maxsize=256))
    header = (
        f"{'set':>3} {'scenario':>11} {'exact':>7} {'toppra':>7} {'optimal':>8} {'lower':>7} "
        f"{'opt/ex':>6} {'opt/lb':>6} {'solve ms':>8} {'fallback':>8} {'2N change':>9}"
    )
    print(header)
    rows = []
    for (reference, (name, _, _)), (route, best, seconds) in zip(cases, warm, strict=True):
        limits = reference.limits
        exact = Exact().schedule(route, limits)
        timed = Toppra().schedule(route, limits)
        bound = lower_bound(route, limits)
        change = float("nan")
        if not args.skip_refinement and best.fallback_reason is None:
            fine = refined.schedule(route, limits)
            if fine.fallback_reason is None:
                change = abs(fine.duration - best.duration) / best.duration
        passed = all(verify(s).passed for s in (exact, timed, best))
        info = best.info
        rows.append(
            (
                reference.label,
                exact.duration,
                best.duration,
                bound,
                best.fallback_reason,
                change,
                passed,
                info,
            )
        )
        emit(
            f"{reference.label:>3} {name:>11} {exact.duration:7.2f} {timed.duration:7.2f} "
            f"{best.duration:8.3f} {bound:7.2f} {best.duration / exact.duration:6.3f} "
            f"{best.duration / bound:6.3f} {1e3 * seconds:8.0f} "
            f"{'yes' if best.fallback_reason else 'no':>8} {100 * change:8.3f}%"
        )
    identical = all(
        a.duration == b.duration == c.duration
        for (_, a, _), (_, b, _), (_, c, _) in zip(cold, loaded, warm, strict=True)
    )
    swaps = [r for r in rows if r[0] in "ab"]
    changes = [r[5] for r in rows if r[5] == r[5]]
    print()
    print(f"scenarios: {len(rows)}; all schedules verified: {all(r[6] for r in rows)}")
    print(f"the three passes give identical schedules: {identical}")
    print(f"swaps: optimal/exact max {max(r[2] / r[1] for r in swaps):.3f} (target <= 0.5)")
    ordered = sum(r[3] <= r[2] * (1 + 1e-9) and r[2] <= r[1] * (1 + 1e-9) for r in rows)
    print(f"lower bound <= optimal <= exact: {ordered} of {len(rows)}")
    print(f"fallbacks: {sum(r[4] is not None for r in rows)} (target 0)")
    print(f"NLP build (cold): {_figures(built)}")
    print(f"NLP load from the store: {_figures(load_times)}; the store holds {stored / 1e6:.1f} MB")
    for label, runs in (("cold", cold), ("load", loaded), ("warm", warm)):
        seconds = [s for _, _, s in runs]
        print(
            f"schedule time, {label}: median {1e3 * statistics.median(seconds):.0f} ms, "
            f"worst {1e3 * max(seconds):.0f} ms, total {sum(seconds):.1f} s"
        )
    solve = [r[7].solve_time for r in rows if r[7] is not None]
    print(
        "solve time (warm, in-process, Schedule.info.solve_time): "
        f"median {1e3 * statistics.median(solve):.0f} ms, worst {1e3 * max(solve):.0f} ms (target 60 ms)"
    )
    if changes:
        print(
            f"doubling nodes ({args.nodes} -> {2 * args.nodes}): makespan change max "
            f"{100 * max(changes):.3f} %, median {100 * statistics.median(changes):.3f} % "
            f"over {len(changes)} scenarios (target < 0.5 %)"
        )
    solved_by: dict[str, int] = {}
    for row in rows:
        info = row[7]
        name = info.solver.value if info is not None and info.solver else "none"
        key = name if info is not None and info.source is Source.NLP else f"{name}, exact faster"
        solved_by[key] = solved_by.get(key, 0) + 1
    print("solved by: " + ", ".join(f"{name} {count}" for name, count in sorted(solved_by.items())))
    for reason in {r[4] for r in rows if r[4]}:
        print(f"fallback reason: {reason}")


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
