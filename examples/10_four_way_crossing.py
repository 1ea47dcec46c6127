"""10 — A 4-way crossing: three instructions instead of two.

On a Y the safe configurations of two vehicles deform onto a circle, so two
continuous instructions plan every move. A 4-way crossing (legs N, W, S, E of
``crossing.toml``) deforms onto a graph ``G_4`` with five independent cycles:
exactly three instructions are needed. trajgen takes the shortest route on
``G_4`` (rule 1), and where two or more routes are equally short it breaks the
tie by a fixed rule (rules 2 and 3), so each instruction is continuous.

Two AGVs cross straight over, N to S and S to N: they meet head-on, so one must
wait in a side leg while the other passes. Then a right-angle crossing, N to S
and W to E, where neither has to turn back.
"""

from pathlib import Path

from topology import Configuration, Instruction, Position, plan
from trajgen import Exact, Optimal, certify, load_scenario, make_schedule

scenario = load_scenario(Path(__file__).with_name("crossing.toml"))
track, limits = scenario.track, scenario.limits
graph = track.retract_graph
cycles = len(graph.edges) - len(graph.vertices) + 1
vertices, edges = len(graph.vertices), len(graph.edges)
print(f"G_{track.leg_count}: {vertices} vertices, {edges} edges, {cycles} independent cycles")
print(f"instructions on this track: {', '.join(i.value for i in Instruction.of_track(track))}")

# Head-on: the planner's route, one vehicle moving at a time between waypoints.
route = scenario.route()
print(f"head-on route ({route.instruction.value}), {route.length:.1f} m of travel:")
for waypoint in route.waypoints:
    print(f"  agv1 {waypoint.first!s:>6}   agv2 {waypoint.second!s:>6}")

exact = certify(make_schedule(route, limits, method=Exact()))
optimal = certify(make_schedule(route, limits, method=Optimal()))
for verified in (exact, optimal):
    schedule, report = verified.schedule, verified.report
    print(
        f"{schedule.method.name:>7}: {schedule.duration:6.2f} s, closest approach "
        f"{report.min_separation:.3f} m, verified {report.passed}"
    )
print(f"head-on optimal / exact = {optimal.schedule.duration / exact.schedule.duration:.3f}")

# Right angle: agv1 N -> S, agv2 W -> E. Both pass the junction, one after the other.
start = Configuration(Position("N", 10.0), Position("W", 10.0))
goal = Configuration(Position("S", 10.0), Position("E", 10.0))
crossing = plan(track, start, goal, min_separation=limits.min_separation)
fast = certify(make_schedule(crossing, limits, method=Optimal()))
print(
    f"right-angle crossing ({crossing.instruction.value}): {crossing.length:.1f} m of travel, "
    f"optimal {fast.schedule.duration:.2f} s, closest approach {fast.report.min_separation:.3f} m"
)
