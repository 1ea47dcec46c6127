"""02 — From a scenario file to verified speed profiles for the PLCs.

A scenario file names the track, the minimum separation and, for each AGV, its
drive limits, start and goal. We plan the route, time it two ways, let the
independent verifier check both, and hand the vehicles CSV profiles and plots.

- ``exact`` follows the planner's route piece by piece with jerk-limited
  S-curves: smooth, but one vehicle moves at a time.
- ``toppra`` rounds the corners where that stays safe and times the path with
  TOPPRA: faster, but only velocity and acceleration are limited.
"""

import os
import tempfile
from pathlib import Path

from trajgen import CsvOptions, Exact, Outputs, Toppra, load_scenario, make_schedule, run, verify

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()

route = scenario.route()
print(
    f"route: {route.instruction}, {len(route.waypoints)} waypoints, regions {[str(r) for r in route.regions]}"
)

# Each timing method is an object that carries its options.
exact = make_schedule(route, scenario.limits, method=Exact())
fast = make_schedule(route, scenario.limits, method=Toppra())
for schedule in (exact, fast):
    report = verify(schedule)
    print(
        f"{schedule.method.name:>6}: {schedule.duration:6.2f} s, verified {report.passed}, "
        f"closest approach {report.min_separation:.2f} m, peak |v|/limit {max(report.velocity_ratio):.4f}"
    )
print("toppra notes:", "; ".join(fast.notes))

# The pipeline plans, schedules, verifies, renders every file, then commits them all at once:
# the files appear whole or not at all.
outputs = Outputs(csv_dir=output / "csv", plot_dir=output / "plots", csv=CsvOptions(sample_period=0.01))
result = run(scenario, method=Exact(), outputs=outputs)
for path in result.files:
    print(f"wrote {path}")

# The first rows of agv2's profile: t, signed axis, v, a, j, leg (1-based), s, x, y.
print(*(output / "csv" / "agv2.csv").read_text().splitlines()[:3], sep="\n")
print(f"exact makespan: {result.verified.schedule.duration:.2f} s")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
