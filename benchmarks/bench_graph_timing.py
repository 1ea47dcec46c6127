"""The timing methods on the example track graphs: makespans, against the lone-vehicle S-curve bound.

Run: ``python benchmarks/bench_graph_timing.py``.

For each example graph scenario (``examples/graphs/``) and for the built-in swap written as a
track graph (each leg an edge from the junction ``O``): the makespan of ``exact``, ``toppra`` and
``optimal`` (each verified), the lone-vehicle bound (the larger of the two vehicles' own
jerk-limited rest-to-rest times over their shortest paths: no schedule can be faster), optimal's
excess over it, and optimal's classes with their makespans. Also the star form's optimal makespan
of the swap, for the comparison of the two forms. Makespans do not depend on the clock; the
solve times (``time.perf_counter``, one core) are printed for scale.
"""

from __future__ import annotations

import time
from pathlib import Path

from topology import plan_graph
from trajgen import certify
from trajgen.methods import make_schedule
from trajgen.model.analysis import lower_bound
from trajgen.scenario import BuiltinScenario, builtin_scenario, load_scenario

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "graphs"
NAMES = ("h", "main-line-with-sidings", "passing-loop", "ring-with-spurs")


def star_as_graph(scenario):
    """The route of a junction scenario on its track as a track graph (``StarGraph.track_graph``)."""
    star = scenario.track
    return plan_graph(
        star.track_graph(),
        [star.edge_point(p) for p in scenario.start],
        [star.edge_point(p) for p in scenario.goal],
        min_separation=scenario.limits.min_separation,
        names=scenario.names,
    )


def main() -> None:
    cases = [(name, load_scenario(EXAMPLES / f"{name}.toml")) for name in NAMES]
    swap = builtin_scenario(BuiltinScenario.SWAP)
    rows = [(name, scenario.route(), scenario.limits) for name, scenario in cases]
    rows.append(("swap as a graph", star_as_graph(swap), swap.limits))
    print(
        f"{'scenario':<24}{'exact s':>9}{'toppra s':>10}{'optimal s':>11}{'bound s':>9}"
        f"{'optimal/bound':>15}{'solve s':>9}"
    )
    details = []
    for name, route, limits in rows:
        makespans = {}
        for method in ("exact", "toppra", "optimal"):
            began = time.perf_counter()
            verified = certify(make_schedule(route, limits, method=method))
            makespans[method] = (verified.schedule.duration, time.perf_counter() - began)
            if method == "optimal":
                details.append((name, verified.schedule.info.summary()["classes"]))
        bound = lower_bound(route, limits)
        print(
            f"{name:<24}{makespans['exact'][0]:>9.3f}{makespans['toppra'][0]:>10.3f}"
            f"{makespans['optimal'][0]:>11.3f}{bound:>9.3f}{makespans['optimal'][0] / bound:>15.3f}"
            f"{makespans['optimal'][1]:>9.2f}"
        )
    star = certify(make_schedule(swap.route(), swap.limits, method="optimal")).schedule.duration
    graph = certify(make_schedule(star_as_graph(swap), swap.limits, method="optimal")).schedule.duration
    excess = 100.0 * (graph / star - 1.0)
    print(f"\nswap, optimal: star form {star:.3f} s, graph form {graph:.3f} s ({excess:+.2f} %)")
    print("\noptimal's classes (each verified; the chosen one marked):")
    for name, classes in details:
        for c in classes:
            mark = " <- chosen" if c["chosen"] else ""
            makespan = "failed" if c["makespan_s"] is None else f"{c['makespan_s']:.3f} s"
            print(f"  {name:<24}{c['homotopy']:<9}{makespan:>10}  {c['class']}{mark}")


if __name__ == "__main__":
    main()
