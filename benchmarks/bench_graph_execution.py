"""What one control cycle's path queries cost on a track graph, against a junction's.

Run: ``python benchmarks/bench_graph_execution.py [--calls N]``.

The executor asks each vehicle's path, every cycle, where a travel value is (``place``), which
travel a measured position is at (``project``), and, in the braking check, the track two ranges of
travel sweep and their distance (``sweep`` + ``set_distance``, up to some hundred times a cycle).
Printed: microseconds per call, median of 5 runs of ``--calls`` calls (``time.perf_counter``, one
core), on the H (``examples/graphs/h.toml``, exact) with :class:`GraphVehiclePath` and
:class:`GraphMetric`, and on the built-in swap with :class:`VehiclePath`.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from trajgen.methods import make_schedule
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.model.paths import VehiclePath, set_distance
from trajgen.scenario import BuiltinScenario, builtin_scenario, load_scenario

H = Path(__file__).resolve().parent.parent / "examples" / "graphs" / "h.toml"


def per_call(function, calls: int) -> float:
    """Median microseconds per call over 5 runs."""
    runs = []
    for _ in range(5):
        began = time.perf_counter()
        for _ in range(calls):
            function()
        runs.append((time.perf_counter() - began) / calls * 1e6)
    return statistics.median(runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=20000)
    calls = parser.parse_args().calls
    scenario = load_scenario(H)
    track = scenario.track
    metric = GraphMetric(track)
    route = make_schedule(scenario.route(), scenario.limits, method="exact").route
    first, second = (GraphVehiclePath.from_path(path, track) for path in graph_paths(route))
    place = first.locate(7.3)
    swap = builtin_scenario(BuiltinScenario.SWAP)
    star = swap.route()
    one, other = VehiclePath.from_route(star, 0), VehiclePath.from_route(star, 1)
    lengths = swap.track.lengths
    star_place = one.locate(7.3)
    rows = [
        ("place", lambda: first.place(7.3), lambda: one.place(7.3)),
        ("project", lambda: first.project(*place, 7.2, metric), lambda: one.project(*star_place, 7.2)),
        (
            "sweep + set_distance",
            lambda: metric.set_distance(first.sweep(5.0, 9.0), second.sweep(3.0, 6.0)),
            lambda: set_distance(one.sweep(5.0, 9.0, lengths), other.sweep(3.0, 6.0, lengths)),
        ),
    ]
    print(f"{'query':<22}{'graph (H) us':>14}{'junction (swap) us':>20}")
    for name, graph_call, star_call in rows:
        print(f"{name:<22}{per_call(graph_call, calls):>14.2f}{per_call(star_call, calls):>20.2f}")


if __name__ == "__main__":
    main()
