"""PLC tables, ``trajgen check`` and VDA 5050 orders of the example track graphs.

Run: ``python benchmarks/bench_graph_exports.py``.

For each example graph scenario (``examples/graphs/``) and timing method: per table dialect the
points of both tables, how much the tables are slowed down to keep the limits as interpolated
(1: not at all), the worst distance of a table from the schedule (mm), and the time to make,
render, read back and verify them; the time ``check`` takes on the generic CSV; and the VDA 5050
orders: messages, and the makespan of the releases' replay against the schedule's (a schedule
with both vehicles near each other at once is released node by node, so it runs slower). Only
the times depend on the clock (``time.perf_counter``, one core).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from trajgen import certify
from trajgen.export.csv import profile_chunk_pair, profile_paths
from trajgen.export.plc.check import check_profiles
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.export.plc.files import plc_tables
from trajgen.export.plc.tables import Interpolation
from trajgen.export.vda5050.release import order_releases
from trajgen.methods import make_schedule
from trajgen.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "graphs"
NAMES = ("h", "main-line-with-sidings", "passing-loop", "ring-with-spurs")
METHODS = ("exact", "toppra", "optimal")


def main() -> None:
    print(f"{'scenario':<24}{'method':<9}{'dialect':<18}{'points':>13}{'slowed':>10}{'error mm':>10}{'s':>7}")
    orders = []
    for name in NAMES:
        scenario = load_scenario(EXAMPLES / f"{name}.toml")
        for method in METHODS:
            verified = certify(make_schedule(scenario.route(), scenario.limits, method=method))
            for dialect in DIALECTS:
                if not isinstance(dialect, TableDialect):
                    continue
                if dialect.interpolation is Interpolation.CUBIC and not verified.schedule.jerk_limited:
                    continue  # a spline needs a jerk-limited schedule: refused
                began = time.perf_counter()
                tables = plc_tables(verified, dialect)
                spent = time.perf_counter() - began
                assert tables.check.passed
                points = "/".join(str(t.times.size) for t in tables.resampled.tables)
                print(
                    f"{name:<24}{method:<9}{dialect.name.value:<18}{points:>13}"
                    f"{tables.resampled.time_scale:>10.6f}{1e3 * max(tables.resampled.position_error):>10.4f}"
                    f"{spent:>7.2f}"
                )
            with tempfile.TemporaryDirectory() as folder:
                for path, chunks in zip(
                    profile_paths(scenario.names, folder), profile_chunk_pair(verified), strict=True
                ):
                    path.write_bytes(b"".join(chunks))
                began = time.perf_counter()
                verdict = check_profiles(scenario, folder, jerk=verified.schedule.jerk_limited)
                spent = time.perf_counter() - began
            assert verdict.passed, verdict.failures
            rows = "/".join(str(t.times.size) for t in verdict.tables)
            print(f"{name:<24}{method:<9}{'generic (check)':<18}{rows:>13}{'':>10}{'':>10}{spent:>7.2f}")
            releases = order_releases(verified)
            orders.append(
                (name, method, len(releases.releases), verified.schedule.duration, releases.planned_duration)
            )
    print(f"\n{'scenario':<24}{'method':<9}{'messages':>9}{'schedule s':>12}{'released s':>12}")
    for name, method, messages, duration, planned in orders:
        print(f"{name:<24}{method:<9}{messages:>9}{duration:>12.3f}{planned:>12.3f}")


if __name__ == "__main__":
    main()
