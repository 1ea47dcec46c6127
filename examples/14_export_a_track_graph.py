"""14 — A track graph exported for the machines: PLC tables, `check`, and VDA 5050 orders.

The H (``graphs/h.toml``) timed by ``optimal``, then written as a PLC engineer and a fleet manager
take it: SIMATIC ``TO_Cam`` tables (1,000 points each, linear), read back and verified as the
controller interpolates them along the route's paths (each table turns back where its path does);
the same files checked as a received pair would be, and a copy with agv1 started 8 s late, which
the check refuses; and the VDA 5050 orders, whose nodes sit at the junctions,
the parking points, the reversals and the edge of each junction's zone.
"""

import os
import tempfile
from datetime import UTC, datetime
from pathlib import Path

from trajgen import certify, load_scenario
from trajgen.export import commit_files
from trajgen.export.plc.check import check_profiles
from trajgen.export.plc.files import plc_tables, table_paths
from trajgen.export.vda5050 import Vda5050Options, order_releases
from trajgen.export.vda5050.files import order_files
from trajgen.methods import make_schedule

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "graphs" / "h.toml")
verified = certify(make_schedule(scenario.route(), scenario.limits, method="optimal"))
print(f"optimal: {verified.schedule.duration:.3f} s, verified")

kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
out = Path(kept or scratch.name).resolve()

# 1. SIMATIC TO_Cam tables, verified as interpolated before anything is written.
tables = plc_tables(verified, "siemens-xy")
paths = table_paths(tables.dialect, scenario.names, out / "tables")
figures = tables.resampled.summary()
print(
    f"siemens-xy: {figures['points']} points, worst error {1e3 * max(figures['position_error_m']):.3f} mm, "
    f"closest approach as interpolated {tables.check.report.min_separation:.4f} m"
)

# 2. The VDA 5050 orders of both vehicles and their manifest, committed with the tables.
options = Vda5050Options(start_time=datetime(2026, 1, 1, 8, 0, tzinfo=UTC), map_id="plant")
files = dict(zip(paths, tables.contents, strict=True))
files |= order_files(verified, scenario.names, out / "orders", options=options)
for path in commit_files(files):
    print(f"wrote {path}")
releases = order_releases(verified)
for vehicle, path in enumerate(releases.paths):
    ids = [path.node_id(k) for k in range(len(path.nodes))]
    print(f"{scenario.names[vehicle]} nodes: {' '.join(ids)}")
print(f"the orders with their waits take {releases.planned_duration:.3f} s (one vehicle at a time: 51.500 s)")

# 3. The tables checked as received files, then with agv1's started 8 s late (its drive held at
#    the start, agv2's table unchanged): agv2 now meets agv1 near J2, and the check refuses the pair.
verdict = check_profiles(scenario, out / "tables", dialect="siemens-xy")
print(f"check of the written tables: {'PASS' if verdict.passed else 'FAIL'}")
late = out / "late"
late.mkdir(exist_ok=True)
(late / paths[1].name).write_bytes(paths[1].read_bytes())
rows = paths[0].read_text().splitlines()
held = [rows[0]] + [f"{float(t) + 8.0:.9f};{y}" for t, y in (row.split(";") for row in rows[1:])]
(late / paths[0].name).write_text("\r\n".join(held) + "\r\n")
verdict = check_profiles(scenario, late, dialect="siemens-xy")
print(f"check with agv1 started 8 s late: {'PASS' if verdict.passed else 'FAIL'}")
for failure in verdict.failures[:2]:
    print(f"  {failure}")
if scratch is not None:
    print(f"(the files in {out} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
