"""PLC dialects: resampled tables, their files, and ``trajgen check`` on them and on edited files.

On the demo swap, and on the built-in 4-way crossing (its legs numbered 1 to 4); then on the
example track graphs (every table dialect of every method, read back along the route).
"""

from __future__ import annotations

import dataclasses
import json
import re
import tempfile

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.conftest import REPO
from tests.support.fleets import FLEETS, SEPARATION, fleet
from tests.support.graph_cases import CONVOY, TINY_BACK_OFF, random_routes, verified_example
from tests.support.helpers import LIMITS, MIXED, route_of
from tests.support.star_scenarios import CROSSING
from trajgen import Exact, Optimal, Toppra, certify, default_scenario, load_scenario, make_schedule, run
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main
from trajgen.errors import InputError, OptionError, OutputLimitError, ProfileFileError, VerificationError
from trajgen.export import CsvOptions, write_profiles
from trajgen.export.plc import plc_tables
from trajgen.export.plc.check import check_profiles
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.export.plc.resample import resample
from trajgen.export.plc.table_check import check_tables, graph_travel, turning_points
from trajgen.export.plc.tables import Interpolation, ProfileTable, divided_differences
from trajgen.model.junction_route import junction_graph_route
from trajgen.model.profiles import PiecewiseCubic
from trajgen.pipeline import Outputs

SWAP = str(REPO / "examples" / "swap.toml")
TABLE_DIALECTS = [d for d in DIALECTS if isinstance(d, TableDialect)]
ALL = [d.name.value for d in DIALECTS]


@pytest.fixture(scope="module")
def swap():
    """The demo swap, scheduled by optimal (the default), verified."""
    return run(default_scenario()).verified


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Every dialect's files of the demo swap, written by ``trajgen schedule --dialect``."""
    root = tmp_path_factory.mktemp("dialects")
    for name in ALL:
        assert main(["schedule", SWAP, "--csv", str(root / name), "--dialect", name]) == EXIT_OK
    return root


def _files(folder, dialect):
    suffix = ".csv" if dialect.point_limit is None else dialect.suffix
    return [folder / f"agv1{suffix}", folder / f"agv2{suffix}"]


def _copy(exported, dialect, target):
    """The demo swap's files of ``dialect`` copied into ``target`` (to edit them there)."""
    target.mkdir(parents=True, exist_ok=True)
    for source in _files(exported / dialect.name.value, dialect):
        (target / source.name).write_bytes(source.read_bytes())


@pytest.mark.parametrize("name", ALL, ids=ALL)
def test_every_dialects_output_passes_the_checker(exported, name, capsys):
    assert main(["check", SWAP, "--csv", str(exported / name), "--dialect", name, "--json"]) == EXIT_OK
    verdict = json.loads(capsys.readouterr().out)
    assert verdict["passed"]
    assert verdict["failures"] == []
    assert verdict["min_separation_m"] >= 1.5 - 1e-9


@pytest.mark.parametrize("dialect", TABLE_DIALECTS, ids=[d.name.value for d in TABLE_DIALECTS])
def test_table_files_have_the_dialects_format(exported, dialect, swap):
    for vehicle, path in enumerate(_files(exported / dialect.name.value, dialect)):
        data = path.read_bytes()
        text = data.decode("ascii")
        assert text.endswith("\r\n")
        assert text.count("\r\n") == text.count("\n")
        lines = text.split("\r\n")[:-1]
        if dialect.header is not None:
            assert lines.pop(0) == dialect.header
        rows = [line.split(dialect.delimiter) for line in lines]
        assert {len(row) for row in rows} == {2 if dialect.extra is None else 3}
        master = np.array([float(row[0]) for row in rows])
        slave = np.array([float(row[1]) for row in rows])
        assert np.all(np.diff(master) > 0.0)  # master values strictly increase
        assert 2 <= len(rows) <= dialect.point_limit
        assert master[0] == 0.0
        assert master[-1] == pytest.approx(swap.schedule.duration, rel=1e-3)  # slowed by < 0.1 %
        if dialect.interpolation is Interpolation.VELOCITY:
            assert slave[0] == slave[-1] == 0.0  # from rest to rest, mm/s
        else:
            goal = swap.schedule.state(swap.schedule.duration).axis[vehicle, 0]
            assert slave[0] == 0.0
            assert slave[-1] == pytest.approx(1000.0 * goal, abs=1e-6)  # millimetres


