"""Scenarios: the shipped swap and crossing, random ones of 3 to 8 legs, track graphs, every bad file."""

from __future__ import annotations

import dataclasses
import json
import random
import tomllib
from importlib import resources

import pytest

from limits import Limits
from tests.conftest import REPO
from tests.support.grid_oracle import GridTrack, shortest_route
from tests.support.helpers import AGV, GRAPH_RUN_FILES, legs_cases, legs_id
from tests.support.star_scenarios import STAR_SCENARIOS
from topology import Position, StarGraph, TrackGraph
from trajgen import BuiltinScenario, builtin_scenario, make_schedule, parse_scenario, verify
from trajgen.cli import main
from trajgen.errors import InputError, ScenarioError, VehicleCountError
from trajgen.scenario import GraphScenario, default_scenario, load_scenario
from trajgen.scenario.sampling import online_campaign, random_scenarios, random_track

SWAP_FILE = REPO / "examples" / "swap.toml"
GOOD = SWAP_FILE.read_text()

#: The built-in scenarios by number of legs: the swap on a Y (the default) and the 4-way crossing.
BUILT_IN = {3: BuiltinScenario.SWAP, 4: BuiltinScenario.CROSSING}


@pytest.mark.parametrize("legs", legs_cases(sorted(BUILT_IN), slow={4}))
def test_example_file_is_the_built_in_scenario_and_ships_as_package_data(legs):
    name = BUILT_IN[legs]
    example = REPO / "examples" / f"{name.value}.toml"
    packaged = resources.files("trajgen").joinpath("data", f"{name.value}.toml")
    assert packaged.is_file()
    assert (REPO / "trajgen" / "data" / f"{name.value}.toml").read_text() == example.read_text()
    shipped = builtin_scenario(name)
    assert shipped.track.leg_count == legs
    if legs == 3:
        assert example == SWAP_FILE
        default = default_scenario()  # the default
        assert (default.track, default.limits, default.start, default.goal) == (
            shipped.track,
            shipped.limits,
            shipped.start,
            shipped.goal,
        )
    else:
        assert shipped.track.legs == {"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}
        assert shipped.track.angles_deg == (90.0, 180.0, 270.0, 0.0)
        assert shipped.limits == Limits((AGV, AGV), 1.5)
        assert (str(shipped.start), str(shipped.goal)) == ("(N:10, S:10)", "(S:10, N:10)")
    from_file = load_scenario(example)
    assert (shipped.track, shipped.limits, shipped.start, shipped.goal) == (
        from_file.track,
        from_file.limits,
        from_file.start,
        from_file.goal,
    )
    pyproject = (REPO / "pyproject.toml").read_text(encoding="utf-8")
    assert 'trajgen = ["data/*.toml"]' in pyproject  # setuptools package-data: every packaged scenario


@pytest.mark.slow
def test_builtin_scenario_refuses_an_unknown_name():
    with pytest.raises(
        InputError, match=r"built-in scenario 'ring' is unknown: expected one of \['swap', 'crossing', 'h'\]"
    ):
        builtin_scenario("ring")


def test_swap_scenario_contents():
    scenario = load_scenario(SWAP_FILE)
    assert scenario.track.names == ("A", "B", "C")
    assert scenario.track.angles_deg == (90.0, 210.0, 330.0)
    assert scenario.names == ("agv1", "agv2")
    assert scenario.limits.min_separation == 1.5
    assert scenario.limits.first.max_jerk == 1.0
    assert scenario.start.first == Position("A", 10.0)
    assert scenario.goal == scenario.start.swapped()


def _write(tmp_path, text):
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        pytest.param(
            "[safety]",
            "[safety]\nspeed = 3",
            r"\[safety\] has unknown key\(s\) \['speed'\]",
            id="unknown-key",
        ),
        pytest.param(
            "[track]",
            "[track]\nlanes = 2",
            r"\[track\] has unknown key\(s\) \['lanes'\]",
            id="unknown-track-key",
        ),
        pytest.param(
            'name = "agv1"',
            'name = "agv1"\ncolour = "red"',
            r"\[\[vehicle\]\] 1 has unknown key",
            id="unknown-vehicle-key",
        ),
        pytest.param(
            "min_separation = 1.5",
            "",
            r"\[safety\] is missing required key\(s\) \['min_separation'\]",
            id="missing-separation",
        ),
        pytest.param(
            'goal = "B:10.0"',
            "",
            r"\[\[vehicle\]\] 1 is missing required key\(s\) \['goal'\]",
            id="missing-goal",
        ),
        pytest.param(
            'max_jerk = 1.0\nstart = "A',
            'max_jerk = "fast"\nstart = "A',
            r"\[\[vehicle\]\] 1 max_jerk must be a number, got str 'fast'",
            id="wrong-type",
        ),
        pytest.param(
            "min_separation = 1.5",
            "min_separation = true",
            "min_separation must be a number, got bool",
            id="bool-number",
        ),
        pytest.param(
            'start = "A:10.0"',
            'start = "A=10"',
            r"\[\[vehicle\]\] 1 start: position 'A=10' is malformed",
            id="malformed-position",
        ),
        pytest.param(
            'start = "A:10.0"', 'start = "D:1"', r"\[\[vehicle\]\] 1 start: unknown leg 'D'", id="unknown-leg"
        ),
        pytest.param(
            'start = "A:10.0"',
            'start = "A:12"',
            r"start: position s=12\.0 m is beyond the end of leg 'A'",
            id="beyond-leg",
        ),
        pytest.param(
            'start = "A:10.0"',
            "start = 10",
            r"start must be a string like 'A:10\.0' or 'O', got int 10",
            id="position-not-string",
        ),
        pytest.param(
            "max_velocity = 1.0",
            "max_velocity = -1.0",
            r"\[\[vehicle\]\] 1: max_velocity must be > 0 m/s, got -1\.0",
            id="negative-limit",
        ),
        pytest.param("C = 10.0 }", "C = 0.0 }", r"\[track\]: length of leg 'C' must be > 0 m", id="zero-leg"),
        pytest.param(
            "C = 10.0 }",
            "C = 10.0, D = 3.0, E = 3.0, F = 3.0, G = 3.0, H = 3.0, I = 3.0 }",
            r"\[track\]: a track has 3 to 8 legs, got 9",
            id="nine-legs",
        ),
        pytest.param(
            "min_separation = 1.5",
            "min_separation = 12.0",
            r"min_separation 12\.0 m exceeds the shortest leg 10\.0 m",
            id="separation-too-large",
        ),
        pytest.param(
            'goal = "A:10.0"',
            'goal = "B:9.0"',
            r"goal positions \(B:10, B:9\) are 1\.0 m apart",
            id="too-close-at-goal",
        ),
        pytest.param(
            'name = "agv2"', 'name = "agv1"', "name 'agv1' is used by two vehicles", id="duplicate-name"
        ),
        pytest.param(
            'name = "agv2"',
            'name = "../agv2"',
            "name '../agv2' is not a portable file name",
            id="unsafe-name",
        ),
        pytest.param(
            'name = "agv2"', 'name = "agv2\\n"', r"name 'agv2\\n' is not a portable file name", id="newline"
        ),
        pytest.param(
            'name = "agv2"', 'name = "NUL"', "'NUL' is a reserved device name on Windows", id="reserved"
        ),
        pytest.param(
            'name = "agv2"', 'name = "AGV1"', r"'AGV1' is used by two vehicles \(case ignored\)", id="case"
        ),
        pytest.param('name = "agv2"', 'name = "x"', "", id="fine-name"),
        pytest.param(
            "A = 10.0,",
            "A = 1e-300,",
            r"leg 'A' is 1e-300 m long: expected 0\.001 to 100000 m",
            id="tiny-leg",
        ),
        pytest.param(
            "max_velocity = 1.0",
            "max_velocity = 1e9",
            r"max_velocity is 1000000000\.0: expected 0\.0001 to 100",
            id="fast",
        ),
        pytest.param("[track]", "[track", "not valid TOML", id="bad-toml"),
    ],
)
def test_bad_scenario_files(tmp_path, old, new, match):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1) if "agv2" not in old else _replace_last(GOOD, old, new))
    if not match:  # a control: the edit alone is fine
        assert load_scenario(path).names[1] == "x"
        return
    with pytest.raises(ScenarioError, match=match) as caught:
        load_scenario(path)
    assert str(path) in str(caught.value)  # the message names the file


