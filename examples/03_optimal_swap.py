"""03 — The fastest safe swap: both AGVs move at once, inside the planner's homotopy class.

The exact schedule moves one vehicle at a time and parks the waiting vehicle at
the far end of the side leg. The planner has already decided *who waits where
and in which order the junction is used* (the homotopy class, a sequence of
regions). Within that class, the optimal method lets both vehicles move at
once, parks the waiting vehicle only as deep as the separation needs, and
keeps the jerk limited. The independent verifier checks the result; the
coordination diagram shows why it is safe.
"""

import os
import tempfile
from pathlib import Path

from trajgen import METHODS, certify, load_scenario, lower_bound, make_schedule
from trajgen.export import commit_files
from trajgen.plots import render_coordination, render_speed

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
output = Path(os.environ.get("TRAJGEN_EXAMPLE_OUTPUT") or tempfile.mkdtemp(prefix="trajgen-example-"))

route = scenario.plan()
print("homotopy class:", " -> ".join(str(region) for region in route.regions))

# Every registered method, each schedule certified by the verifier (it raises if one fails).
verified = {m.name: certify(make_schedule(route, scenario.limits, method=m())) for m in METHODS}
bound = lower_bound(route, scenario.limits)
for name, item in verified.items():
    report = item.report
    print(
        f"{name:>8}: {item.schedule.duration:6.2f} s  verified {report.passed}  "
        f"closest approach {report.min_separation:5.2f} m  same class {report.regions_match}"
    )
print(f"   bound: {bound:6.2f} s  (each vehicle alone on its shortest path)")
optimal = verified["optimal"].schedule
ratio = optimal.duration / verified["exact"].schedule.duration
print(f"optimal / exact = {ratio:.3f}; solver: {optimal.info.status}")

# How deep does the waiting vehicle park? (exact parks it at the end of leg C)
state = optimal.sample(0.01)
print(f"deepest point of vehicle 2 in leg C: {state.s[1][state.leg[1] == 2].max():.2f} m of 10 m")

# Renderers return bytes; the files are committed together.
files = commit_files(
    {
        output / "speed.png": render_speed(verified["optimal"], names=scenario.names),
        output / "coordination.png": render_coordination(verified),
    }
)
for path in files:
    print(f"wrote {path}")
