"""What exported files say of their limits: no number above its limit; a schedule without jerk limits says so.

Issue 38, items 4 and 5. The bench sets are those of ``benchmarks/bench_export_limits.py``: the
built-in swap and crossing (the optimal schedules of both hold velocities 6e-9 above the limit as
computed, within the verifier's 1e-6) and the example track graphs (the H among them). A table
dialect other than the velocity profile writes positions only: no number of it has a limit.
"""

from __future__ import annotations

import dataclasses
import functools
import json

import numpy as np
import pytest

from tests.conftest import REPO
from trajgen import certify
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main
from trajgen.export.csv import CsvOptions, Units, profile_paths, render_profile, write_profiles
from trajgen.methods import make_schedule
from trajgen.scenario import builtin_scenario, load_scenario

SWAP = str(REPO / "examples" / "swap.toml")
H = REPO / "examples" / "graphs" / "h.toml"
#: ``(scenario, method)`` of the bench sets: the junctions first (every method), then the graphs.
BENCH = (
    *((name, method) for name in ("swap", "crossing") for method in ("exact", "toppra", "optimal")),
    *(
        (name, method)
        for name in ("h", "main-line-with-sidings", "passing-loop", "ring-with-spurs")
        for method in ("exact", "toppra")
    ),
)
#: Every unit and decimal mark of the generic CSV (each with another delimiter).
GENERIC_SETTINGS = [
    pytest.param(Units.METRES, ".", ";", id="m-point"),
    pytest.param(Units.METRES, ",", ";", id="m-comma"),
    pytest.param(Units.MILLIMETRES, ".", ",", id="mm-point"),
    pytest.param(Units.MILLIMETRES, ",", "\t", id="mm-comma"),
]
RECORD = "# schedule timed by toppra: jerk not limited (velocity and acceleration are)"


@functools.cache
def bench(name: str, method: str):
    """A bench set's scenario and its verified schedule by ``method``, once per process."""
    if name in ("swap", "crossing"):
        scenario = builtin_scenario(name)
    else:
        scenario = load_scenario(REPO / "examples" / "graphs" / f"{name}.toml")
    return scenario, certify(make_schedule(scenario.route(), scenario.limits, method=method))


def _number(field: str, decimal: str) -> float:
    try:
        return float(field.replace(decimal, "."))
    except ValueError:  # an edge's name
        return np.nan


def numbers(data: bytes, delimiter: str, decimal: str) -> np.ndarray:
    """The rows of a file as numbers (an edge's name: NaN), without its record line and header."""
    rows = []
    for line in data.decode("ascii").split("\n"):
        fields = line.rstrip("\r").split(delimiter)
        if not np.isnan(_number(fields[0], decimal)):  # not a record line, a header or the end
            rows.append([_number(field, decimal) for field in fields])
    return np.array(rows)


# --- item 5: no number above its limit -------------------------------------------------------------


def limited_columns(data: bytes, decimal: str, delimiter: str) -> np.ndarray:
    """The ``v``, ``a``, ``j`` columns of a generic CSV as written, in its units, shape (n, 3)."""
    text = data.decode("ascii")
    if decimal == ",":
        text = text.replace(",", ".")
    lines = [line for line in text.split("\r\n") if line[:1].isdigit()]  # no record, header or end
    return np.array([line.split(delimiter)[2:5] for line in lines], dtype=float)