def _replace_last(text: str, old: str, new: str) -> str:
    head, _, tail = text.rpartition(old)
    return head + new + tail


def test_the_reader_takes_any_number_of_vehicles_and_the_junction_planner_two(tmp_path):
    none = "vehicle = []\n" + GOOD[: GOOD.index("[[vehicle]]")]
    with pytest.raises(ScenarioError, match=r"expected one or more \[\[vehicle\]\] tables, got 0"):
        load_scenario(_write(tmp_path, none))
    one = GOOD[: GOOD.rindex("[[vehicle]]")]
    with pytest.raises(
        ScenarioError,
        match=r"scenario.toml: the junction planner \(the paper's\) plans exactly 2 vehicles, got 1",
    ):
        load_scenario(_write(tmp_path, one))
    three = GOOD + GOOD[GOOD.rindex("[[vehicle]]") :].replace("agv2", "agv3")
    with pytest.raises(ScenarioError, match="plans exactly 2 vehicles, got 3"):
        load_scenario(_write(tmp_path, three))


def test_missing_file_is_a_scenario_error(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read the scenario file"):
        load_scenario(tmp_path / "absent.toml")


# -- junctions of 4 to 8 legs: the scenario refuses what a junction cannot be --------------------------------


@pytest.mark.slow
def test_the_scenario_refuses_nine_legs():
    data = STAR_SCENARIOS[8]
    legs = {**data["track"]["legs"], "I": 10.0}
    bad = {**data, "track": {"legs": legs}}
    with pytest.raises(
        ScenarioError, match=r"<nine>: \[track\]: a track has 3 to 8 legs, got 9: \['A', .*'I'\]"
    ):
        parse_scenario(bad, source="<nine>")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("short", "named"),
    [({"W": 1.0}, r"\['W'\]"), ({"W": 1.0, "E": 1.2}, r"\['W', 'E'\]")],
    ids=["one-short-leg", "two-short-legs"],
)
def test_the_scenario_refuses_a_separation_longer_than_legs_naming_them(short, named):
    data = STAR_SCENARIOS[4]
    bad = {**data, "track": {"legs": {**data["track"]["legs"], **short}}}
    with pytest.raises(
        ScenarioError,
        match=rf"min_separation 1.5 m exceeds the shortest leg 1.0 m: legs {named} could not serve",
    ):
        parse_scenario(bad, source="<short legs>")


