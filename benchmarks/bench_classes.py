"""``optimal`` against the converged optimum of each class and two fleet baselines (issue 10).

Run: ``python benchmarks/bench_classes.py [--random N] [--nodes N] [--only LABEL]``.

Sets: those of ``bench_optimal.py`` (a-d, ``--random`` pairs in c and d),
plus long legs (50/50/50, 200/120/80, 100/150/200, 1000/800/1200 m), very
unequal legs (2/30/5 m), separations from 0.2 m to just under the shortest leg
(12/8/15 m), and mixed fleets (vehicle 1 two and four times as fast as vehicle
2). Each set has its three swaps and a few seeded random start/goal pairs.

Columns (seconds): exact, toppra, optimal in the paper's class, optimal (the
default: the faster of the two classes), the converged optimum of the chosen
class (``Optimal(nodes=64)`` refined until a pass gains < 0.001 %), zone
locking and prioritized planning (``baselines.py``), the lower bound, and the
wall time of ``Optimal().schedule`` (``*``: it built an NLP). Summary: the worst
ratio to the converged optimum, to each baseline, how often the non-paper
class wins and by how much, and the solve times.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

from baselines import prioritized, zone_locking
from tqdm import tqdm

from limits import Limits, VehicleLimits
from topology import Configuration, Homotopy, YGraph, plan
from trajgen import Exact, Optimal, SolverCache, Toppra, lower_bound, verify
from trajgen.methods.optimal import DEFAULT_NODES
from trajgen.progress import progress
from trajgen.scenario.sampling import random_scenarios, reference_sets

AGV = VehicleLimits(1.0, 0.5, 1.0)
SLOW = VehicleLimits(0.7, 0.35, 0.6)


def emit(line: str) -> None:
    """Print a result row above the progress bar, at once (also into a pipe)."""
    tqdm.write(line)
    sys.stdout.flush()


def _swaps(track: YGraph) -> list[tuple[str, Configuration, Configuration]]:
    out = []
    names = track.names
    for first, second in zip(names, names[1:] + names[:1], strict=True):
        start = Configuration(track.endpoint(first), track.endpoint(second))
        out.append((f"swap {first}{second}", start, start.swapped()))
    return out


def _set(label: str, legs, limits: Limits, random_count: int, seed: int):
    track = YGraph(dict(zip("ABC", legs, strict=True)))
    scenarios = _swaps(track)
    for k, scenario in enumerate(random_scenarios(random_count, seed=seed, track=track, limits=limits)):
        scenarios.append((f"random {k}", scenario.start, scenario.goal))
    return label, track, limits, scenarios


def benchmark_sets(random_pairs: int):
    """(label, track, limits, scenarios) of every set of the benchmark."""
    sets = [(r.label, r.track, r.limits, list(r.scenarios)) for r in reference_sets(random_pairs)]
    same = Limits((AGV, AGV), 1.5)
    for k, legs in enumerate(((50, 50, 50), (200, 120, 80), (100, 150, 200), (1000, 800, 1200))):
        sets.append(_set(f"long {'/'.join(map(str, legs))}", legs, same, 3, 100 + k))
    sets.append(_set("unequal 2/30/5", (2, 30, 5), same, 5, 200))
    for separation in (0.2, 4.0, 7.99):
        sets.append(_set(f"separation {separation}", (12, 8, 15), Limits((AGV, AGV), separation), 3, 300))
    for factor in (2.0, 4.0):
        fast = VehicleLimits(2.0, 1.0, 2.0)
        slow = VehicleLimits(2.0 / factor, 1.0 / factor, 2.0 / factor)
        for legs in ((10, 10, 10), (12, 8, 15)):
            name = f"mixed x{factor:g} {'/'.join(map(str, legs))}"
            sets.append(_set(name, legs, Limits((fast, slow), 1.5), 3, 400))
    sets.append(_set("mixed 1.0/0.7 12/8/15", (12, 8, 15), Limits((AGV, SLOW), 1.5), 0, 0))
    return sets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=50, help="random pairs in sets c and d (50)")
    parser.add_argument("--nodes", type=int, default=DEFAULT_NODES, help=f"nodes per phase ({DEFAULT_NODES})")
    parser.add_argument("--only", default="", help="run only the sets whose label starts with this")
    args = parser.parse_args()
    cache = SolverCache(maxsize=256)
    fastest = Optimal(nodes=args.nodes, cache=cache)
    paper = Optimal(nodes=args.nodes, homotopy="planned", cache=cache)
    reference = Optimal(
        nodes=64,
        refinements=12,
        refinement_tolerance=1e-5,
        time_limit=120.0,
        homotopy="planned",
        cache=SolverCache(maxsize=256),
    )
    print(
        f"{'set':>22} {'scenario':>10} {'exact':>8} {'toppra':>8} {'paper':>9} {'optimal':>9} {'class':>5} "
        f"{'converged':>9} {'zone':>8} {'prio':>8} {'lower':>8} {'opt/conv':>8} {'opt/zone':>8} "
        f"{'opt/prio':>8} {'ms':>6}"
    )
    rows = []
    cases = [
        (label, track, limits, scenario)
        for label, track, limits, scenarios in benchmark_sets(args.random)
        if label.startswith(args.only)
        for scenario in scenarios
    ]
    for label, track, limits, (name, start, goal) in progress(cases, description="scenarios"):
        route = plan(track, start, goal, min_separation=limits.min_separation)
        exact = Exact().schedule(route, limits)
        timed = Toppra().schedule(route, limits)
        began = time.perf_counter()
        best = fastest.schedule(route, limits)
        wall = time.perf_counter() - began
        in_paper = paper.schedule(route, limits)
        # the converged optimum of the chosen class
        chosen_route = best.route
        converged = reference.schedule(chosen_route, limits)
        zone = zone_locking(route, limits)
        priority = prioritized(route, limits)
        bound = lower_bound(route, limits)
        schedules = (exact, timed, best, in_paper, converged)
        passed = all(verify(s).passed for s in schedules)
        row = {
            "set": label,
            "name": name,
            "exact": exact.duration,
            "toppra": timed.duration,
            "paper": in_paper.duration,
            "optimal": best.duration,
            "other_class": best.route.homotopy is Homotopy.OTHER,
            "converged": converged.duration,
            "zone": zone.makespan if zone.safe else float("inf"),
            "prio": priority.makespan if priority.safe else float("inf"),
            "lower": bound,
            "wall": wall,
            "built": best.info is not None and best.info.built,
            "fallback": best.fallback_reason is not None or in_paper.fallback_reason is not None,
            "verified": passed,
            "short": label in "abcd",
        }
        rows.append(row)
        emit(
            f"{label:>22} {name:>10} {row['exact']:8.2f} {row['toppra']:8.2f} {row['paper']:9.3f} "
            f"{row['optimal']:9.3f} {'other' if row['other_class'] else 'paper':>5} "
            f"{row['converged']:9.3f} "
            f"{row['zone']:8.2f} {row['prio']:8.2f} {bound:8.2f} "
            f"{row['optimal'] / row['converged']:8.5f} {row['optimal'] / row['zone']:8.4f} "
            f"{row['optimal'] / row['prio']:8.4f} {1e3 * wall:5.0f}{'*' if row['built'] else ' '}"
        )
    _summary(rows)


def _summary(rows: list[dict]) -> None:
    print()
    print(f"scenarios: {len(rows)}; all schedules verified: {all(r['verified'] for r in rows)}")
    print(f"fallbacks: {sum(r['fallback'] for r in rows)}")
    ratio = max(rows, key=lambda r: r["optimal"] / r["converged"])
    print(
        f"worst optimal / converged optimum of its class: {ratio['optimal'] / ratio['converged']:.5f} "
        f"({ratio['set']} {ratio['name']}; target <= 1.002)"
    )
    print(f"worst optimal (paper class) / exact: {max(r['paper'] / r['exact'] for r in rows):.4f}")
    for key, label in (("zone", "zone locking"), ("prio", "prioritized")):
        worst = max(rows, key=lambda r: r["optimal"] / r[key])
        slower = sum(r["optimal"] > r[key] for r in rows)
        print(
            f"worst optimal / {label}: {worst['optimal'] / worst[key]:.4f} ({worst['set']} {worst['name']}); "
            f"slower than it in {slower} of {len(rows)} (target 0)"
        )
    other = [r for r in rows if r["other_class"]]
    if other:
        gains = [r["paper"] / r["optimal"] for r in other]
        print(
            f"the non-paper class wins {len(other)} of {len(rows)}: paper/optimal median "
            f"{statistics.median(gains):.4f}, max {max(gains):.4f}"
        )
    for key, label in (("zone", "zone locking"), ("prio", "prioritized")):
        failed = [f"{r['set']} {r['name']}" for r in rows if r[key] == float("inf")]
        print(
            f"{label} found no safe motion (unsafe when sampled, deadlocked, or no holding point) in "
            f"{len(failed)} of {len(rows)}: {', '.join(failed) or '-'} (left out of its ratios)"
        )
    ordered = sum(r["lower"] <= r["optimal"] * (1 + 1e-9) <= r["exact"] * (1 + 2e-9) for r in rows)
    print(f"lower bound <= optimal <= exact: {ordered} of {len(rows)}")
    for subset, label in (([r for r in rows if r["short"]], "10-15 m sets a-d"), (rows, "all")):
        cached = [r["wall"] for r in subset if not r["built"]]
        if cached:
            print(
                f"Optimal().schedule wall time, {label} (cached NLPs): "
                f"median {1e3 * statistics.median(cached):.0f} ms, "
                f"worst {1e3 * max(cached):.0f} ms over {len(cached)}; "
                f"with builds worst {1e3 * max(r['wall'] for r in subset):.0f} ms"
            )


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
