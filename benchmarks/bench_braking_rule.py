"""What the braking rule costs: optimal makespans with and without it, beside the two fleet baselines.

A plan for the online executor must let each follower stop short of its frontier at every instant
(the braking rule, issue 22): ``Optimal(braking_rule=True)`` states it in the NLP, and the verifier
checks it. This prints, per scenario of the benchmark sets of ``bench_optimal.py`` (a: the three
swaps on 10/10/10 m; b: on 12/8/15 m; c: seeded random start/goal pairs on 12/8/15 m; d: set c
with a slower second vehicle), the optimal makespan without the rule and with it, the change, and
the two baselines fleet software uses (zone locking and prioritized planning, ``baselines.py``).
Every schedule is verified (the ruled ones with the rule); a fallback is flagged.

Run: ``python benchmarks/bench_braking_rule.py [--random N]`` (N random pairs in sets c and d, 10).

``--campaign N`` instead plans, as the online executor does (the separation plus twice the
position margin, the braking rule in the NLP), the first N scenarios of the online campaign
(:func:`~trajgen.scenario.sampling.online_campaign`, seed 7) on 3, 4 and 5 legs, and prints how
each ended: solved, fallbacks by reason, and fatrop calls abandoned by the watchdog (a solver that
did not come back within ``--time-limit`` seconds: fatrop 1.1.8's endless inertia correction);
``--wide`` takes the wide campaign (:func:`~trajgen.scenario.sampling.campaign_scenarios`) instead.
"""

from __future__ import annotations

import argparse
import collections
import logging
import statistics
import time

from baselines import prioritized, zone_locking

from limits import Limits
from topology import plan
from trajgen import Optimal, SolverCache, verify
from trajgen.errors import InputError
from trajgen.execution.goals import execution_margin
from trajgen.methods.optimal import Outcome
from trajgen.progress import progress
from trajgen.scenario.sampling import campaign_scenarios, online_campaign, reference_sets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=10, help="random pairs in sets c and d (10)")
    parser.add_argument("--campaign", type=int, default=0, metavar="N", help="plan N campaign scenarios")
    parser.add_argument("--wide", action="store_true", help="with --campaign: the wide campaign")
    parser.add_argument("--time-limit", type=float, default=20.0, help="with --campaign: seconds (20)")
    args = parser.parse_args()
    logging.disable(logging.WARNING)
    if args.campaign:
        campaign(args.campaign, wide=args.wide, time_limit=args.time_limit)
        return
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


def campaign(count: int, *, wide: bool, time_limit: float) -> None:
    """Braking-rule plans of ``count`` campaign scenarios per leg count: how each ended."""
    scenarios = campaign_scenarios if wide else online_campaign
    method = Optimal(braking_rule=True, time_limit=time_limit, cache=SolverCache(maxsize=64))
    outcomes: collections.Counter = collections.Counter()
    cases = [
        (legs, k, s) for legs in (3, 4, 5) for k, s in enumerate(scenarios(count, seed=7, leg_count=legs))
    ]
    for legs, k, scenario in progress(cases, description="plans"):
        separation = scenario.limits.min_separation + 2.0 * execution_margin(scenario, 0.05)
        try:
            route = plan(scenario.track, scenario.start, scenario.goal, min_separation=separation)
        except InputError:  # the margin does not fit: no plan for execution
            outcomes["not plannable with the margin"] += 1
            continue
        schedule = method.schedule(route, Limits(scenario.limits.vehicles, separation))
        reason = schedule.fallback_reason
        outcomes["solved" if reason is None else f"fallback {reason.value}"] += 1
        abandoned = [a for a in schedule.info.attempts if a.outcome is Outcome.ABANDONED]
        outcomes["fatrop calls abandoned (hangs)"] += len(abandoned)
        if abandoned:
            print(
                f"k={legs} scenario {k}: a fatrop call did not come back within {time_limit:g} s", flush=True
            )
    print(f"{'wide' if wide else 'online'} campaign, {len(cases)} plans with the braking rule:")
    for what, count_of in sorted(outcomes.items()):
        print(f"  {what}: {count_of}")


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
