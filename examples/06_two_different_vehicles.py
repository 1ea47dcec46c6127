"""06 — Two different vehicles: a fast AGV and a slow, heavy one.

Vehicle 1 drives at 1.0 m/s, 0.5 m/s², 1.0 m/s³; vehicle 2 at 0.7 m/s,
0.35 m/s², 0.6 m/s³. Which vehicle waits and where matters now: the schedule
should keep the slow vehicle moving and let the fast one make the detour.
In the paper's homotopy class the slow vehicle has the long way; the other
class gives it the short one, and ``optimal`` finds that it is faster.
"""

from limits import Limits, VehicleLimits
from topology import Configuration, Position, YGraph, plan
from trajgen import Optimal, certify, make_schedule
from trajgen.model.summary import class_label

track = YGraph({"A": 12.0, "B": 8.0, "C": 15.0})
start = Configuration(Position("A", 12.0), Position("B", 8.0))
fast = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
slow = VehicleLimits(max_velocity=0.7, max_acceleration=0.35, max_jerk=0.6)
limits = Limits(vehicles=(fast, slow), min_separation=1.5)
route = plan(track, start, start.swapped(), min_separation=1.5)

# Keep the paper's class, then let optimal choose between the two shortest classes.
in_planned_class = certify(make_schedule(route, limits, method=Optimal(homotopy="planned")))
fastest = certify(make_schedule(route, limits, method=Optimal()))
print(f"class {class_label(in_planned_class.schedule.route)}: {in_planned_class.schedule.duration:.2f} s")
print(f"chosen: class {class_label(fastest.schedule.route)}, {fastest.schedule.duration:.2f} s")

# Each vehicle keeps its own limits (the verifier's worst ratios, per vehicle).
report = fastest.report
for k, name in enumerate(("fast", "slow")):
    print(
        f"{name} vehicle: peak |v|/limit {report.velocity_ratio[k]:.4f}, |a|/limit "
        f"{report.acceleration_ratio[k]:.4f}, |j|/limit {report.jerk_ratio[k]:.4f}"
    )
saved = in_planned_class.schedule.duration - fastest.schedule.duration
print(f"time saved by the other class: {saved:.2f} s")
