"""08 — VDA 5050 orders: handing the swap to a fleet manager.

A plant whose AGVs speak VDA 5050 does not take speed profiles: its master
control sends each vehicle an *order* (nodes and edges with a speed limit per
edge) and releases the track bit by bit. The part that is released (the
*base*) the vehicle drives at its own pace; the rest (the *horizon*) it only
knows about, and it stops at the last released node until an *order update*
releases more.

So the safety of the swap now rests on the releases: each vehicle's released
track must stay the minimum separation away from the other's, however fast
either drives. trajgen derives the nodes from the verified schedule, plans the
releases in the order the schedule uses the junction, and writes every
message with the event that makes it safe to send.

We also take agv1's drive limits from its maker's VDA 5050 factsheet.
"""

import json
import os
import tempfile
from datetime import UTC, datetime
from pathlib import Path

from trajgen import load_scenario, run
from trajgen.export.vda5050 import Vda5050Options, write_orders

here = Path(__file__).resolve().parent
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()

# 1. The AGV maker's factsheet (VDA 5050 2.1.0) gives speedMax, accelerationMax and
#    decelerationMax. trajgen's limits are symmetric, so it takes the smaller of the two
#    accelerations (here 0.5 m/s²). A factsheet has no jerk limit: the scenario keeps max_jerk.
factsheet = {
    "headerId": 1,
    "timestamp": "2025-05-01T07:00:00.00Z",
    "version": "2.1.0",
    "manufacturer": "Acme",
    "serialNumber": "SN-0001",
    "typeSpecification": {
        "seriesName": "Y-100",
        "agvKinematic": "DIFF",
        "agvClass": "CARRIER",
        "maxLoadMass": 500,
        "localizationTypes": ["NATURAL"],
        "navigationTypes": ["VIRTUAL_LINE_GUIDED"],
    },
    "physicalParameters": {
        "speedMin": 0.01,
        "speedMax": 1.0,
        "accelerationMax": 0.6,
        "decelerationMax": 0.5,
        "heightMax": 0.4,
        "width": 0.8,
        "length": 1.2,
    },
    "protocolLimits": {
        "maxStringLens": {},
        "maxArrayLens": {},
        "timing": {"minOrderInterval": 0.5, "minStateInterval": 0.5},
    },
    "protocolFeatures": {"optionalParameters": [], "agvActions": []},
    "agvGeometry": {},
    "loadSpecification": {},
}
output.mkdir(parents=True, exist_ok=True)
(output / "acme-y100.json").write_text(json.dumps(factsheet, indent=2), encoding="utf-8")

# The scenario of the demo swap, with agv1's velocity and acceleration from the factsheet
# (a relative path is found beside the scenario file).
text = (here / "swap.toml").read_text(encoding="utf-8")
agv1 = text.index('name = "agv1"')
text = text[:agv1] + text[agv1:].replace("max_velocity = 1.0", 'factsheet = "acme-y100.json"', 1).replace(
    "max_acceleration = 0.5\n", "", 1
)
(output / "swap-factsheet.toml").write_text(text, encoding="utf-8")
scenario = load_scenario(output / "swap-factsheet.toml")
print("agv1 limits from the factsheet:", scenario.limits.first)

# 2. Plan, schedule (optimal: both vehicles move at once) and verify, as for CSV profiles.
result = run(scenario, method="optimal")
print(f"verified schedule: {result.verified.schedule.duration:.2f} s")

# 3. Write the orders. The start time makes the timestamps real and the files reproducible.
options = Vda5050Options(
    start_time=datetime(2025, 5, 1, 8, 0, tzinfo=UTC),
    map_id="hall-1",
    manufacturers=("Acme", "Acme"),
    serial_numbers=("SN-0001", "SN-0002"),
)
files = write_orders(result.verified, scenario.names, output / "vda5050", options=options)
for path in files:
    print(f"wrote {path}")

# 4. agv1's first order: released to the hold node 1.5 m (the separation) before the junction,
#    the junction and beyond it still horizon, because agv2 goes through first.
order = json.loads((output / "vda5050" / "agv1" / "order-000.json").read_text(encoding="utf-8"))
for node in order["nodes"]:
    print(f"  node {node['nodeId']:>6} seq {node['sequenceId']} released={node['released']}")
for edge in order["edges"]:
    print(f"  edge {edge['edgeId']:>12} maxSpeed {edge['maxSpeed']} m/s released={edge['released']}")

# 5. The manifest says when each message becomes safe: on which node report of the other vehicle,
#    and at what time of the schedule that is (the timestamp).
manifest = json.loads((output / "vda5050" / "manifest.json").read_text(encoding="utf-8"))
for entry in manifest["messages"]:
    trigger = entry["trigger"]
    when = "at the start" if trigger is None else f"when {trigger['vehicle']} reports {trigger['node_id']}"
    print(f"  {entry['file']}: {entry['timestamp']} ({when}), waits {entry['wait_s']:.2f} s")
planned, scheduled = manifest["planned_duration_s"], manifest["schedule_duration_s"]
print(
    f"VDA 5050 cannot time two vehicles near the junction at once: {planned:.2f} s against {scheduled:.2f} s"
)
update = next(e for e in manifest["messages"] if e["vehicle"] == "agv1" and e["order_update_id"] == 1)
print(f"agv1 may pass the junction at t = {update['send_at_s']:.3f} s")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
