"""CSV profiles: format, round trip re-verified from the file, options, atomicity, legs up to k."""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.helpers import LIMITS, MIXED, route_of, too_close
from tests.support.star_scenarios import STAR_SCENARIOS, leg_index, read_csv, toml_text
from trajgen import Exact, Schedule, Toppra, certify, load_scenario
from trajgen.cli import EXIT_OK, main
from trajgen.errors import OptionError, UnverifiedScheduleError, VerificationError
from trajgen.export import CsvOptions, Units, commit_files, write_profiles
from trajgen.export import csv as csv_export
from trajgen.export.csv import format_block, format_rows, profile_chunk_pair, render_profile
from trajgen.export.plc.check import check_profiles

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))
NAMES = ("agv1", "agv2")


def read_profile(path, options: CsvOptions):
    raw = path.read_bytes()
    assert raw.endswith(b"\r\n")
    lines = raw.decode("ascii").split("\r\n")[:-1]
    assert all("\n" not in line and "\r" not in line for line in lines)
    if lines[0].startswith("#"):  # a schedule without jerk limits records so on the first line
        lines = lines[1:]
    header = lines[0].split(options.delimiter)
    rows = [
        [field.replace(options.decimal, ".") for field in line.split(options.delimiter)] for line in lines[1:]
    ]
    data = np.array(rows, dtype=float)
    return header, data


@pytest.mark.parametrize(
    ("method", "limits"),
    [pytest.param("exact", LIMITS, id="exact"), pytest.param("toppra", MIXED, id="toppra-mixed-limits")],
)
def test_csv_round_trip_re_verified_from_the_files(tmp_path, method, limits):
    route = route_of(*SWAP)
    schedule = (Exact() if method == "exact" else Toppra()).schedule(route, limits)
    options = CsvOptions()
    paths = write_profiles(certify(schedule), NAMES, tmp_path, options=options)
    assert [p.name for p in paths] == ["agv1.csv", "agv2.csv"]
    tables = [read_profile(p, options) for p in paths]
    for header, data in tables:
        assert header == ["t_s", "axis_m", "v_mps", "a_mps2", "j_mps3", "leg", "s_m", "x_m", "y_m"]
        t = data[:, 0]
        assert t[0] == 0.0
        assert t[-1] == pytest.approx(schedule.duration, abs=1e-6)
        assert np.allclose(np.diff(t)[:-1], 0.01, atol=1e-6)
        assert 0.0 < t[-1] - t[-2] <= 0.01 + 1e-6
        assert set(np.unique(data[:, 5])) <= {0.0, 1.0, 2.0, 3.0}
        assert np.all((data[:, 5] == 0) == (data[:, 6] == 0))
    # re-verify from the files alone
    (_, first), (_, second) = tables
    legs = np.stack([first[:, 5], second[:, 5]]).astype(int)
    s = np.stack([first[:, 6], second[:, 6]])
    separation = np.where((legs[0] == legs[1]) & (legs[0] > 0), np.abs(s[0] - s[1]), s[0] + s[1])
    assert separation.min() >= limits.min_separation - 1e-6
    for data, vehicle in zip((first, second), limits.vehicles, strict=True):
        assert np.abs(data[:, 2]).max() <= vehicle.max_velocity * (1 + 1e-6)
        assert np.abs(data[:, 3]).max() <= vehicle.max_acceleration * (1 + 1e-6)
        # v consistent with the finite difference of the axis (error bounded by a_max * h / 2)
        h = np.diff(data[:, 0])
        difference = np.diff(data[:, 1]) / h
        midpoint_v = 0.5 * (data[1:, 2] + data[:-1, 2])
        assert np.abs(difference - midpoint_v).max() <= vehicle.max_acceleration * h.max() / 2 + 1e-6
        # x, y agree with the leg angles
        angles = np.radians(np.array([0.0, 90.0, 210.0, 330.0]))[data[:, 5].astype(int)]
        assert np.allclose(data[:, 7], data[:, 6] * np.cos(angles), atol=1e-8)
        assert np.allclose(data[:, 8], data[:, 6] * np.sin(angles), atol=1e-8)
    # start and goal: agv1 from A (leg 1) end to B (leg 2) end
    assert (first[0, 5], first[0, 6], first[-1, 5], first[-1, 6]) == (1, 10.0, 2, 10.0)
    assert (second[0, 5], second[0, 6], second[-1, 5], second[-1, 6]) == (2, 10.0, 1, 10.0)
    assert not list(tmp_path.glob(".*.tmp"))