@pytest.mark.parametrize(("units", "decimal", "delimiter"), GENERIC_SETTINGS)
def test_no_number_of_a_generic_csv_exceeds_its_limit_and_check_passes(tmp_path, units, decimal, delimiter):
    options = CsvOptions(units=units, decimal=decimal, delimiter=delimiter)
    reached = 0
    for name, method in BENCH:
        scenario, verified = bench(name, method)
        for vehicle in (0, 1):
            columns = limited_columns(render_profile(verified, vehicle, options), decimal, delimiter)
            limits = scenario.limits.vehicles[vehicle]
            stated = [(0, limits.max_velocity), (1, limits.max_acceleration)]
            if verified.schedule.jerk_limited:  # toppra's jerk column states no limit (its file says so)
                stated.append((2, limits.max_jerk))
            for column, limit in stated:
                peak = float(np.abs(columns[:, column]).max())
                assert peak <= limit * units.scale, (name, method, vehicle, column, peak)
                reached += peak == limit * units.scale
        if method == "optimal":  # its numbers were held to the limits: the files still pass their check
            from trajgen.export.plc.check import check_profiles

            folder = tmp_path / f"{name}-{method}"
            write_profiles(verified, scenario.names, folder, options=options)
            verdict = check_profiles(scenario, folder)
            assert verdict.passed, verdict.failures
    assert reached  # the limits are reached, not merely kept clear of


def test_a_velocity_profile_writes_no_velocity_above_its_limit(tmp_path):
    from trajgen.export.plc import plc_tables

    for name, method in BENCH:
        scenario, verified = bench(name, method)
        tables = plc_tables(verified, "velocity-profile")
        for vehicle, data in enumerate(tables.contents):
            peak = float(np.abs(numbers(data, ";", ".")[:, 1]).max())
            assert peak <= scenario.limits.vehicles[vehicle].max_velocity * 1000.0, (name, method, peak)


def test_a_velocity_table_written_a_hair_above_its_limit_is_slowed_down(monkeypatch):
    """A velocity table 5e-10 above its limit (within what its interpolation check lets through) backs off."""
    from trajgen.export.plc import files, plc_tables
    from trajgen.export.plc.tables import ProfileTable

    verified = bench("swap", "exact")[1]
    resample = files.resample

    def above(*args, **kwargs):
        made = resample(*args, **kwargs)
        raised = tuple(
            ProfileTable(t.times, t.values * (1.0 + 5e-10), t.interpolation, start=t.start)
            for t in made.tables
        )
        return dataclasses.replace(made, tables=raised)

    monkeypatch.setattr(files, "resample", above)
    tables = plc_tables(verified, "velocity-profile")
    peak = max(float(np.abs(numbers(data, ";", ".")[:, 1]).max()) for data in tables.contents)
    assert peak <= 1000.0
    assert tables.resampled.time_scale > 1.0  # slowed down, not clipped
    assert tables.check.passed


def test_a_velocity_table_still_above_its_limit_after_every_resampling_is_never_written(monkeypatch):
    from trajgen.errors import VerificationError
    from trajgen.export.plc import files, plc_tables

    verified = bench("swap", "exact")[1]
    monkeypatch.setattr(files, "_written_above", lambda *args: 1.000001)  # however slow, 1e-6 above
    with pytest.raises(VerificationError, match=r"write a velocity 1\.000001 times its limit after 3 "):
        plc_tables(verified, "velocity-profile")


def test_a_graph_csv_holds_a_velocity_a_hair_above_its_limit_to_the_limit():
    from trajgen.export.rows import format_rows_block

    scenario, verified = bench("h", "exact")
    state = verified.schedule.state(np.linspace(0.0, verified.schedule.duration, 400))
    above = dataclasses.replace(state, velocity=state.velocity * (1.0 + 5e-9))
    options = {"delimiter": ";", "decimal": ",", "scale": 1000.0, "decimals": 6}
    limits = scenario.limits.vehicles[0]
    held = numbers(format_rows_block(scenario.track, above, 0, **options, limits=limits), ";", ",")
    as_is = numbers(format_rows_block(scenario.track, above, 0, **options), ";", ",")
    assert np.abs(as_is[:, 2]).max() > 1000.0  # the case is real: unheld, it is written above the limit
    assert np.abs(held[:, 2]).max() == 1000.0
    far = dataclasses.replace(state, velocity=state.velocity * 1.01)  # no round-off: left for a check to see
    beyond = numbers(format_rows_block(scenario.track, far, 0, **options, limits=limits), ";", ",")
    assert np.abs(beyond[:, 2]).max() == pytest.approx(1010.0, abs=1e-3)


