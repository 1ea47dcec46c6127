"""12 — A track graph: several junctions, a passing loop, and a layout that cannot work.

A plant's layout has more than one junction. A scenario whose ``[track]`` has ``edges``
(``graphs/passing-loop.toml``) is a track graph, and the exact planner finds the shortest
collision-free route with one vehicle moving at a time: here the AGVs meet head-on on a single
line and pass each other on its loop. Without the loop they could not change their order, and
the planner says so, naming who is blocked and where. The route is drawn from above.
"""

import os
import tempfile
from pathlib import Path

from topology import InfeasibleError, TrackGraph, plan_graph
from trajgen import load_scenario
from trajgen.export import commit_files
from trajgen.plots import plot_graph_route, png_bytes

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "graphs" / "passing-loop.toml")
track = scenario.track
print(
    f"track: {len(track.nodes)} nodes, {track.edge_count} edges; {scenario.limits.min_separation:g} m apart"
)

# 1. The shortest collision-free route: each vehicle's travel, and the moves one at a time.
route = scenario.route()
for vehicle, name in enumerate(scenario.names):
    print(f"{name} drives {route.travel[vehicle]:g} m")
for number, move in enumerate(route.moves, start=1):
    edges = ", ".join(track.edges[edge].name for edge in move.edges)
    print(
        f"  {number}. {scenario.names[move.vehicle]}: {track.name(move.points[0])} -> "
        f"{track.name(move.points[-1])} along {edges} ({move.length:g} m)"
    )

# 2. The same line without its loop: the vehicles cannot change their order.
without_loop = TrackGraph.from_edges(
    {edge.name: (edge.start, edge.end, edge.length) for edge in track.edges if edge.name != "loop"},
    coordinates=dict(zip(track.nodes, track.coordinates, strict=True)),
)
start = [track.name(point) for point in scenario.start]  # as written: "west:1", "east:9"
goal = [track.name(point) for point in scenario.goal]
try:
    plan_graph(without_loop, start, goal, min_separation=1.5, names=scenario.names)
except InfeasibleError as error:
    print(f"without the loop: {error}")

# 3. The picture: the track from above with the numbered moves.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()
picture = png_bytes(plot_graph_route(route, names=scenario.names))
for path in commit_files({output / "passing-loop.png": picture}):
    print(f"wrote {path} ({path.stat().st_size:,} bytes)")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