def test_millimetres_comma_decimal_and_tab(tmp_path):
    schedule = certify(Exact().schedule(route_of(*SWAP), LIMITS))
    metres = CsvOptions(sample_period=0.1)
    millimetres = CsvOptions(sample_period=0.1, delimiter="\t", decimal=",", units=Units.MILLIMETRES)
    m_path, _ = write_profiles(schedule, NAMES, tmp_path / "m", options=metres)
    mm_path, _ = write_profiles(schedule, NAMES, tmp_path / "mm", options=millimetres)
    _, in_metres = read_profile(m_path, metres)
    mm_header, in_mm = read_profile(mm_path, millimetres)
    assert mm_header == ["t_s", "axis_mm", "v_mmps", "a_mmps2", "j_mmps3", "leg", "s_mm", "x_mm", "y_mm"]
    assert "," in mm_path.read_text().splitlines()[5]
    assert np.allclose(in_mm[:, 0], in_metres[:, 0])
    assert np.allclose(in_mm[:, 5], in_metres[:, 5])
    for column in (1, 2, 3, 4, 6, 7, 8):
        assert np.allclose(in_mm[:, column], 1000.0 * in_metres[:, column], atol=1e-5)


def test_failing_schedule_cannot_be_certified_nor_written(tmp_path):
    broken = too_close(Exact().schedule(route_of(*SWAP), LIMITS))
    target = tmp_path / "out"
    with pytest.raises(VerificationError, match=r"below the minimum 10\.5 m"):
        certify(broken)
    with pytest.raises(
        UnverifiedScheduleError, match=r"write_profiles takes a VerifiedSchedule.*got Schedule"
    ):
        write_profiles(broken, NAMES, target)
    assert not target.exists()


def test_existing_files_are_replaced_whole(tmp_path):
    schedule = certify(Exact().schedule(route_of(*SWAP), LIMITS))
    (tmp_path / "agv1.csv").write_text("old")
    write_profiles(schedule, NAMES, tmp_path, options=CsvOptions(sample_period=0.5))
    assert (tmp_path / "agv1.csv").read_text().startswith("t_s;")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["agv1.csv", "agv2.csv"]


@pytest.mark.parametrize(
    ("options", "match"),
    [
        pytest.param(
            {"delimiter": ",", "decimal": ","}, "decimal mark and delimiter are both ','", id="same-marks"
        ),
        pytest.param(
            {"decimal": ";", "delimiter": ","}, r"decimal mark ';' is not supported", id="bad-decimal"
        ),
        pytest.param({"delimiter": ";;"}, "delimiter ';;' is not usable", id="long-delimiter"),
        pytest.param({"delimiter": "5"}, "delimiter '5' is not usable", id="digit-delimiter"),
        pytest.param({"sample_period": 0.0}, r"sample period must be > 0 s, got 0\.0", id="zero-period"),
        pytest.param({"sample_period": float("nan")}, "sample period.*must be finite", id="nan-period"),
        pytest.param(
            {"units": "inch"}, r"units 'inch' is unknown: expected one of \['m', 'mm'\]", id="units"
        ),
    ],
)
def test_bad_csv_options(options, match):
    with pytest.raises(ValueError, match=match):
        CsvOptions(**options)


def test_option_errors_are_option_errors():
    with pytest.raises(OptionError):
        CsvOptions(delimiter=",", decimal=",")


@pytest.fixture(scope="module")
def swap_exact():
    return certify(Exact().schedule(route_of(*SWAP), LIMITS))


