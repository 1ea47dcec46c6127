"""04 — A plan meets the floor: the first AGV is stopped in the junction, and the other waits for it.

The verified optimal swap is played in closed loop by the online executor, once
per 10 ms control cycle, against a simulated plant. Just as AGV 1 reaches the
junction, the plant makes it brake at its emergency deceleration and hold for
4 s (a blocked path, an emergency stop). The executor is not told: it sees AGV 1
fall behind its setpoints and re-times it with Ruckig from where it stands. It
keeps the plan's paths and, at every conflict, the plan's order: AGV 2, which
passes the junction after AGV 1, may come no farther than its frontier (short
of where AGV 1 could still come to rest), waits there, and starts the moment
AGV 1 moves on. Nothing re-routes, and the stop costs about its own length.
Every cycle it only commands motion for which it has checked that, if both
vehicles started braking now (the other even at its emergency deceleration),
the separation would still hold.
"""

import os
import tempfile
from pathlib import Path

import numpy as np

from trajgen import load_scenario
from trajgen.execution import schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.export import commit_files
from trajgen.plots import plot_simulation, png_bytes

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()

# The plan the executor plays: the optimal swap, planned with room for the executor's margins.
plan = schedule_for_execution(scenario)
schedule = plan.schedule
print(f"planned swap: {schedule.duration:.2f} s, verified {plan.report.passed}")

# When does AGV 1 reach the junction in the plan? That is where the fault strikes.
t = np.arange(0.0, schedule.duration, 0.01)
state = schedule.state(t)
at_junction = float(t[np.argmax(state.s[0] < 0.05)])
fault = f"stop:{scenario.names[0]}@{at_junction:.2f}+4"
print(f"fault: {fault}  ({scenario.names[0]} braked at the junction and held for 4 s)")

result, _ = simulate(scenario, parse_faults(scenario, [fault]), verified=plan)

print("what the executor did:")
for event in result.events:
    print(f"  t = {event.time:6.2f} s  {event.kind:>13}: {event.detail}")
print(
    f"reached the goal: {result.reached_goal} after {result.makespan_s:.2f} s ({result.time_lost_s:+.2f} s)"
)
print(
    f"closest approach {result.min_separation_m:.3f} m "
    f"(certified between cycles: {result.certified_separation_m:.3f} m; "
    f"minimum {scenario.limits.min_separation} m)"
)
print(
    f"worst setpoints against the limits: v {result.velocity_ratio:.3f}, a {result.acceleration_ratio:.3f}, "
    f"j {result.jerk_ratio:.3f}; violations {result.violations}"
)
assert result.reached_goal
assert result.violations == 0
assert result.replans == 0  # nothing re-routes
assert result.emergency_brakes == 0

path = output / "simulation.png"
figure = plot_simulation(result, names=scenario.names, min_separation=scenario.limits.min_separation)
commit_files({path: png_bytes(figure)})
print(f"wrote {path}")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
