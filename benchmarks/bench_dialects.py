"""PLC dialects on the demo swap, and how often the tables of random scenarios verify.

Run: ``python benchmarks/bench_dialects.py [--scenarios N] [--seed S]``.

For each dialect: the first lines of vehicle 1's file, the point limit, the
points used, the worst position and velocity error of the interpolated tables
against the schedule, how much slower the tables run, and the time to
resample, render, read back and verify both tables. Then every table dialect
on N seeded random scenarios (exact and optimal): how many export and verify.
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from limits import ILLUSTRATIVE_LIMITS
from topology import YGraph
from trajgen import Exact, Optimal, certify, default_scenario, make_schedule, run
from trajgen.errors import OutputLimitError, VerificationError
from trajgen.export.plc import plc_tables
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.progress import progress
from trajgen.scenario.sampling import random_scenarios


def demo() -> None:
    verified = run(default_scenario()).verified
    print(f"demo swap, optimal: {verified.schedule.duration:.3f} s")
    for dialect in DIALECTS:
        if not isinstance(dialect, TableDialect):
            continue
        begin = time.perf_counter()
        tables = plc_tables(verified, dialect)
        elapsed = time.perf_counter() - begin
        figures = tables.summary()
        print(f"\n{dialect.name.value}: limit {dialect.point_limit:,} points, {dialect.interpolation.value}")
        for line in tables.contents[0].decode("ascii").splitlines()[:4]:
            print(f"    {line}")
        print(
            f"  points {figures['points']}, worst error {1e3 * max(figures['position_error_m']):.3g} mm "
            f"and {1e3 * max(figures['velocity_error_mps']):.3g} mm/s, time scale "
            f"{figures['time_scale']:.6f}, separation as interpolated {figures['min_separation_m']:.6f} m, "
            f"{1e3 * elapsed:.0f} ms"
        )


def campaign(count: int, seed: int) -> None:
    rng = random.Random(seed)
    scenarios = []
    for k in range(count):  # a different track each time, as in bench_schedule.py
        track = YGraph({name: rng.uniform(4.0, 20.0) for name in "ABC"})
        scenarios += random_scenarios(1, seed=seed * 1000 + k, track=track, limits=ILLUSTRATIVE_LIMITS)
    dialects = [d for d in DIALECTS if isinstance(d, TableDialect)]
    outcomes = {(d.name.value, m): [] for d in dialects for m in ("exact", "optimal")}
    times = []
    for scenario in progress(scenarios, description="scenarios"):
        route = scenario.route()
        for label, method in (("exact", Exact()), ("optimal", Optimal())):
            verified = certify(make_schedule(route, scenario.limits, method=method))
            for dialect in dialects:
                begin = time.perf_counter()
                try:
                    tables = plc_tables(verified, dialect)
                    outcomes[dialect.name.value, label].append(max(tables.resampled.position_error))
                except (VerificationError, OutputLimitError) as error:
                    outcomes[dialect.name.value, label].append(error)
                times.append(time.perf_counter() - begin)
    print(f"\n{count} random scenarios (seed {seed}), every table dialect:")
    for (name, label), results in outcomes.items():
        errors = [r for r in results if isinstance(r, float)]
        failed = [r for r in results if not isinstance(r, float)]
        worst = f", worst position error {1e3 * max(errors):.3g} mm" if errors else ""
        print(f"  {name:17s} {label:8s} verified {len(errors)}/{len(results)}{worst}")
        for error in failed[:2]:
            print(f"      {type(error).__name__}: {str(error)[:160]}")
    print(
        f"  per export (resample, render, read back, verify): "
        f"median {1e3 * statistics.median(times):.0f} ms, "
        f"worst {1e3 * max(times):.0f} ms"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    demo()
    campaign(args.scenarios, args.seed)


if __name__ == "__main__":
    main()
