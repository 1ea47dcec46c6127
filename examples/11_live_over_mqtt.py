"""Drive the swap live: VDA 5050 orders over an MQTT broker to two simulated AGVs.

The master (trajgen's ``LiveMaster``) sends each vehicle its order with the base
released only up to its frontier; as the vehicles report the nodes they reach,
it releases more. Here the broker (amqtt, or mosquitto when installed) and both
vehicles run in this process, twenty times faster than real time: a state a
second and a node every metre keep a pure-Python broker at ease. The vehicles
never come closer than the minimum separation, whatever the timing of the
messages: the released base, not the clock, keeps them apart.

Run: ``python examples/11_live_over_mqtt.py``.
"""

from trajgen import default_scenario
from trajgen.live import LiveDemo

scenario = default_scenario()  # the swap: agv1 at A:10, agv2 at B:10 exchange places
with LiveDemo(scenario, method="exact", time_scale=20, state_rate=1, spacing=1.0) as demo:
    outcome = demo.run()

run = outcome.run
print(f"outcome: {run.outcome.value} after {run.makespan:.1f} s of the run (plan {run.planned:.1f} s)")
print(f"{run.orders} orders and order updates ({run.resent} sent again), {run.ignored} messages ignored")
print(f"closest approach on the true positions: {outcome.closest:.3f} m (separation 1.5 m)")

# The run log: one JSON object per line (plan, order, state, connection, ..., end).
releases = [r for r in outcome.log.records() if r["event"] == "order" and r["update"] > 0 and not r["resent"]]
print(f"{len(releases)} order updates released more base, the first at {releases[0]['t']:.1f} s")
outcome.log.close()
