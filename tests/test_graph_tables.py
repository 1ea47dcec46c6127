"""PLC tables and ``trajgen check`` on track graphs: written, read back as interpolated, faults found."""

from __future__ import annotations

import dataclasses
import json
import tempfile

import numpy as np
import pytest

from tests.conftest import REPO
from tests.support.graph_cases import CONVOY, TINY_BACK_OFF, random_routes, verified_example
from trajgen import certify
from trajgen.cli import main
from trajgen.errors import OptionError, VerificationError
from trajgen.export.plc.check import check_profiles
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.export.plc.files import plc_tables
from trajgen.export.plc.table_check import check_tables, graph_travel, turning_points
from trajgen.export.plc.tables import Interpolation, ProfileTable
from trajgen.methods import make_schedule
from trajgen.model.profiles import PiecewiseCubic
from trajgen.scenario import load_scenario

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]
TABLE_DIALECTS = [dialect for dialect in DIALECTS if isinstance(dialect, TableDialect)]


_verified = verified_example


def _hurried(table: ProfileTable) -> ProfileTable:
    """The same table without the rest it starts with: the vehicle sets off at t = 0."""
    moving = int(np.nonzero(table.values != table.values[0])[0][0]) - 1
    return ProfileTable(
        table.times[moving:] - table.times[moving], table.values[moving:], table.interpolation
    )


def test_turning_points_and_travel_of_a_motion_that_goes_two_metres_and_back_one_and_a_half():
    # forward 2 m in 2 s, back 1.5 m in 1.5 s (velocity steps: a linear table)
    table = ProfileTable([0.0, 2.0, 3.5], [0.0, 2.0, 0.5], Interpolation.LINEAR)
    times, axis = turning_points(table.motion(), 1e-9)
    assert times.tolist() == [2.0]
    assert axis.tolist() == [2.0]
    travel, turns = graph_travel(table.motion(), 1e-9)
    assert turns.tolist() == [2.0]
    assert travel.evaluate(np.array([1.0, 2.0, 3.0, 3.5]))[0].tolist() == pytest.approx([1.0, 2.0, 3.0, 3.5])
    assert np.all(travel.evaluate(np.linspace(0.0, 3.5, 50))[1] >= 0.0)


def test_a_wiggle_within_the_tolerance_is_no_turn_and_one_beyond_it_is():
    motion = PiecewiseCubic(
        np.array([0.0, 1.0, 2.0]), np.array([[0.0, 1.0, 0.0], [1.0, -1e-7, 0.0]]), np.zeros(2)
    )
    assert turning_points(motion, 1e-6)[0].size == 0
    assert turning_points(motion, 1e-8)[0].tolist() == [1.0]