def test_the_cap_is_the_largest_number_written_at_most_the_limit():
    from trajgen.export.numbers import fixed_point_text, limit_cap, within_limit

    rng = np.random.default_rng(38)
    for limit in [1.2, 0.1234567896, 1000.0, 1.0000000004, 1.0000000006, *rng.uniform(1e-3, 1e4, 300)]:
        for places in (6, 9):
            cap = limit_cap(limit, places)
            assert float(fixed_point_text(cap, places)) <= limit
            assert float(fixed_point_text(cap + 10.0**-places, places)) > limit, (limit, places)
    assert (limit_cap(1.2, 9), limit_cap(0.1234567896, 9), limit_cap(1.0000000006, 9)) == (
        1.2,
        0.123456789,
        1.0,
    )
    values = np.array([1.2000000061, -1.2000000061, 1.19, 1.2 * (1 + 2e-6), -0.0])
    held = within_limit(values, 1.2, 9, tolerance=1e-6)
    assert [fixed_point_text(v, 9) for v in held] == [
        "1.200000000",
        "-1.200000000",
        "1.190000000",
        "1.200002400",  # twice the tolerance: no round-off, left as it is
        "0.000000000",
    ]
    below = np.array([0.5, -1.1999])
    assert within_limit(below, 1.2, 9, tolerance=1e-6) is below


# --- item 4: a schedule without jerk limits says so, and check reads it -----------------------------


@functools.cache
def _toppra_swap_files() -> dict[str, bytes]:
    """The generic CSVs ``trajgen schedule --method toppra`` writes of the swap (once per process)."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as folder:
        assert main(["schedule", SWAP, "--method", "toppra", "--csv", folder]) == EXIT_OK
        return {path.name: path.read_bytes() for path in sorted(Path(folder).iterdir())}


def _write(folder, files: dict[str, bytes], first_line: str | None = "keep"):
    """The files in ``folder``, their record line kept, dropped (``None``) or replaced."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in files.items():
        lines = data.split(b"\r\n")
        if first_line != "keep" and lines[0].startswith(b"#"):
            lines = lines[1:]
        if first_line not in ("keep", None):
            lines = [first_line.encode("ascii"), *lines]
        (folder / name).write_bytes(b"\r\n".join(lines))
    return folder


