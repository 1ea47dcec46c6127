"""Scenario files of track graphs (``[track]`` with ``edges``): read, refused plainly, planned by the CLI."""

from __future__ import annotations

import dataclasses
import json
import tomllib

import pytest

from limits import Limits
from tests.conftest import REPO
from tests.support.grid_oracle import GridTrack, shortest_route
from tests.support.helpers import GRAPH_RUN_FILES
from topology import TrackGraph
from trajgen import verify
from trajgen.cli import main
from trajgen.errors import InputError, ScenarioError, VehicleCountError
from trajgen.methods import make_schedule
from trajgen.scenario import GraphScenario, load_scenario, parse_scenario

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]

BASE = """
[safety]
min_separation = 1.5

[[vehicle]]
name = "agv1"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "{start1}"
goal = "{goal1}"

[[vehicle]]
name = "agv2"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "{start2}"
goal = "{goal2}"
"""


def _scenario(track: str, start=("a:6", "b:6"), goal=("b:6", "a:6")) -> dict:
    text = track + BASE.format(start1=start[0], start2=start[1], goal1=goal[0], goal2=goal[1])
    return tomllib.loads(text)


Y = """
[track.edges]
a = { from = "J", to = "A", length = 6.0 }
b = { from = "J", to = "B", length = 6.0 }
c = { from = "J", to = "C", length = 6.0 }
"""


