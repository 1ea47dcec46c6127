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

from topology import plan
from trajgen.export import CsvOptions, write_profiles
from trajgen.plotting import write_plots
from trajgen.scenario import load_scenario
from trajgen.schedule import exact_schedule
from trajgen.toppra_timing import toppra_schedule
from trajgen.verify import verify

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
output = Path(os.environ.get("TRAJGEN_EXAMPLE_OUTPUT") or tempfile.mkdtemp(prefix="trajgen-example-"))

route = plan(scenario.track, scenario.start, scenario.goal, min_separation=scenario.limits.min_separation)
print(
    f"route: {route.instruction}, {len(route.waypoints)} waypoints, regions {[str(r) for r in route.regions]}"
)

exact = exact_schedule(route, scenario.limits)
fast = toppra_schedule(route, scenario.limits)
for schedule in (exact, fast):
    report = verify(schedule)
    print(
        f"{schedule.method:>6}: {schedule.duration:6.2f} s, verified {report.passed}, "
        f"closest approach {report.min_separation:.2f} m, peak |v|/limit {max(report.velocity_ratio):.4f}"
    )
print("toppra notes:", "; ".join(fast.notes))

# Only verified schedules are written; the files appear whole or not at all.
_, paths = write_profiles(exact, scenario.names, output / "csv", options=CsvOptions(sample_period=0.01))
plots = write_plots(exact, output / "plots", names=scenario.names)
for path in (*paths, *plots):
    print(f"wrote {path}")

# The first rows of agv2's profile: t, signed axis, v, a, j, leg (1-based), s, x, y.
print(*paths[1].read_text().splitlines()[:3], sep="\n")
