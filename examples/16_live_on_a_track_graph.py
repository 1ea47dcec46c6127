"""Drive the H live: VDA 5050 orders over an MQTT broker to two line-guided AGVs on a track graph.

The H's side edges curve (6.5 m between nodes 6.4 m apart), so the orders give their inner nodes
no position: the simulated vehicles drive there by the edges' lengths and report where they are by
their last node and the distance past it, as line-guided vehicles do. The master releases each
vehicle's base node by node, as on a junction; the claims of track it releases, not the clock,
keep the vehicles apart. The broker and both vehicles run in this process, twenty times faster
than real time.

Run: ``python examples/16_live_on_a_track_graph.py``.
"""

from trajgen import builtin_scenario
from trajgen.live import LiveDemo
from trajgen.live.places import snapshot_point

scenario = builtin_scenario("h")  # agv1 at A and agv2 at D swap ends; one waits in a side edge
with LiveDemo(scenario, method="exact", time_scale=20, state_rate=1, spacing=1.0) as demo:
    outcome = demo.run()

run = outcome.run
print(f"outcome: {run.outcome.value} after {run.makespan:.1f} s of the run (plan {run.planned:.1f} s)")
print(f"{run.orders} orders and order updates, {run.ignored} messages ignored")
print(f"closest approach on the true places: {outcome.closest:.3f} m (separation 1.5 m)")
# where each vehicle truly stands, from its last node and the metres past it (no x/y on a curve)
for name, vehicle, goal in zip(scenario.names, outcome.vehicles, scenario.goal, strict=True):
    snapshot = vehicle.snapshot
    place = snapshot_point(scenario.track, snapshot.node, snapshot.next_node, snapshot.along)
    away = scenario.track.distance(place, goal)
    print(f"{name} stands at {scenario.track.name(place)}, {away:.3f} m from its goal")
outcome.log.close()
