"""13 — A track graph timed: the H by all three methods, verified, written as CSV and pictures.

The H (``graphs/h.toml``) joins two Y junctions by a middle edge; agv1 and agv2 swap its ends,
one waiting in a side leg while the other passes. ``exact`` times the planner's moves one after
the other, ``toppra`` overlaps the hand-overs where the corner keeps the separation, and
``optimal`` solves the jerk-limited time-optimal problem in each class (agv1 waiting in ``c``, or
agv2 in ``b``) and keeps the faster. Every schedule is verified in closed form with the track
distance of the graph, and the generic CSV names the edge and the metres along it.
"""

import os
import tempfile
from pathlib import Path

from trajgen import certify, load_scenario
from trajgen.export import commit_files
from trajgen.export.csv import profile_chunk_pair, profile_paths
from trajgen.methods import make_schedule
from trajgen.model.analysis import lower_bound
from trajgen.plots import plot_coordination, png_bytes

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "graphs" / "h.toml")
route = scenario.route()
bound = lower_bound(route, scenario.limits)
print(f"lone-vehicle bound: {bound:.3f} s (no schedule is faster)")

# 1. All three methods, each verified by the closed-form verifier of track graphs.
verified = {}
for method in ("exact", "toppra", "optimal"):
    verified[method] = certify(make_schedule(route, scenario.limits, method=method))
    report = verified[method].report
    print(
        f"{method:>8}: {verified[method].schedule.duration:7.3f} s, closest approach "
        f"{report.min_separation:.4f} m, worst |v|/limit {max(report.velocity_ratio):.6f}"
    )
print(f"optimal / exact = {verified['optimal'].schedule.duration / verified['exact'].schedule.duration:.4f}")
for comparison in verified["optimal"].schedule.info.summary()["classes"]:
    mark = "  <- chosen" if comparison["chosen"] else ""
    print(f"  class {comparison['class']}: {comparison['makespan_s']:.3f} s{mark}")

# 2. The optimal schedule's generic CSV (the edge by name, s along it, x/y) and the coordination
#    diagram of all three, committed together.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
out = Path(kept or scratch.name).resolve()
files = dict(zip(profile_paths(scenario.names, out), profile_chunk_pair(verified["optimal"]), strict=True))
files[out / "coordination.png"] = png_bytes(plot_coordination(verified))
for path in commit_files(files):
    print(f"wrote {path}")
header, first_row = (out / "agv1.csv").read_text().splitlines()[:2]
print(f"{header}\n{first_row}")
if scratch is not None:
    print(f"(the files in {out} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