# -- random scenarios of 3 to 8 legs -------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("k", [4, 6, 8], ids=legs_id)
def test_random_scenarios_on_k_legs_plan_and_verify(k):
    scenarios = online_campaign(3, seed=13, leg_count=k)
    assert all(s.track.leg_count == k and s.track.names == tuple("ABCDEFGH"[:k]) for s in scenarios)
    assert [s.source for s in scenarios] == [f"<online k={k} 13:{n}>" for n in range(3)]
    track = scenarios[0].track
    for scenario in [*scenarios, *random_scenarios(3, seed=2, track=track, limits=scenarios[0].limits)]:
        schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
        assert verify(schedule).passed


@pytest.mark.slow
@pytest.mark.parametrize("count", [2, 9, True], ids=["two", "nine", "bool"])
def test_random_track_refuses_a_leg_count_out_of_range(count):
    with pytest.raises(
        InputError, match=rf"leg_count \(number of legs\) must be an integer from 3 to 8, got {count!r}"
    ):
        random_track(random.Random(0), leg_count=count)


@pytest.mark.slow
def test_random_three_leg_tracks_are_ygraphs_as_before():
    track = random_track(random.Random(3))
    assert track.names == ("A", "B", "C")
    assert track.cycle is not None
    assert isinstance(random_track(random.Random(3), leg_count=5), StarGraph)


def test_the_built_in_h_is_the_example_graph_and_ships_as_package_data():
    example = REPO / "examples" / "graphs" / "h.toml"
    packaged = resources.files("trajgen").joinpath("data", "h.toml")
    assert packaged.is_file()
    assert packaged.read_text() == example.read_text()
    shipped, from_file = builtin_scenario("h"), load_scenario(example)
    assert (shipped.track, shipped.limits, shipped.start, shipped.goal) == (
        from_file.track,
        from_file.limits,
        from_file.start,
        from_file.goal,
    )
    assert [e.name for e in shipped.track.edges] == ["a", "b", "m", "c", "e"]
    assert [shipped.track.name(p) for p in shipped.start] == ["A", "D"]


# -- track graphs: the [track] with edges, positions on edges, the built-in H ----------------------------


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
    assert "   2  agv2: D -> A along e, m, a, 20.5 m (agv1 at c:1.5)" in out  # the route's moves
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