def test_a_toppra_csv_records_it_and_check_passes_saying_jerk_was_not_checked(tmp_path, capsys):
    files = _toppra_swap_files()
    capsys.readouterr()
    for data in files.values():
        assert data.split(b"\r\n")[:2] == [RECORD.encode(), b"t_s;axis_m;v_mps;a_mps2;j_mps3;leg;s_m;x_m;y_m"]
    folder = _write(tmp_path / "csv", files)
    assert main(["check", SWAP, "--csv", str(folder)]) == EXIT_OK
    text = capsys.readouterr().out
    assert (
        "note: the files record that their schedule is not jerk-limited (method toppra): jerk not checked\n"
        "PASS: the files keep the separation and the velocity and acceleration limits"
    ) in text
    assert main(["check", SWAP, "--csv", str(folder), "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["jerk_checked"] is False
    assert summary["record"] == {"method": "toppra", "jerk_limited": False}
    assert summary["ratios"]["jerk"] is None


def test_a_toppra_csv_without_the_record_still_reads_and_fails_on_jerk_naming_the_flag(tmp_path, capsys):
    folder = _write(tmp_path / "csv", _toppra_swap_files(), first_line=None)  # as a file of before 0.7
    capsys.readouterr()
    assert main(["check", SWAP, "--csv", str(folder)]) == EXIT_FAILURE
    text = capsys.readouterr().out
    assert "jerk reaches" in text
    assert "not jerk-limited (method" not in text
    assert text.rstrip().endswith("alone with --ignore-jerk\nFAIL")
    assert main(["check", SWAP, "--csv", str(folder), "--ignore-jerk"]) == EXIT_OK


def test_a_file_claiming_a_jerk_limited_schedule_is_held_to_the_jerk_limit(tmp_path, capsys):
    claim = "# schedule timed by toppra: jerk limited"
    folder = _write(tmp_path / "csv", _toppra_swap_files(), first_line=claim)
    capsys.readouterr()
    assert main(["check", SWAP, "--csv", str(folder)]) == EXIT_FAILURE
    text = capsys.readouterr().out
    assert "jerk reaches" in text
    assert "note: the files record that their schedule is jerk-limited (method toppra)" in text
    assert "--ignore-jerk" not in text  # they claim the jerk limit: no flag to offer


def test_files_that_record_their_schedule_differently_fail_and_are_held_to_jerk(tmp_path, capsys):
    files = _toppra_swap_files()
    folder = _write(tmp_path / "csv", files)
    _write(folder, {"agv2.csv": files["agv2.csv"]}, first_line=None)
    capsys.readouterr()
    assert main(["check", SWAP, "--csv", str(folder)]) == EXIT_FAILURE
    text = capsys.readouterr().out
    assert (
        f"agv1.csv records that its schedule is not jerk-limited (method toppra), {folder / 'agv2.csv'} "
        "does not: expected both files of one schedule to record it alike"
    ) in text
    assert "jerk reaches" in text


def test_a_comment_line_that_is_no_record_is_refused_naming_the_record(tmp_path):
    from trajgen.errors import ProfileFileError
    from trajgen.export.plc.dialects import DIALECTS

    data = b"# exported by hand\r\n" + _toppra_swap_files()["agv1.csv"].split(b"\r\n", 1)[1]
    with pytest.raises(
        ProfileFileError, match=r"line 1: .* is not trajgen's record of its schedule: expected"
    ):
        DIALECTS.lookup("generic").read(data, source="agv1.csv")
    (tmp_path / "agv1.csv").write_bytes(data)
    (tmp_path / "agv2.csv").write_bytes(_toppra_swap_files()["agv2.csv"])
    assert main(["check", SWAP, "--csv", str(tmp_path)]) == EXIT_BAD_INPUT


def test_a_graph_csv_of_toppra_records_it_and_passes_check(tmp_path, capsys):
    scenario, verified = bench("h", "toppra")
    paths = write_profiles(verified, scenario.names, tmp_path)
    assert paths == profile_paths(scenario.names, tmp_path)
    assert all(path.read_bytes().startswith(RECORD.encode() + b"\r\nt_s;axis_m") for path in paths)
    capsys.readouterr()
    assert main(["check", str(H), "--csv", str(tmp_path)]) == EXIT_OK
    assert "jerk not checked" in capsys.readouterr().out


def test_a_table_of_toppra_records_nothing_and_check_names_the_flag(tmp_path, capsys):
    """A table dialect has no place for the record: its files are held to jerk unless --ignore-jerk."""
    argv = ["schedule", SWAP, "--method", "toppra", "--dialect", "siemens-xy", "--csv", str(tmp_path)]
    assert main(argv) == EXIT_OK
    assert not (tmp_path / "agv1.csv").read_bytes().startswith(b"#")
    capsys.readouterr()
    assert main(["check", SWAP, "--csv", str(tmp_path), "--dialect", "siemens-xy"]) == EXIT_FAILURE
    assert capsys.readouterr().out.rstrip().endswith("alone with --ignore-jerk\nFAIL")
    assert (
        main(["check", SWAP, "--csv", str(tmp_path), "--dialect", "siemens-xy", "--ignore-jerk"]) == EXIT_OK
    )