@pytest.mark.parametrize("name", ALL, ids=ALL)
def test_a_row_moved_by_a_centimetre_fails_the_check(exported, name, tmp_path, capsys):
    dialect = DIALECTS.lookup(name)
    edited = tmp_path / name
    _copy(exported, dialect, edited)
    path = _files(edited, dialect)[0]
    lines = path.read_bytes().decode("ascii").split("\r\n")
    row = len(lines) // 3
    separator = "\t" if "\t" in lines[row] else (";" if ";" in lines[row] else ",")
    fields = lines[row].split(separator)
    scale = 1.0 if name == "generic" else 1000.0  # generic: metres; the tables: millimetres (mm/s)
    fields[1] = f"{float(fields[1]) + 0.01 * scale:.9f}"
    lines[row] = separator.join(fields)
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    assert main(["check", SWAP, "--csv", str(edited), "--dialect", name]) == EXIT_FAILURE
    out = capsys.readouterr().out
    assert "FAIL" in out
    assert "violation: vehicle 1" in out or "violation: goal" in out or "violation: separation" in out


def test_a_violation_names_the_time_the_quantity_the_value_and_the_limit(exported, tmp_path, capsys):
    dialect = DIALECTS.lookup("siemens-xy")
    edited = tmp_path / "siemens"
    _copy(exported, dialect, edited)
    path = edited / "agv2.csv"
    lines = path.read_bytes().decode("ascii").split("\r\n")
    t, x = lines[400].split(";")
    lines[400] = f"{t};{float(x) + 10.0:.9f}"
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    verdict = check_profiles(default_scenario(), edited, dialect="siemens-xy")
    assert not verdict.passed
    assert any(
        f.startswith("vehicle 2 velocity reaches") and "at t=" in f and "max_velocity 1 m/s" in f
        for f in verdict.failures
    )
    assert any(
        "vehicle 2 acceleration reaches" in f and "max_acceleration 0.5" in f for f in verdict.failures
    )


@pytest.mark.parametrize(
    ("name", "mangle", "match"),
    [
        ("twincat-cam", lambda t: t.replace(";", ","), r"1 field\(s\) separated by ';', expected 2"),
        ("codesys-xy", lambda t: t.replace("\t", ";"), r"separated by '\\t', expected 2"),
        ("logix-time-cam", lambda t: t.replace("Master,Slave,SegmentType\r\n", ""), r"header .* is not"),
        ("logix-time-cam", lambda t: t.replace(",1\r\n", ",0\r\n", 3), r"segment types \['0', '1'\]"),
        ("siemens-xy", lambda t: t.replace("0.000000000;", "zero;", 1), r"'zero' is not a number"),
        ("velocity-profile", lambda t: t.replace("0.000000000;", "0.5;", 1), r"first master value is 0.5 s"),
        ("generic", lambda t: "x;y\r\n" + t, r"header 'x;y' is not trajgen's"),
        ("twincat-cam", lambda t: t.replace("0.000000000;0.000000000", "nan;0", 1), r"'nan' is not a finite"),
        ("twincat-cam", lambda t: "", r"is empty"),
    ],
    ids=[
        "delimiter",
        "codesys-delimiter",
        "no-header",
        "mixed-segments",
        "text",
        "start",
        "generic-header",
        "nan",
        "empty",
    ],
)
def test_a_file_that_cannot_be_read_exits_2(exported, tmp_path, capsys, name, mangle, match):
    dialect = DIALECTS.lookup(name)
    broken = tmp_path / name
    _copy(exported, dialect, broken)
    path = _files(broken, dialect)[0]
    path.write_bytes(mangle(path.read_bytes().decode("ascii")).encode("ascii"))
    with pytest.raises(ProfileFileError, match=match):
        check_profiles(default_scenario(), broken, dialect=name)
    assert main(["check", SWAP, "--csv", str(broken), "--dialect", name]) == EXIT_BAD_INPUT
    assert "trajgen: error:" in capsys.readouterr().err


