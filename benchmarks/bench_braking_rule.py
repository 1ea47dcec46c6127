"""What the braking rule costs: optimal makespans with and without it, beside the two fleet baselines.

A plan for the online executor must let each follower stop short of its frontier at every instant
(the braking rule, issue 22): ``Optimal(braking_rule=True)`` states it in the NLP, and the verifier
checks it. This prints, per scenario of the benchmark sets of ``bench_optimal.py`` (a: the three
swaps on 10/10/10 m; b: on 12/8/15 m; c: seeded random start/goal pairs on 12/8/15 m; d: set c
with a slower second vehicle), the optimal makespan without the rule and with it, the change, and
the two baselines fleet software uses (zone locking and prioritized planning, ``baselines.py``).
Every schedule is verified (the ruled ones with the rule); a fallback is flagged.

Run: ``python benchmarks/bench_braking_rule.py [--random N]`` (N random pairs in sets c and d, 10).
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time

from baselines import prioritized, zone_locking

from topology import plan
from trajgen import Optimal, SolverCache, verify
from trajgen.progress import progress
from trajgen.scenario.sampling import reference_sets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=10, help="random pairs in sets c and d (10)")
    args = parser.parse_args()
    logging.disable(logging.WARNING)
    free = Optimal(cache=SolverCache(maxsize=128))
    ruled = Optimal(braking_rule=True, cache=SolverCache(maxsize=128))
    cases = [
        (ref.label, ref.limits, ref.track, s) for ref in reference_sets(args.random) for s in ref.scenarios
    ]
    print(
        f"{'set':>3} {'scenario':>11} {'optimal':>8} {'ruled':>8} {'change':>7} {'zone':>8} {'prior.':>8} "
        f"{'verified':>8} {'fallback':>8}"
    )
    rows = []
    for label, limits, track, (name, start, goal) in progress(cases, description="scenarios"):
        route = plan(track, start, goal, min_separation=limits.min_separation)
        without, with_rule = free.schedule(route, limits), ruled.schedule(route, limits)
        zone, priority = zone_locking(route, limits), prioritized(route, limits)
        verified = verify(without).passed and verify(with_rule).passed
        fallback = without.fallback_reason is not None or with_rule.fallback_reason is not None
        change = with_rule.duration / without.duration - 1.0
        rows.append((label, without.duration, with_rule.duration, change, zone, priority, verified, fallback))
        print(
            f"{label:>3} {name:>11} {without.duration:8.2f} {with_rule.duration:8.2f} {100 * change:6.2f}% "
            f"{zone.makespan:8.2f} {priority.makespan:8.2f} {verified!s:>8} {'yes' if fallback else 'no':>8}",
            flush=True,
        )
    print()
    for label in sorted({row[0] for row in rows}):
        part = [row for row in rows if row[0] == label]
        changes = [row[3] for row in part]
        print(
            f"set {label} ({len(part)}): the rule costs median {100 * statistics.median(changes):.2f} %, "
            f"worst {100 * max(changes):.2f} %; ruled optimal faster than zone locking in "
            f"{sum(row[2] < row[4].makespan for row in part)}, than prioritized in "
            f"{sum(row[2] < row[5].makespan for row in part)}"
        )
    changes = [row[3] for row in rows]
    against_zone = statistics.median(row[2] / row[4].makespan - 1 for row in rows)
    against_priority = statistics.median(row[2] / row[5].makespan - 1 for row in rows)
    print(
        f"all {len(rows)}: the rule costs median {100 * statistics.median(changes):.2f} %, worst "
        f"{100 * max(changes):.2f} %; verified {sum(row[6] for row in rows)}/{len(rows)}; "
        f"fallbacks {sum(row[7] for row in rows)}; ruled optimal against zone locking: median "
        f"{100 * against_zone:+.1f} %, against prioritized: median {100 * against_priority:+.1f} %"
    )


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
