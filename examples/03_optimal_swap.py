"""03 — The fastest safe swap: both AGVs move at once, in the faster of two homotopy classes.

The exact schedule moves one vehicle at a time and parks the waiting vehicle at
the far end of the side leg. The planner has already decided *who waits where
and in which order the junction is used* (the homotopy class, a sequence of
regions). The optimal method solves that class and the one that goes the other
way round the configuration circle, lets both vehicles move at once, parks the
waiting vehicle only as deep as the separation needs, keeps the jerk limited,
and returns the faster. The independent verifier checks the result; the
coordination diagram shows why it is safe.
"""

import os
import tempfile
from pathlib import Path

from trajgen import METHODS, certify, load_scenario, lower_bound, make_schedule
from trajgen.export import commit_files
from trajgen.model.summary import class_label, class_words
from trajgen.plots import plot_coordination, plot_speed, png_bytes

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()

route = scenario.route()
print(f"class {class_label(route)}:", " -> ".join(str(region) for region in route.regions))

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
print(f"optimal / exact = {ratio:.4f}; solver: {optimal.info.status}")
for item in optimal.info.classes:  # the two classes it solved, and which it chose
    makespan = "not solved" if item.makespan is None else f"{item.makespan:.3f} s"
    print(
        f"  class {class_words(item.homotopy.value, item.way_round.value)}: {makespan}, chosen {item.chosen}"
    )

# How deep does the waiting vehicle park? (exact parks it at the end of leg C)
state = optimal.sample(0.01)
waiting = max(range(2), key=lambda v: (state.leg[v] == 2).sum())  # the vehicle that dodges into C
deepest = state.s[waiting][state.leg[waiting] == 2].max()
print(f"deepest point of vehicle {waiting + 1} in leg C: {deepest:.2f} m of 10 m")

# Plots return matplotlib Figures; as PNG bytes, the files are committed together.
files = commit_files(
    {
        output / "speed.png": png_bytes(plot_speed(verified["optimal"], names=scenario.names)),
        output / "coordination.png": png_bytes(plot_coordination(verified)),
    }
)
for path in files:
    print(f"wrote {path}")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