def test_both_files_sample_each_block_once_and_any_block_size_gives_the_same_bytes(
    tmp_path, monkeypatch, swap_exact
):
    options = CsvOptions(sample_period=0.1)  # 676 rows
    expected = [render_profile(swap_exact, vehicle, options) for vehicle in (0, 1)]
    samplings = []
    real_state = Schedule.state

    def counting_state(schedule, t):
        samplings.append(np.size(t))
        return real_state(schedule, t)

    monkeypatch.setattr(Schedule, "state", counting_state)
    monkeypatch.setattr(csv_export, "ROWS_PER_CHUNK", 100)
    paths = write_profiles(swap_exact, NAMES, tmp_path, options=options)
    assert [path.read_bytes() for path in paths] == expected
    assert samplings == [100] * 6 + [76]  # one sampling per block for both files
    samplings.clear()
    first, second = profile_chunk_pair(swap_exact, options)
    assert b"".join(first) + b"".join(second) == expected[0] + expected[1]  # one file, then the other
    assert len(samplings) == 14  # each block sampled for each file


def test_format_rows_are_the_lines_of_format_block(swap_exact):
    schedule = swap_exact.schedule
    state = schedule.sample(0.5)
    options = CsvOptions(delimiter="\t", decimal=",", units=Units.MILLIMETRES)
    block = format_block(schedule.track, state, 1, options)
    rows = format_rows(schedule.track, state, 1, options)
    assert len(rows) == state.t.size
    assert "".join(row + "\r\n" for row in rows).encode("ascii") == block
    assert rows[0].split("\t")[:2] == ["0,000000", "0,000000"]


def test_commit_files_takes_a_chunk_of_each_file_in_turn(tmp_path):
    taken = []

    def chunks(name: str, count: int):
        for k in range(count):
            taken.append(f"{name}{k}")
            yield f"{name}{k};".encode()

    paths = commit_files(
        {tmp_path / "a.csv": chunks("a", 3), tmp_path / "b.csv": b"whole", tmp_path / "c.csv": chunks("c", 1)}
    )
    assert taken == ["a0", "c0", "a1", "a2"]
    assert [path.read_bytes() for path in paths] == [b"a0;a1;a2;", b"whole", b"c0;"]


# -- a junction of 8 legs: legs 1-based up to 8, x and y from the angles --------------------------------


@pytest.mark.slow
def test_csv_legs_are_one_based_up_to_k_and_xy_follow_the_angles(tmp_path, capsys):
    data = STAR_SCENARIOS[8]
    path = tmp_path / "eight.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    scenario = load_scenario(path)
    assert main(["schedule", str(path), "--method", "exact", "--csv", str(tmp_path / "csv")]) == EXIT_OK
    capsys.readouterr()
    angles = np.radians(np.array(scenario.track.angles_deg))
    seen: set[int] = set()
    for vehicle, name in enumerate(scenario.names):
        columns = read_csv(tmp_path / "csv" / f"{name}.csv")
        legs = columns["leg"].astype(int)
        assert np.all(legs == columns["leg"])  # integers
        assert np.all((legs >= 0) & (legs <= 8))
        seen |= set(legs.tolist())
        on_leg = legs > 0
        angle = angles[np.where(on_leg, legs - 1, 0)]
        s = columns["s_m"]
        np.testing.assert_allclose(columns["x_m"], np.where(on_leg, s * np.cos(angle), 0.0), atol=2e-9)
        np.testing.assert_allclose(columns["y_m"], np.where(on_leg, s * np.sin(angle), 0.0), atol=2e-9)
        # the first and last rows: the scenario's start and goal, by 1-based index
        for row, position in ((0, scenario.start[vehicle]), (-1, scenario.goal[vehicle])):
            assert legs[row] == leg_index(scenario, position) + 1
            assert s[row] == pytest.approx(position.s, abs=1e-9)
    assert 8 in seen  # the 8th leg, H, is leg 8
    assert scenario.start[0].leg == "H"
    assert scenario.track.index("H") == 7
    assert check_profiles(scenario, tmp_path / "csv").passed
