"""Continuity constants of the star planner's instructions, per kind of perturbation and per k (issue 13).

Run: ``python benchmarks/bench_continuity.py [--cases N] [--seed S]``.

For each kind of query (generic queries under rule 1, points along the tie
sets of rule 2, retractions crossing a vertex of ``G_k``) and k = 4, 6, 8,
builds ``--cases`` seeded cases with ``tests/support/continuity.py``, as
``tests/test_planner.py`` does (which bounds them on seed 0), moves start and
goal by ``DELTA`` metres, and prints over the comparable cases (both queries
under one instruction and class):

- ratio: ``max over tau of d(route_a.at(tau), route_b.at(tau))`` divided by how
  far start and goal moved (``d`` is the track distance of vehicle 1 plus that
  of vehicle 2);
- normalized: the ratio divided by the retraction's gain at the query (up to
  leg length / s near the junction), the constant the test bounds by
  ``CONTINUITY_BOUND``.

A jump of the route would show as a ratio of about (route length) / DELTA, 1e8.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # the tests' construction

from tests.support.continuity import CONTINUITY_BOUND, DELTA, continuity_cases


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=3000, help="seeded cases per kind and k (3000)")
    parser.add_argument("--seed", type=int, default=1, help="seed (1; the test uses 0)")
    args = parser.parse_args()
    print(f"delta = {DELTA} m, {args.cases} cases per row, test bound on normalized = {CONTINUITY_BOUND}")
    print(f"{'kind':8} {'k':>2} {'compared':>9} {'worst ratio':>12} {'worst normalized':>17} {'median':>8}")
    for kind in ("generic", "tie", "vertex"):
        for legs in (4, 6, 8):
            ratios, normalized = [], []
            for case in continuity_cases(kind, legs, args.cases, seed=args.seed):
                if case is not None:
                    ratios.append(case.ratio)
                    normalized.append(case.normalized)
            normalized.sort()
            print(
                f"{kind:8} {legs:>2} {len(ratios):>9} {max(ratios):>12.4f} {normalized[-1]:>17.4f} "
                f"{normalized[len(normalized) // 2]:>8.4f}"
            )


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
