"""15 — A track graph in closed loop: the H played by the online executor, stopped, and re-routed.

The executor keeps the plan's paths and, at every conflict, who passes first; time stretches. On
the H (``graphs/h.toml``) agv1 waits in the side leg ``c`` while agv2 passes. The plan here is
``exact``: the planner's moves one at a time. Undisturbed, the executor plays it as planned. When
agv1 stops for 5 s on its way to ``c``, both leave the plan's clock and each drives as fast as its
frontier lets it, in the plan's order: agv2 waits short of the junction J2 only while agv1 could
still be in the way, so the run ends before the one-move-at-a-time plan would. Then a new goal for
agv2 half-way: both stop, the exact planner plans from where they stand, and the run goes on. The
separation is measured on the simulated vehicles' true positions.
"""

from pathlib import Path

from trajgen import load_scenario
from trajgen.execution import schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "graphs" / "h.toml")
verified = schedule_for_execution(scenario, method="exact")  # keeps 2 x 0.05 m of margin

plain, _ = simulate(scenario, verified=verified)
print(
    f"undisturbed: {plain.makespan_s:.2f} s against {plain.planned_s:.2f} s planned, closest approach "
    f"{plain.min_separation_m:.3f} m"
)

stopped, _ = simulate(scenario, parse_faults(scenario, ["stop:agv1@10+5"]), verified=verified)
print(
    f"agv1 stops 5 s at t = 10 s: the run with the stop takes {stopped.makespan_s:.2f} s, closest approach "
    f"{stopped.min_separation_m:.3f} m, {stopped.separation_violations} separation violations, "
    f"{stopped.emergency_brakes} emergency brakes"
)

rerouted, _ = simulate(scenario, parse_faults(scenario, ["goal:agv2@20=b:3"]), verified=verified)
for event in rerouted.events:
    print(f"  {event.time:7.2f} s  {event.kind}: {event.detail}")
print(
    f"new goal for agv2: reached {rerouted.reached_goal} at {rerouted.makespan_s:.2f} s, closest approach "
    f"{rerouted.min_separation_m:.3f} m"
)
