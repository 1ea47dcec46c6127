"""01 — Plan a swap on a Y-track.

Two AGVs sit at the far ends of legs A and B of a Y-shaped track and must
exchange places. Neither can pass the other on a leg, so one of them has to
wait in the third leg while the other crosses the junction. The planner picks
which one, and in which order, from the topology of the configuration space.
"""

from topology import Configuration, Position, YGraph, classify, plan, retract

# A track with legs of different lengths (metres), listed counterclockwise.
track = YGraph({"A": 10.0, "B": 8.0, "C": 15.0})

# Vehicle 1 at the end of A, vehicle 2 at the end of B; the goal swaps them.
start = Configuration(Position("A", 10.0), Position("B", 8.0))
goal = start.swapped()

# Keep at least 1.5 m between the vehicles, measured along the track.
route = plan(track, start, goal, min_separation=1.5)

# A swap is "antipodal" on the boundary circle: the planner goes counterclockwise.
print(f"instruction: {route.instruction}")
for k, waypoint in enumerate(route.waypoints):
    print(f"  {k}: {waypoint}   ({classify(track, waypoint)}, {track.separation(waypoint):g} m apart)")

# The homotopy class is the sequence of regions the pair visits.
print("regions:", " -> ".join(str(region) for region in route.regions))
print(f"vehicle 1 drives {route.travel[0]:g} m, vehicle 2 drives {route.travel[1]:g} m")

# A start inside the track first retracts onto the boundary circle.
inner = Configuration(Position("A", 3.0), Position("B", 2.0))
print("retraction of (A:3, B:2):", " -> ".join(str(c) for c in retract(track, inner)))