def test_near_where_the_path_turns_a_fine_back_off_is_a_turn_and_elsewhere_it_is_no_turn():
    """A 5 nm return at 1 m: a turn where the path turns there (fine 1 nm), none elsewhere (1 µm).

    An interpolation's overshoot at a stop between two rows is such a return, where the path
    stops but does not turn; a path's own back-off of nanometres is one where it turns.
    """
    motion = PiecewiseCubic(
        np.array([0.0, 1.0, 2.0]), np.array([[0.0, 1.0, 0.0], [1.0, -5e-9, 0.0]]), np.zeros(2)
    )
    assert turning_points(motion, 1e-6, expected=np.array([1.0]), fine=1e-9)[0].tolist() == [1.0]
    assert turning_points(motion, 1e-6, expected=np.array([1.0 + 2e-6]), fine=1e-9)[0].size == 0
    assert turning_points(motion, 1e-6, expected=np.empty(0), fine=1e-9)[0].size == 0
    assert turning_points(motion, 1e-6)[0].size == 0


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", FEASIBLE)
def test_every_table_dialect_on_every_example_graph_is_verified_as_its_controller_interpolates(name, method):
    scenario, verified = _verified(name, method)
    for dialect in TABLE_DIALECTS:
        if dialect.interpolation is Interpolation.CUBIC and not verified.schedule.jerk_limited:
            with pytest.raises(OptionError, match="interpolates a cubic spline: it needs a jerk-limited"):
                plc_tables(verified, dialect)
            continue
        tables = plc_tables(verified, dialect)
        assert tables.check.passed, (dialect.name, tables.check.failures)
        assert tables.check.report.min_separation >= scenario.limits.min_separation - 1e-9
        assert all(table.times.size <= dialect.point_limit for table in tables.resampled.tables)
        # the tables run the schedule: as long, or slowed down uniformly, never faster
        assert max(t.duration for t in tables.resampled.tables) >= verified.schedule.duration - 1e-6
        # and they are read along the route's paths: each turn back where its path turns back
        paths = tables.check.schedule.paths
        for vehicle, table in enumerate(tables.resampled.tables):
            turns = graph_travel(table.motion(), 1e-6)[1]
            assert turns == pytest.approx(paths[vehicle].cusps, abs=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("name", FEASIBLE)
def test_every_table_dialect_of_the_optimal_schedule_on_every_example_graph_is_verified(name):
    scenario, verified = _verified(name, "optimal")
    assert verified.schedule.jerk_limited
    for dialect in TABLE_DIALECTS:
        tables = plc_tables(verified, dialect)
        assert tables.check.passed, (dialect.name, tables.check.failures)
        assert tables.check.report.min_separation >= scenario.limits.min_separation - 1e-9


def test_a_table_that_sets_off_before_its_turn_is_found_to_break_the_separation():
    scenario, verified = _verified("h", "exact")
    first, second = plc_tables(verified, "siemens-xy").resampled.tables
    assert check_tables((first, second), verified.schedule.route, scenario.limits).passed
    assert second.values[1] == second.values[0]  # agv2 waits for agv1's first move
    early = check_tables((first, _hurried(second)), verified.schedule.route, scenario.limits)
    assert not early.passed
    assert any("below the minimum 1.5 m" in f or "pass each other" in f for f in early.failures), (
        early.failures
    )


def test_a_table_that_turns_back_where_its_path_does_not_or_misses_a_turn_is_refused():
    scenario, verified = _verified("h", "exact")
    first, second = plc_tables(verified, "siemens-xy").resampled.tables
    route = verified.schedule.route
    assert verified.schedule.paths[0].cusps.size == 1  # agv1 goes up c and comes back
    # agv1 driven on instead of back: its axis keeps growing after the turn
    cusp = int(np.argmax(first.values))
    onward = first.values.copy()
    onward[cusp:] = 2.0 * first.values[cusp] - first.values[cusp:]
    missed = check_tables((dataclasses.replace(first, values=onward), second), route, scenario.limits)
    assert not missed.passed
    assert any(
        f.startswith("vehicle 1's table turns back 0 time(s) (at nowhere m of travel): expected 1")
        for f in missed.failures
    ), missed.failures
    # agv2 (no turn on its path) made to back up half a metre midway and go on
    k = second.times.size // 2
    times = np.concatenate([second.times[: k + 1], second.times[k] + [1.0, 2.0], second.times[k + 1 :] + 2.0])
    values = np.concatenate([second.values[: k + 1], second.values[k] - [0.5, 0.0], second.values[k + 1 :]])
    backed = ProfileTable(times, values, Interpolation.LINEAR)
    extra = check_tables((first, backed), route, scenario.limits, jerk=False)
    assert any(f.startswith("vehicle 2's table turns back 2 time(s)") for f in extra.failures), extra.failures


def test_check_reads_a_graphs_generic_csv_and_its_tables_from_the_command_line(tmp_path, capsys):
    scenario_file = str(EXAMPLES / "h.toml")
    assert main(["schedule", scenario_file, "--csv", str(tmp_path / "generic")]) == 0
    assert main(["schedule", scenario_file, "--csv", str(tmp_path / "cam"), "--dialect", "twincat-cam"]) == 0
    capsys.readouterr()
    assert main(["check", scenario_file, "--csv", str(tmp_path / "generic")]) == 0
    out = capsys.readouterr().out
    assert "class: planned (agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D)" in out
    assert "PASS" in out
    assert (
        main(["check", scenario_file, "--csv", str(tmp_path / "cam"), "--dialect", "twincat-cam", "--json"])
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert summary["passed"]
    assert summary["class"] == "agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D"
    assert "homotopy" not in summary


def test_a_graph_csv_whose_edge_or_s_column_lies_is_found(tmp_path):
    scenario = load_scenario(EXAMPLES / "h.toml")
    assert main(["schedule", str(EXAMPLES / "h.toml"), "--csv", str(tmp_path)]) == 0
    path = tmp_path / "agv2.csv"
    original = path.read_bytes()
    rows = original.split(b"\r\n")
    fields = rows[40].split(b";")
    fields[5] = b"zz"
    rows[40] = b";".join(fields)
    path.write_bytes(b"\r\n".join(rows))
    verdict = check_profiles(scenario, tmp_path)
    assert not verdict.passed
    assert any("edge 'zz' is not on the track" in f for f in verdict.failures), verdict.failures
    rows = original.split(b"\r\n")
    fields = rows[40].split(b";")
    fields[6] = f"{float(fields[6]) - 0.25:.9f}".encode()
    rows[40] = b";".join(fields)
    path.write_bytes(b"\r\n".join(rows))
    verdict = check_profiles(scenario, tmp_path)
    assert any("but its axis puts it on edge" in f for f in verdict.failures), verdict.failures


def test_a_junctions_csv_checked_against_a_graph_says_it_is_not_for_that_track(tmp_path):
    assert main(["schedule", str(REPO / "trajgen" / "data" / "swap.toml"), "--csv", str(tmp_path)]) == 0
    verdict = check_profiles(load_scenario(EXAMPLES / "h.toml"), tmp_path)
    assert not verdict.passed
    assert any("is not for this scenario's track: expected a track graph's" in f for f in verdict.failures)


def test_a_table_set_that_fails_as_interpolated_is_never_returned(monkeypatch):
    _, verified = _verified("h", "exact")
    import trajgen.export.plc.files as files

    real = files.check_tables

    def early(tables, route, limits, *, jerk=True):
        return real((tables[0], _hurried(tables[1])), route, limits, jerk=jerk)

    monkeypatch.setattr(files, "check_tables", early)
    with pytest.raises(
        VerificationError, match=r"the siemens-xy tables .* fail as their controllers interpolate"
    ):
        plc_tables(verified, "siemens-xy")


@pytest.mark.slow
def test_every_table_dialect_on_seeded_random_graphs_is_verified_as_interpolated():
    """10 random trees and graphs with loops (no node coordinates), exact and toppra."""
    for seed, route, limits in random_routes(10, 3000):
        for method in ("exact", "toppra"):
            verified = certify(make_schedule(route, limits, method=method))
            for dialect in TABLE_DIALECTS:
                if dialect.interpolation is Interpolation.CUBIC and not verified.schedule.jerk_limited:
                    continue
                tables = plc_tables(verified, dialect)
                assert tables.check.passed, (seed, method, dialect.name)
                for vehicle, table in enumerate(tables.resampled.tables):
                    turns = graph_travel(table.motion(), 1e-6)[1]
                    assert turns == pytest.approx(verified.schedule.paths[vehicle].cusps, abs=1e-6)


@pytest.mark.parametrize("dialect", [d.name.value for d in DIALECTS])
def test_a_vehicle_that_backs_off_a_micrometre_and_returns_is_written_and_checked(dialect, tmp_path):
    """agv2 starts 1 µm inside the separation from J1: it backs off 1 µm for agv1 and comes back."""
    scenario_file = tmp_path / "tiny.toml"
    scenario_file.write_text(TINY_BACK_OFF)
    scenario = load_scenario(scenario_file)
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    assert verified.schedule.paths[1].length == pytest.approx(2e-6)
    assert verified.schedule.paths[1].cusps.size == 1
    out = tmp_path / "files"
    assert main(["schedule", str(scenario_file), "--csv", str(out), "--dialect", dialect]) == 0
    verdict = check_profiles(scenario, out, dialect=dialect)
    assert verdict.passed, verdict.failures


@pytest.mark.parametrize("goal", ["home", "a:3"])
@pytest.mark.parametrize(
    "back_off", ["1.4999999985", "1.499999998", "1.4999999975"], ids=["1.5nm", "2nm", "2.5nm"]
)
@pytest.mark.parametrize("dialect", [d.name.value for d in DIALECTS])
def test_a_back_off_of_nanometres_is_written_and_passes_check_or_is_refused_unwritten(
    dialect, back_off, goal, tmp_path
):
    """agv2 starts 1.5 to 2.5 nm inside the separation from J1: a turn of a few units of the last decimal.

    It backs off for agv1 and comes back, to stay (home) or to drive on to A the other way. The
    generic CSV, written to the nanometre, must show the turn and pass (at 2.5 nm its interpolated
    overshoot at agv2's later stop is no turn); a dialect whose table cannot hold it as
    interpolated is refused with nothing written, never written failing.
    """
    text = TINY_BACK_OFF.replace("b:1.499999", f"b:{back_off}")
    if goal != "home":
        text = text.replace(f'goal = "b:{back_off}"', f'goal = "{goal}"')
    scenario_file = tmp_path / "tiny.toml"
    scenario_file.write_text(text)
    scenario = load_scenario(scenario_file)
    out = tmp_path / "files"
    code = main(["schedule", str(scenario_file), "--csv", str(out), "--dialect", dialect])
    if code == 0:
        verdict = check_profiles(scenario, out, dialect=dialect)
        assert verdict.passed, verdict.failures
    else:
        assert dialect != "generic"
        assert not out.exists() or not any(out.iterdir())


def _creeping_files(tmp_path, scenario_text: str, creeper: str, *, creep: float, s_follows: bool):
    """Trajgen's generic CSVs of a scenario, ``creeper``'s file then creeping ``creep`` metres on.

    Its axis grows by ``creep`` over 200 more rows (2 s, a smooth step: far within every limit);
    its s and x columns follow or stay. The other file holds its last row as long.
    """
    tmp_path.mkdir(parents=True, exist_ok=True)
    scenario_file = tmp_path / "scenario.toml"
    scenario_file.write_text(scenario_text)
    scenario = load_scenario(scenario_file)
    out = tmp_path / "files"
    assert main(["schedule", str(scenario_file), "--csv", str(out)]) == 0
    lines = (out / f"{creeper}.csv").read_text().splitlines()
    t, axis, *rest = lines[-1].split(";")
    step = 0.01
    extra = []
    for k in range(1, 201):
        u = k / 200.0
        moved = creep * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
        follow = moved if s_follows else 0.0
        row = [f"{float(t) + k * step:.6f}", f"{float(axis) + moved:.9f}", *rest[:4]]
        row.append(f"{float(rest[4]) + follow:.9f}")
        if len(rest) > 5:
            row += [f"{float(rest[5]) + follow:.9f}", rest[6]]
        extra.append(";".join(row))
    (out / f"{creeper}.csv").write_text("\r\n".join(lines + extra) + "\r\n")
    other = next(name for name in scenario.names if name != creeper)
    second = (out / f"{other}.csv").read_text().splitlines()
    t2 = float(second[-1].split(";")[0])
    pad = [";".join([f"{t2 + k * step:.6f}", *second[-1].split(";")[1:]]) for k in range(1, 201)]
    (out / f"{other}.csv").write_text("\r\n".join(second + pad) + "\r\n")
    return scenario, out


@pytest.mark.parametrize("honest", [True, False], ids=["s-column-follows", "s-column-lies"])
def test_a_generic_csv_whose_last_rows_creep_nine_micrometres_too_close_is_refused(honest, tmp_path):
    """agv1 parks exactly the separation behind agv2; its file then creeps 9 µm further, row by row."""
    scenario, out = _creeping_files(tmp_path, CONVOY, "agv1", creep=9e-6, s_follows=honest)
    verdict = check_profiles(scenario, out)
    assert not verdict.passed
    assert any("below the minimum 1.5 m" in f for f in verdict.failures), verdict.failures
    lies = [f for f in verdict.failures if "but its axis puts it on edge 'e'" in f]
    assert bool(lies) != honest, verdict.failures


def test_a_generic_csv_that_creeps_past_a_goal_at_a_track_node_is_refused(tmp_path):
    """agv1 parks at node J, exactly the separation behind agv2; its axis then creeps 9 µm past J.

    Past J the track does not say which edge it is on (its s column stays at J): the 9 µm are
    taken off the separation, not clipped away.
    """
    at_node = CONVOY.replace('goal = "e:5.5"', 'goal = "J"').replace('goal = "e:7"', 'goal = "e:1.5"')
    scenario, out = _creeping_files(tmp_path, at_node, "agv1", creep=9e-6, s_follows=False)
    verdict = check_profiles(scenario, out)
    assert not verdict.passed
    assert any("below the minimum 1.5 m" in f and "9 µm of it off its path" in f for f in verdict.failures), (
        verdict.failures
    )
    # the same files without the creep pass: the refusal is the creep's
    scenario, out = _creeping_files(tmp_path / "still", at_node, "agv1", creep=0.0, s_follows=False)
    assert check_profiles(scenario, out).passed


def test_a_vehicle_that_should_stand_still_and_creeps_nine_micrometres_is_refused(tmp_path):
    """agv2 stays at e:7 and agv1 parks exactly the separation from it; agv2's axis creeps 9 µm."""
    standing = CONVOY.replace('start = "w:5"', 'start = "e:7"')
    scenario, out = _creeping_files(tmp_path, standing, "agv2", creep=9e-6, s_follows=False)
    verdict = check_profiles(scenario, out)
    assert not verdict.passed
    assert any("below the minimum 1.5 m" in f for f in verdict.failures), verdict.failures
    scenario, out = _creeping_files(tmp_path / "still", standing, "agv2", creep=0.0, s_follows=False)
    assert check_profiles(scenario, out).passed


def test_a_coarse_file_buys_no_closer_approach_than_a_nanometre_one(tmp_path):
    """The tables of a 4 µm creep, read as if written to 5 decimals (round-off 5 µm), still fail."""
    scenario, out = _creeping_files(tmp_path, CONVOY, "agv1", creep=4e-6, s_follows=True)
    tables = tuple(
        DIALECTS.lookup("generic").read((out / f"{name}.csv").read_bytes(), source=name).table
        for name in scenario.names
    )
    coarse = tuple(dataclasses.replace(table, resolution=5e-6) for table in tables)
    for given in (tables, coarse):
        verdict = check_tables(given, scenario.route(), scenario.limits)
        assert not verdict.passed
        assert any("below the minimum 1.5 m" in f for f in verdict.failures), verdict.failures


@pytest.mark.slow
def test_the_generic_csv_of_seeded_random_graphs_passes_check():
    """20 random trees and graphs with loops, exact and toppra: trajgen's own files pass its check."""
    from trajgen.export.csv import write_profiles
    from trajgen.scenario import GraphScenario

    for seed, route, limits in random_routes(20, 3000):
        scenario = GraphScenario(route.track, limits, ("agv1", "agv2"), route.start, route.goal)
        for method in ("exact", "toppra"):
            verified = certify(make_schedule(route, limits, method=method))
            with tempfile.TemporaryDirectory() as directory:
                write_profiles(verified, scenario.names, directory)
                verdict = check_profiles(scenario, directory, jerk=verified.schedule.jerk_limited)
            assert verdict.passed, (seed, method, verdict.failures)
