"""PLC dialects: resampled tables, their files, and ``trajgen check`` on them and on edited files.

On the demo swap, and on the built-in 4-way crossing (its legs numbered 1 to 4).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.conftest import REPO
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
from trajgen.export.plc.table_check import check_tables
from trajgen.export.plc.tables import Interpolation, ProfileTable, divided_differences
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
