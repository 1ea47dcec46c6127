"""05 — A swap on a junction whose legs are not equal.

Real junctions are not symmetric: here leg A is 12 m, B 8 m and C 15 m. The
vehicles start at the far ends of A and B and swap. The configuration space
is still a circle around the deleted junction point, but its arcs now have
different lengths, so the two ways round it are not equally long: the
planner's instruction (counterclockwise for a swap) and the other way round
(``homotopy="other"``). ``optimal`` solves both and keeps the faster.
"""

from limits import Limits, VehicleLimits
from topology import Configuration, Position, YGraph, plan
from trajgen import Exact, Optimal, certify, make_schedule
from trajgen.model.summary import class_label

track = YGraph({"A": 12.0, "B": 8.0, "C": 15.0})  # metres, counterclockwise order
start = Configuration(Position("A", 12.0), Position("B", 8.0))
agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
limits = Limits(vehicles=(agv, agv), min_separation=1.5)

# The planner's two routes: its instruction, and the same retractions the other way round.
paper = plan(track, start, start.swapped(), min_separation=1.5)
other = plan(track, start, start.swapped(), min_separation=1.5, homotopy="other")
for route in (paper, other):
    print(f"{class_label(route)}: regions {' '.join(map(str, route.regions))}")

# exact: one vehicle moves at a time along the planner's route; optimal: both at once, either class.
exact = certify(make_schedule(paper, limits, method=Exact()))
optimal = certify(make_schedule(paper, limits, method=Optimal()))
for verified in (exact, optimal):
    schedule, report = verified.schedule, verified.report
    print(
        f"{schedule.method.name:>7}: {schedule.duration:6.2f} s in "
        f"class {class_label(schedule.route)}, closest approach {report.min_separation:.3f} m"
    )

# The waiting vehicle parks only as deep in a leg as the separation needs.
print(f"optimal / exact = {optimal.schedule.duration / exact.schedule.duration:.3f}")