@pytest.mark.parametrize("name", FEASIBLE)
def test_each_example_plans_the_grid_oracles_shortest_route(name, capsys):
    path = EXAMPLES / f"{name}.toml"
    scenario = load_scenario(path)
    assert isinstance(scenario, GraphScenario)
    assert main(["plan", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert len(summary["travel_m"]) == 2
    assert summary["length_m"] == pytest.approx(sum(summary["travel_m"]))
    assert summary["verified"] is True
    assert summary["closest_approach_m"] >= scenario.limits.min_separation - 1e-9
    assert {move["vehicle"] for move in summary["moves"]} <= set(scenario.names)
    edges = {edge.name: (edge.start, edge.end, edge.length) for edge in scenario.track.edges}
    grid = GridTrack(edges)
    ids = [_grid_point(scenario.track, grid, p) for p in (*scenario.start, *scenario.goal)]
    expected = shortest_route(grid, (ids[0], ids[1]), (ids[2], ids[3]), scenario.limits.min_separation)
    assert summary["length_m"] == pytest.approx(expected, abs=1e-9)
    assert main(["plan", str(path)]) == 0
    text = capsys.readouterr().out
    assert f"travel: {scenario.names[0]} {summary['travel_m'][0]:g} m" in text
    assert text.count(" -> ") == len(summary["moves"])
    assert f"verified: every move keeps {scenario.limits.min_separation:g} m" in text


def _grid_point(track: TrackGraph, grid: GridTrack, point) -> int:
    return grid.index(track.edges[point.edge].name, point.s)


def test_the_infeasible_example_exits_2_naming_the_vehicle_and_the_place(capsys):
    assert main(["plan", str(EXAMPLES / "infeasible.toml")]) == 2
    error = capsys.readouterr().err
    assert "no collision-free route" in error
    assert "agv2 cannot reach its goal W" in error
    assert "agv1 at node W blocks it" in error


def test_a_graph_scenario_reads_nodes_edges_and_positions():
    data = tomllib.loads(
        """
[track]
nodes = { J = [0.0, 0.0], A = [0.0, 6.0], B = [-5.0, -4.0], C = [5.0, -4.0] }
[track.edges]
a = { from = "J", to = "A" }
b = { from = "J", to = "B", length = 7.0 }
c = { from = "J", to = "C", length = 7.0 }
"""
        + BASE.format(start1="A", start2="b:7", goal1="b:7", goal2="a:6")
    )
    scenario = parse_scenario(data, source="y.toml")
    assert scenario.track.length(scenario.track.edge("a")) == pytest.approx(6.0)  # the straight distance
    assert scenario.start == (scenario.track.point("a:6"), scenario.track.point("B"))
    assert scenario.route().length == pytest.approx(6 + 7 + 1.5 + 1.5 + 6 + 7)


@pytest.mark.parametrize(
    ("track", "positions", "match"),
    [
        (
            Y.replace('c = { from = "J", to = "C"', 'c = { from = "C", to = "C"'),
            None,
            r"\[track\]: edge 'c' runs from node 'C' to itself",
        ),
        (Y + 'd = { from = "X", to = "Y", length = 2.0 }\n', None, r"\[track\]: the track is not connected"),
        (
            "[track]\nnodes = { J = [0.0, 0.0], A = [0.0, 6.0] }\n[track.edges]\n"
            'a = { from = "J", to = "A", length = 5.0 }\n',
            ("a:5", "J"),
            r"\[track\]: edge 'a' is 5.0 m long but its nodes 'J' and 'A' are 6 m apart",
        ),
        (
            Y.replace('c = { from = "J"', 'J = { from = "J"'),
            None,
            r"edge name 'J' is given twice \(or is also a node's\)",
        ),
        (
            Y.replace("length = 6.0 }\nc", "length = 6.0, speed = 2 }\nc"),
            None,
            r"\[track\] edges.'b' has unknown key\(s\) \['speed'\]: expected only \['from', 'length', 'to'\]",
        ),
        (
            Y.replace("[track.edges]", "[track]\nlegs = { A = 1.0 }\n[track.edges]"),
            None,
            r"\[track\] has unknown key\(s\) \['legs'\]: expected only \['edges', 'nodes'\]",
        ),
        (Y, ("a:7", "b:6"), r"\[\[vehicle\]\] 1 start: position 'a:7' is off edge 'a'"),
        (Y, ("q:1", "b:6"), r"\[\[vehicle\]\] 1 start: edge 'q' is not on the track"),
        (
            Y,
            ("a:1", "b:0.2"),
            r"the vehicles' start positions \(a:1, b:0.2\) are 1.2 m apart along the track",
        ),
    ],
    ids=[
        "self-loop",
        "disconnected",
        "shorter-than-straight",
        "duplicate-name",
        "unknown-key",
        "legs-and-edges",
        "off-edge",
        "unknown-edge",
        "too-close",
    ],
)
def test_a_bad_graph_scenario_is_refused_naming_the_key(track, positions, match):
    start = positions or ("a:6", "b:6")
    data = _scenario(track if track.lstrip().startswith("[track") else "[track]\n" + track, start=start)
    with pytest.raises(ScenarioError, match=match):
        parse_scenario(data, source="bad.toml")


@pytest.mark.slow  # a demo on the command line, end to end
def test_demo_runs_the_built_in_h_end_to_end(tmp_path, capsys):
    assert main(["demo", "--scenario", "h", "--method", "exact", "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "Demo: the built-in scenario <built-in h.toml> (a track graph, an H of two junctions" in out
    assert "   2  agv2: D -> A along e, m, a, 20.5 m (the other at c:1.5)" in out  # the route's moves
    assert "method: exact  duration: 51.500 s  verified: True" in out
    written = sorted(path.name for path in tmp_path.iterdir())
    assert written == GRAPH_RUN_FILES


THREE = """
[track.edges]
a = { from = "J", to = "A", length = 10.0 }
b = { from = "J", to = "B", length = 10.0 }
c = { from = "J", to = "C", length = 10.0 }
[safety]
min_separation = 1.5
""" + "".join(
    f"""
[[vehicle]]
name = "agv{k}"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "{start}"
goal = "{goal}"
"""
    for k, (start, goal) in enumerate([("A", "B"), ("B", "A"), ("C", "c:5")], start=1)
)


def test_three_vehicles_are_read_and_only_the_planner_refuses_them(tmp_path, capsys):
    path = tmp_path / "three.toml"
    path.write_text(THREE)
    scenario = load_scenario(path)
    assert scenario.names == ("agv1", "agv2", "agv3")
    assert scenario.limits.count == 3
    assert len(scenario.start) == len(scenario.goal) == 3
    with pytest.raises(
        VehicleCountError, match=r"three.toml: the track-graph planner plans exactly 2 vehicles, got 3"
    ):
        scenario.route()
    out = tmp_path / "out"
    commands = (
        ["plan"],
        ["schedule"],
        ["simulate"],
        ["check", "--csv", str(tmp_path)],
        ["export-vda5050", "--out", str(out)],
        ["animate", "--out", str(out / "a.gif")],
    )
    for count, vehicles in (
        (3, THREE),
        (1, THREE[: THREE.index("[[vehicle]]", THREE.index("[[vehicle]]") + 1)]),
    ):
        path.write_text(vehicles)
        for command in commands:
            assert main([*command, str(path)]) == 2, command
            error = capsys.readouterr().err
            assert f"three.toml: the track-graph planner plans exactly 2 vehicles, got {count}" in error, (
                command
            )
            assert "internal failure" not in error
    assert not out.exists()


def test_the_api_refuses_limits_of_another_number_of_vehicles_than_the_route_moves():
    scenario = load_scenario(REPO / "examples" / "graphs" / "h.toml")
    route, (agv, _) = scenario.route(), scenario.limits.vehicles
    for count in (1, 3):
        limits = Limits((agv,) * count, scenario.limits.min_separation)
        with pytest.raises(InputError, match=rf"limits of {count} vehicle\(s\) for a route of 2"):
            make_schedule(route, limits, method="exact")
    schedule = make_schedule(route, scenario.limits, method="exact")
    report = verify(dataclasses.replace(schedule, limits=Limits((agv,) * 3, 1.5)))
    assert not report.passed
    assert report.failures == ("the limits are of 3 vehicle(s), the route moves 2: expected one per vehicle",)


def test_every_pair_of_three_vehicles_keeps_the_separation_at_the_start(tmp_path):
    path = tmp_path / "close.toml"
    path.write_text(THREE.replace('start = "C"', 'start = "c:0.5"').replace('start = "B"', 'start = "b:0.5"'))
    with pytest.raises(
        ScenarioError, match=r"agv2's and agv3's start positions \(b:0.5, c:0.5\) are 1.0 m apart"
    ):
        load_scenario(path)