def test_missing_files_and_line_ends(exported, tmp_path, capsys):
    assert main(["check", SWAP, "--csv", str(tmp_path), "--dialect", "twincat-cam"]) == EXIT_BAD_INPUT
    assert "agv1.csv: cannot read the profile file: No such file" in capsys.readouterr().err
    lf = tmp_path / "lf"
    lf.mkdir()
    for source in _files(exported / "twincat-cam", DIALECTS.lookup("twincat-cam")):
        (lf / source.name).write_bytes(source.read_bytes().replace(b"\r\n", b"\n"))
    verdict = check_profiles(default_scenario(), lf, dialect="twincat-cam")
    assert not verdict.passed
    assert verdict.check.passed
    assert any("ends with LF only, expected CRLF" in problem for problem in verdict.problems)


def test_the_summary_reports_points_and_errors(tmp_path, capsys):
    out = tmp_path / "plc"
    assert main(["schedule", SWAP, "--csv", str(out), "--dialect", "velocity-profile", "--json"]) == EXIT_OK
    export = json.loads(capsys.readouterr().out)["export"]
    assert export["dialect"] == "velocity-profile"
    assert export["point_limit"] == 100
    assert max(export["points"]) <= 100
    assert 0.0 < max(export["position_error_m"]) < 0.005
    assert 0.0 < max(export["velocity_error_mps"]) < 0.01
    assert export["verified"]
    assert export["time_scale"] >= 1.0
    assert main(["schedule", SWAP, "--csv", str(out), "--dialect", "siemens-xy"]) == EXIT_OK
    assert (
        "siemens-xy tables: 1000 and 1000 points (limit 1,000, linear), worst error"
        in capsys.readouterr().out
    )


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (
            ["--dialect", "siemens-xy", "--max-points", "20000"],
            r"max points 20,000 is more than dialect 'siemens-xy'",
        ),
        (["--dialect", "fanuc"], r"dialect 'fanuc' is unknown"),
        (["--dialect", "twincat-cam", "--max-points", "1"], r"max points must be an integer >= 2, got 1"),
        (["--max-points", "50"], r"max points 50 applies to table dialects"),
        (["--dialect", "logix-time-cam", "--method", "toppra"], r"needs a jerk-limited schedule"),
        (
            ["--dialect", "twincat-cam", "--units", "m"],
            r"--units applies to the generic CSV only: dialect 'twincat-cam'",
        ),
        (["--dialect", "siemens-xy", "--delimiter", ","], r"--delimiter applies to the generic CSV only"),
        (
            ["--dialect", "siemens-xy", "--delimiter", ",", "--units", "mm"],
            r"--delimiter, --units apply to the generic CSV only",
        ),
    ],
    ids=[
        "siemens-limit",
        "unknown",
        "one-point",
        "generic-points",
        "cubic-toppra",
        "units",
        "delimiter",
        "two-options",
    ],
)
def test_bad_dialect_options_exit_2_and_write_nothing(tmp_path, capsys, args, match):
    out = tmp_path / "out"
    assert main(["schedule", SWAP, "--csv", str(out), *args]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert re.search(match, err), err
    assert not out.exists()


def test_too_few_points_for_the_starts_and_stops_are_refused(swap):
    with pytest.raises(OutputLimitError, match=r"needs at least 3 points .* expected at most max_points 2"):
        plc_tables(swap, "twincat-cam", max_points=2)


def test_tables_that_fail_as_interpolated_are_never_written(tmp_path, monkeypatch):
    from trajgen.export.plc import files as plc

    def too_far(tables, route, limits, *, jerk):  # the tables read back, judged with 12 m separation
        return check_tables(tables, route, type(limits)(limits.vehicles, min_separation=12.0), jerk=jerk)

    monkeypatch.setattr(plc, "check_tables", too_far)
    out = tmp_path / "out"
    with pytest.raises(
        VerificationError, match=r"twincat-cam tables .* fail as their controllers interpolate"
    ):
        run(
            default_scenario(),
            method=Exact(),
            outputs=Outputs(csv_dir=out, plot_dir=out, dialect="twincat-cam"),
        )
    assert not out.exists()


def test_placed_points_beat_evenly_spaced_points(swap):
    resampled = resample(swap, interpolation="linear", max_points=300)
    schedule = swap.schedule
    grid = np.linspace(0.0, schedule.duration, 20_001)
    truth = schedule.state(grid).axis
    for vehicle, table in enumerate(resampled.tables):
        assert table.times.size <= 300
        even_times = np.linspace(0.0, schedule.duration, table.times.size)
        even = ProfileTable(even_times, schedule.state(even_times).axis[vehicle], "linear")
        even_error = np.abs(even.motion().evaluate(grid)[0] - truth[vehicle]).max()
        assert resampled.position_error[vehicle] < 0.7 * even_error


def test_a_spline_with_knots_at_every_jerk_switch_is_the_schedule(swap):
    resampled = resample(swap, interpolation="cubic", max_points=1000)
    assert resampled.time_scale == pytest.approx(1.0, abs=2e-6)
    assert max(resampled.position_error) < 1e-9
    assert max(resampled.velocity_error) < 1e-7


@pytest.mark.parametrize(
    ("method", "limits"),
    [(Exact(), LIMITS), (Toppra(), LIMITS), (Optimal(), MIXED)],
    ids=["exact", "toppra", "optimal-mixed"],
)
@pytest.mark.parametrize("interpolation", ["linear", "linear-velocity"], ids=["linear", "velocity"])
def test_resampled_tables_verify_and_agree_with_the_schedule(method, limits, interpolation):
    route = route_of((12.0, 8.0, 15.0), ("A:12", "B:8"), ("B:8", "A:12"))
    verified = certify(make_schedule(route, limits, method=method))
    resampled = resample(verified, interpolation=interpolation, max_points=400)
    schedule = verified.schedule
    verdict = check_tables(resampled.tables, schedule.route, limits, jerk=schedule.jerk_limited)
    assert verdict.passed, verdict.failures
    assert resampled.time_scale < 1.01
    assert max(resampled.position_error) < 0.01
    for vehicle, table in enumerate(resampled.tables):  # start and goal exact
        positions = table.positions()
        end = schedule.state(schedule.duration).axis[vehicle, 0]
        assert positions[0] == pytest.approx(0.0, abs=1e-12)
        assert positions[-1] == pytest.approx(end, abs=1e-9)


@given(
    coefficients=st.lists(st.floats(-5, 5), min_size=4, max_size=4),
    gaps=st.lists(st.floats(0.01, 2.0), min_size=3, max_size=3),
)
def test_divided_differences_of_a_cubic_are_its_derivatives(coefficients, gaps):
    times = np.concatenate([[0.0], np.cumsum(gaps)])
    values = np.polyval(coefficients[::-1], times)
    third, weight = divided_differences(times, values, 3)
    assert third[0] == pytest.approx(6.0 * coefficients[3], abs=1e-6 * (1 + weight[0]))
    second, _ = divided_differences(times, values, 2)
    # 2 f[t0, t1, t2] is f'' somewhere in [t0, t2]: between f''(t0) and f''(t2) for a cubic
    f2 = 2.0 * coefficients[2] + 6.0 * coefficients[3] * times
    assert min(f2[0], f2[2]) - 1e-6 <= second[0] <= max(f2[0], f2[2]) + 1e-6


def test_tables_along_the_wrong_class_fail(swap):
    from topology import Homotopy, plan

    scenario = default_scenario()
    other = Homotopy.OTHER if swap.schedule.route.homotopy is Homotopy.PLANNED else Homotopy.PLANNED
    wrong = plan(scenario.track, scenario.start, scenario.goal, min_separation=1.5, homotopy=other)
    resampled = resample(swap, interpolation="linear", max_points=2000)
    assert check_tables(resampled.tables, swap.schedule.route, scenario.limits).passed
    verdict = check_tables(resampled.tables, wrong, scenario.limits)
    assert not verdict.passed


def test_option_errors():
    with pytest.raises(OptionError, match=r"dialect 'nope' is unknown"):
        DIALECTS.lookup("nope")


def _write(folder, dialect, tables):
    """Write two tables' files of ``dialect`` (ProfileTables in metres) into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, table in zip(("agv1", "agv2"), tables, strict=True):
        (folder / f"{name}{dialect.suffix}").write_bytes(dialect.render(table))


def test_a_sparse_linear_table_with_velocity_steps_fails(tmp_path, swap):
    # 0 -> 1 m/s -> 0 at once: three points whose divided differences look harmless
    twincat = DIALECTS.lookup("twincat-cam")
    jumpy = ProfileTable([0.0, 10.0, 30.0], [0.0, 0.0, 20.0], "linear")
    other = resample(swap, interpolation="linear", max_points=10_000).tables[1]
    _write(tmp_path, twincat, (jumpy, other))
    verdict = check_profiles(default_scenario(), tmp_path, dialect=twincat)
    assert any(
        "vehicle 1 velocity steps by 1 m/s at t=10.000000 s" in f and "would leave the table by 250 mm" in f
        for f in verdict.failures
    )


def test_too_few_points_to_follow_are_refused_not_written(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["schedule", SWAP, "--csv", str(out), "--dialect", "twincat-cam", "--max-points", "12"]
    assert main(args) == EXIT_FAILURE
    assert "velocity steps by" in capsys.readouterr().err
    assert not out.exists()


def test_a_value_written_without_decimals_does_not_widen_the_allowance(exported, tmp_path):
    dialect = DIALECTS.lookup("twincat-cam")
    _copy(exported, dialect, tmp_path)
    path = tmp_path / "agv1.csv"
    lines = path.read_bytes().decode("ascii").split("\r\n")
    lines[0] = "0;0"  # as a spreadsheet saves it
    t, x = lines[40].split(";")
    lines[40] = f"{t};{float(x) + 0.05:.9f}"  # 50 um: a small step, far beyond any limit over 3 ms
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    verdict = check_profiles(default_scenario(), tmp_path, dialect=dialect)
    assert any("vehicle 1 jerk reaches" in f for f in verdict.failures)


@pytest.mark.parametrize(
    ("column", "change", "match"),
    [
        (5, lambda v, row: "3" if v == "2" else v, r"says leg 3, .* but its axis puts it on leg 2"),
        (
            2,
            lambda v, row: (
                f"{float(v) + (0.3 if row % 2 else -0.3):.9f}" if 0.2 < abs(float(v)) < 0.65 else v
            ),
            r"velocity column .* disagrees with its positions",
        ),
        (7, lambda v, row: f"{float(v) + 1.0:.9f}", r"x, y do not lie at leg"),
        (3, lambda v, row: "9.0" if row == 50 else v, r"acceleration column reaches 9 m/s\^2 at"),
    ],
    ids=["leg", "velocity", "x", "acceleration"],
)
def test_every_column_of_a_generic_file_is_checked(exported, tmp_path, column, change, match):
    _copy(exported, DIALECTS.lookup("generic"), tmp_path)
    path = tmp_path / "agv1.csv"
    lines = path.read_bytes().decode("ascii").split("\r\n")
    for row in range(1, len(lines) - 1):
        fields = lines[row].split(";")
        fields[column] = change(fields[column], row)
        lines[row] = ";".join(fields)
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    verdict = check_profiles(default_scenario(), tmp_path)
    assert not verdict.passed
    assert any(re.search(match, f) for f in verdict.failures), verdict.failures


@pytest.mark.slow
def test_check_rejects_a_leg_the_crossing_lacks(tmp_path, capsys):
    out = tmp_path / "csv"
    assert main(["schedule", str(CROSSING), "--method", "exact", "--csv", str(out)]) == EXIT_OK
    capsys.readouterr()
    path = out / "agv1.csv"
    lines = path.read_bytes().decode("ascii").split("\r\n")
    fields = lines[1].split(";")
    assert fields[5] == "1"  # agv1 starts on N, the first leg
    fields[5] = "5"
    lines[1] = ";".join(fields)
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    assert main(["check", str(CROSSING), "--csv", str(out), "--json"]) == EXIT_FAILURE
    verdict = json.loads(capsys.readouterr().out)
    assert not verdict["passed"]
    assert any(
        "leg 5 is not on the track: expected 0 (the junction) or a leg 1 to 4 (1-based, 4 legs)" in f
        for f in verdict["failures"]
    ), verdict["failures"]


def test_a_table_whose_axis_runs_backwards_fails(exported, tmp_path):
    dialect = DIALECTS.lookup("siemens-xy")
    parsed = [
        dialect.read(p.read_bytes(), source=p.name).table for p in _files(exported / "siemens-xy", dialect)
    ]
    flipped = ProfileTable(parsed[0].times, -parsed[0].values, "linear")
    _write(tmp_path, dialect, (flipped, parsed[1]))
    verdict = check_profiles(default_scenario(), tmp_path, dialect=dialect)
    assert any("vehicle 1's axis first moves backwards" in f for f in verdict.failures)


STILL = """
[track]
legs = { A = 10.0, B = 10.0, C = 10.0 }
[safety]
min_separation = 1.5
[[vehicle]]
name = "agv1"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "A:10.0"
goal = "A:10.0"
[[vehicle]]
name = "agv2"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "B:10.0"
goal = "B:10.0"
"""


def test_the_checker_takes_scenarios_where_nothing_moves(tmp_path):
    scenario_path = tmp_path / "still.toml"
    scenario_path.write_text(STILL)
    out = tmp_path / "out"
    assert main(["schedule", str(scenario_path), "--csv", str(out), "--dialect", "siemens-xy"]) == EXIT_OK
    assert main(["check", str(scenario_path), "--csv", str(out), "--dialect", "siemens-xy"]) == EXIT_OK


def test_more_points_than_the_target_takes_fail_the_check(tmp_path, swap):
    dialect = DIALECTS.lookup("velocity-profile")
    _write(tmp_path, dialect, resample(swap, interpolation="linear-velocity", max_points=400).tables)
    verdict = check_profiles(default_scenario(), tmp_path, dialect=dialect)
    assert verdict.check.passed  # the motion is fine
    assert any("points, more than the target takes (100)" in p for p in verdict.problems)
    assert check_profiles(default_scenario(), tmp_path, dialect=dialect, max_points=400).passed


@pytest.mark.parametrize("method", ["toppra", "exact"], ids=["toppra", "exact"])
def test_the_generic_files_of_every_method_pass_the_checker(tmp_path, method):
    out = tmp_path / method
    assert main(["schedule", SWAP, "--csv", str(out), "--method", method]) == EXIT_OK
    jerk = [] if method == "exact" else ["--ignore-jerk"]
    assert main(["check", SWAP, "--csv", str(out), *jerk]) == EXIT_OK


@pytest.mark.parametrize("name", ["twincat-cam", "siemens-xy", "velocity-profile"])
def test_checking_a_dialects_file_without_the_flag_names_the_dialects_it_reads_as(exported, name, capsys):
    assert main(["check", SWAP, "--csv", str(exported / name)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "is not trajgen's" in err
    assert "pass --dialect" in err
    assert repr(name) in err  # the dialect that wrote it is among those named
    # and with the flag the same files pass
    assert main(["check", SWAP, "--csv", str(exported / name), "--dialect", name]) == EXIT_OK


@pytest.mark.parametrize("name", ["twincat-cam", "siemens-xy", "velocity-profile", "logix-time-cam"])
def test_a_generic_csv_checked_as_a_table_dialect_is_called_a_generic_csv(tmp_path, name, capsys):
    """It was "line 1: 9 field(s) separated by ';', expected 2" (issue 38, item 6)."""
    out = tmp_path / "generic"
    assert main(["schedule", SWAP, "--csv", str(out), "--method", "exact"]) == EXIT_OK
    capsys.readouterr()
    assert main(["check", SWAP, "--csv", str(out), "--dialect", name]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert (
        f"agv1.csv is a generic CSV (trajgen's own columns t_s, axis_m, v, a, j, ...), not a {name} table"
        in err
    )
    assert "check it with --dialect generic, the default" in err
    assert "field(s)" not in err


def test_a_generic_csv_cut_at_a_line_boundary_is_first_said_to_end_early(tmp_path, capsys):
    """It was reported as acceleration and jerk violations and a goal off by metres (issue 38, item 6)."""
    out = tmp_path / "cut"
    assert main(["schedule", SWAP, "--csv", str(out), "--method", "exact"]) == EXIT_OK
    capsys.readouterr()
    lines = (out / "agv1.csv").read_bytes().split(b"\r\n")[:-1]  # CRLF after every line
    rows = len(lines) - 1  # below the header
    kept = 2 * rows // 5  # mid-motion
    (out / "agv1.csv").write_bytes(b"".join(line + b"\r\n" for line in lines[: kept + 1]))
    assert main(["check", SWAP, "--csv", str(out)]) == EXIT_FAILURE
    printed = capsys.readouterr().out
    violations = [line for line in printed.splitlines() if line.startswith("violation: ")]
    assert "agv1.csv: the file ends early: its last row " in violations[0]
    assert f"(row {kept:,} of {rows:,} in the other vehicle's file, t = " in violations[0]
    assert "is not at rest (1 m/s), where a schedule ends at rest at its goal" in violations[0]
    assert "--ignore-jerk" not in printed  # the jerk at the cut is the cut's: no flag to offer


def test_a_generic_csv_cut_within_a_line_is_said_to_end_early(tmp_path, capsys):
    """It was "line 313: 8 field(s) separated by ';', expected 9" (the review of issue 38)."""
    out = tmp_path / "cut"
    assert main(["schedule", SWAP, "--csv", str(out), "--method", "exact"]) == EXIT_OK
    capsys.readouterr()
    data = (out / "agv1.csv").read_bytes()
    (out / "agv1.csv").write_bytes(data[: data.index(b";1;", 30_000)])  # within a row, before its leg
    assert main(["check", SWAP, "--csv", str(out)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "agv1.csv: the file ends early: its last line (line " in err
    assert ") is cut short, 5 of 9 fields and no line end" in err


def test_both_generic_csvs_cut_where_the_vehicles_rest_between_moves_are_said_to_end_early(tmp_path, capsys):
    """Cut at a row where both stand between two moves, the last row is at rest, short of the goal."""
    out = tmp_path / "cut"
    assert main(["schedule", SWAP, "--csv", str(out), "--method", "exact"]) == EXIT_OK
    capsys.readouterr()
    files = {name: (out / name).read_bytes().split(b"\r\n")[:-1] for name in ("agv1.csv", "agv2.csv")}
    fields = {name: [line.split(b";") for line in lines[1:]] for name, lines in files.items()}
    # the first row after the first move where both vehicles rest: the exact plan moves one at a time
    kept = next(
        k + 1
        for k in range(len(fields["agv1.csv"]) // 10, len(fields["agv1.csv"]))
        if all(float(fields[name][k][2]) == 0.0 == float(fields[name][k][3]) for name in files)
    )
    for name, lines in files.items():
        (out / name).write_bytes(b"".join(line + b"\r\n" for line in lines[: kept + 1]))
    assert main(["check", SWAP, "--csv", str(out)]) == EXIT_FAILURE
    violations = [line for line in capsys.readouterr().out.splitlines() if line.startswith("violation: ")]
    assert "agv1.csv: the file ends early: its last row (row " in violations[0]
    assert "is at rest after 0.000 m of the 20.000 m its route drives to its goal" in violations[0]


def test_a_file_no_dialect_reads_gets_the_generic_message_alone(tmp_path, capsys):
    folder = tmp_path / "junk"
    folder.mkdir()
    for vehicle in ("agv1", "agv2"):
        (folder / f"{vehicle}.csv").write_text("hello;world\nnot;numbers\n", encoding="utf-8")
    assert main(["check", SWAP, "--csv", str(folder)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "is not trajgen's" in err
    assert "pass --dialect" not in err


def test_write_tables_writes_a_dialects_files_verified_both_or_neither(swap, tmp_path):
    from trajgen.export import plc_tables, write_tables

    written = write_tables(swap, ("agv1", "agv2"), tmp_path / "out", dialect="siemens-xy")
    assert [p.name for p in written] == ["agv1.csv", "agv2.csv"]
    assert tuple(p.read_bytes() for p in written) == plc_tables(swap, "siemens-xy").contents
    assert main(["check", SWAP, "--csv", str(tmp_path / "out"), "--dialect", "siemens-xy"]) == EXIT_OK
    with pytest.raises(OptionError, match="dialect 'generic' is sampled, not resampled: write it with"):
        write_tables(swap, ("agv1", "agv2"), tmp_path / "generic", dialect="generic")
    assert not (tmp_path / "generic").exists()


@pytest.mark.parametrize(
    ("call", "remedy"),
    [
        pytest.param(
            lambda swap, folder: write_profiles(swap, ("a", "b"), folder, options=CsvOptions(max_rows=10)),
            "CsvOptions(max_rows=...) or --max-rows",
            id="rows",
        ),
        pytest.param(
            lambda swap, folder: plc_tables(swap, "siemens-xy", max_points=3),
            "max_points=... or --max-points",
            id="points",
        ),
    ],
)
def test_an_api_error_names_the_apis_remedy_and_the_flag(swap, tmp_path, call, remedy):
    with pytest.raises((InputError, VerificationError)) as raised:
        call(swap, tmp_path / "out")
    assert remedy in str(raised.value)
    assert not (tmp_path / "out").exists()


# -- the table dialects on a 4-way crossing ----------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("dialect", [d.name.value for d in TABLE_DIALECTS])
def test_table_dialects_on_a_crossing(tmp_path, capsys, dialect):
    out = tmp_path / dialect
    argv = ["schedule", str(CROSSING), "--method", "exact", "--csv", str(out), "--dialect", dialect, "--json"]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["export"]["dialect"] == dialect
    assert summary["export"]["min_separation_m"] >= 1.5 - 1e-9
    verdict = check_profiles(load_scenario(CROSSING), out, dialect=dialect)
    assert verdict.passed, verdict.failures
    assert verdict.check.route.graph.leg_count == 4


# -- track graphs: PLC tables and trajgen check ----------------------------------------------------------


EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


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
    "back_off",
    [
        pytest.param("1.4999999985", id="1.5nm", marks=pytest.mark.slow),
        pytest.param("1.499999998", id="2nm"),  # the fast set's: the boundary
        pytest.param("1.4999999975", id="2.5nm", marks=pytest.mark.slow),
    ],
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
    for read in (tables, coarse):
        verdict = check_tables(read, scenario.route(), scenario.limits)
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


# -- any number of vehicles below the planners ------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_every_table_dialect_of_a_fleet_is_verified_as_interpolated_one_table_per_vehicle(case, tmp_path):
    """Three or four vehicles: each dialect's tables, written and read back, keep every pair apart."""
    verified, route = case.verified("exact"), case.route()
    for dialect in TABLE_DIALECTS:
        tables = plc_tables(verified, dialect)
        assert len(tables.contents) == len(tables.resampled.tables) == case.count, dialect.name
        assert tables.check.passed, (dialect.name, tables.check.failures)
        assert tables.check.report.min_separation >= SEPARATION - 1e-9, dialect.name
        assert len(tables.check.ratios["velocity"]) == case.count
    paths = write_profiles(verified, route.names, tmp_path)
    generic = DIALECTS.lookup("generic")
    read = tuple(generic.read(path.read_bytes(), source=path.name).table for path in paths)
    check = check_tables(read, route, case.limits())
    assert check.passed, check.failures
    # the generic CSV of the toppra schedule, read back, too (its rows are its points)
    paths = write_profiles(case.verified("toppra"), route.names, tmp_path / "toppra")
    read = tuple(generic.read(path.read_bytes(), source=path.name).table for path in paths)
    assert check_tables(read, route, case.limits(), jerk=False).passed


def test_a_fleets_table_that_runs_into_the_vehicle_ahead_is_refused_naming_the_pair():
    """The convoy's last vehicle's table, hurried: it runs into the middle one before that has moved off."""
    case = fleet("convoy-of-3")
    verified, route = case.verified("exact"), case.route()
    first, second, third = plc_tables(verified, "siemens-xy").resampled.tables
    check = check_tables((_hurried(first), second, third), route, case.limits())
    assert not check.passed
    named = [re.search(r"vehicle 1 (on|and) .*vehicle 2", failure) for failure in check.failures]
    assert any(named), check.failures


# -- a junction's route timed on its track graph (issue 49: one model below the planners) ------------------


@pytest.mark.parametrize(
    "dialect",
    [
        pytest.param(d, marks=() if d.name.value == "logix-time-cam" else pytest.mark.slow)
        for d in TABLE_DIALECTS
    ],
    ids=[d.name.value for d in TABLE_DIALECTS],
)  # the dialect whose knots are the point in the fast set
@pytest.mark.parametrize("name", ["swap", "crossing"])
def test_the_tables_of_a_junctions_exact_schedule_timed_on_its_track_graph_are_the_junctions(name, dialect):
    """The knots of a table include where a vehicle changes legs, on the junction and on its track graph.

    At the golden files' 300 points every byte agrees. (At a dialect's default points, thousands of
    rows, a track graph's axis, taken from the travel, lies 1e-15 m from the junction's and flips a
    last decimal here and there: ``benchmarks/bench_golden_on_graph.py``.)
    """
    scenario = load_scenario(REPO / "examples" / f"{name}.toml")
    route = scenario.route()
    junction = certify(Exact().schedule(route, scenario.limits))
    on_graph = certify(
        Exact().schedule_graph(junction_graph_route(route, names=scenario.names), scenario.limits)
    )
    made = [plc_tables(verified, dialect, max_points=300).contents for verified in (junction, on_graph)]
    assert made[1] == made[0]
