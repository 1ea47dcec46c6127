"""Every bad input is a clean error: exit 2 from the CLI with a short message naming what was expected.

Nothing is written by a run that exits non-zero; the same checks hold in the Python API.
"""

from __future__ import annotations

import pytest

from tests.conftest import REPO
from tests.support.helpers import LIMITS, route_of
from trajgen import Exact, certify, make_schedule, write_profiles
from trajgen.cli import EXIT_BAD_INPUT, EXIT_OK, main
from trajgen.errors import InputError
from trajgen.export import write_tables

SWAP_FILE = REPO / "examples" / "swap.toml"
GOOD = SWAP_FILE.read_text(encoding="utf-8")


def _scenario(tmp_path, content: bytes | str) -> str:
    path = tmp_path / "scenario.toml"
    path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    return str(path)


FILE_CASES = [
    pytest.param(GOOD.encode("utf-16"), "it looks like UTF-16: save it as UTF-8", id="utf-16"),
    pytest.param(
        GOOD.replace("agv1", "agv\xe9").encode("latin-1"), "is not UTF-8 text: byte 0xe9", id="latin-1"
    ),
    pytest.param("x = " + "[" * 100_000 + "]" * 100_000, "nested too deeply", id="deep-nesting"),
    pytest.param(
        GOOD + "#" * (1 << 20), r"is 1,04\d,\d{3} bytes: expected a scenario file of at most", id="huge"
    ),
    pytest.param(GOOD.replace("A = 10.0,", "A = 1e-300,"), r"leg 'A' is 1e-300 m long", id="tiny-leg"),
    pytest.param(
        GOOD.replace('name = "agv1"', 'name = "' + "n" * 100_000 + '"'),
        "is not a portable file name",
        id="long-name",
    ),
]


@pytest.mark.parametrize(("content", "match"), FILE_CASES)
def test_bad_scenario_files_exit_2_with_a_short_message(tmp_path, capsys, content, match):
    import re

    output = tmp_path / "out"
    assert main(["schedule", _scenario(tmp_path, content), "--csv", str(output)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert re.search(match, err), err[:500]
    assert len(err) < 600  # a long value is quoted by a short prefix only
    assert not output.exists()


def test_a_device_is_not_read_as_a_scenario(tmp_path, capsys):
    assert main(["plan", "/dev/zero"]) == EXIT_BAD_INPUT
    assert "/dev/zero: is not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("options", "match"),
    [
        pytest.param(["--delimiter", "é"], "delimiter 'é' is not usable", id="non-ascii"),
        pytest.param(["--delimiter", "_"], "delimiter '_' is not usable", id="underscore"),
        pytest.param(["--delimiter", "s"], "delimiter 's' is not usable", id="letter-s"),
        pytest.param(["--delimiter", "e"], "delimiter 'e' is not usable", id="letter-e"),
        pytest.param(["--sample-period", "1e-6"], "at least 22,500,001 rows", id="period-1e-6"),
        pytest.param(["--sample-period", "5e-324"], "at least inf rows", id="period-subnormal"),
        pytest.param(["--max-rows", "0"], "max_rows must be an integer >= 1, got 0", id="max-rows-0"),
        pytest.param(["--max-rows", "3000"], "schedule has 6,751 rows", id="max-rows-after-scheduling"),
    ],
)
def test_bad_csv_options_exit_2_and_write_nothing(tmp_path, capsys, options, match):
    output = tmp_path / "out"
    argv = ["schedule", str(SWAP_FILE), "--method", "exact", "--csv", str(output), *options]
    assert main(argv) == EXIT_BAD_INPUT
    assert match in capsys.readouterr().err
    assert not output.exists()


def test_an_unwritable_folder_exits_2(tmp_path, capsys):
    assert (
        main(["schedule", str(SWAP_FILE), "--method", "exact", "--csv", "/proc/trajgen-out"])
        == EXIT_BAD_INPUT
    )
    assert "cannot write" in capsys.readouterr().err


def test_start_equal_to_goal_is_a_valid_request_of_zero_motion(tmp_path, capsys):
    # each vehicle's goal is its start: vehicle 1 stays at the end of A, vehicle 2 at the end of B
    path = _scenario(
        tmp_path,
        GOOD.replace('goal = "B:10.0"', 'goal = "A:X"')
        .replace('goal = "A:10.0"', 'goal = "B:10.0"')
        .replace('goal = "A:X"', 'goal = "A:10.0"'),
    )
    output = tmp_path / "out"
    for method in ("exact", "toppra", "optimal"):
        assert main(["schedule", path, "--method", method, "--csv", str(output), "--json"]) == EXIT_OK
        assert '"duration_s": 0.0' in capsys.readouterr().out
        lines = (output / "agv1.csv").read_text().splitlines()
        # toppra's file records first that its schedule does not limit jerk
        assert lines[0].startswith("# schedule timed by toppra") == (method == "toppra")
        rows = [line for line in lines if not line.startswith("#")]
        assert len(rows) == 2  # the header and one row at t = 0, at rest
        assert rows[1].startswith("0.000000;0.000000000;0.000000000;0.000000000;0.000000000;1;10.000000000")


def test_the_api_refuses_names_that_leave_the_folder(tmp_path):
    verified = certify(
        Exact().schedule(route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10")), LIMITS)
    )
    with pytest.raises(InputError, match=r"vehicle name '\.\./x' is not a portable file name"):
        write_profiles(verified, ("../x", "/abs/y"), tmp_path)
    with pytest.raises(InputError, match="vehicle names must be a sequence of names, one per vehicle, got 5"):
        write_profiles(verified, 5, tmp_path)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"vehicle names \('a', 'b', 'c'\): expected 2, one per vehicle"):
        write_profiles(verified, ("a", "b", "c"), tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_the_api_refuses_a_route_planned_for_a_smaller_separation():
    route = route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"), separation=0.5)
    for method in ("exact", "toppra", "optimal"):
        with pytest.raises(
            InputError, match=r"planned for a min_separation of 0\.5 m but the limits ask 1\.5 m"
        ):
            make_schedule(route, LIMITS, method=method)
    with pytest.raises(InputError, match=r"route must be a topology\.Route, got str"):
        Exact().schedule("route", LIMITS)  # type: ignore[arg-type]


@pytest.mark.parametrize("value", [None, 5, "x", 1.5, [], {}, b"x", (1, 2)], ids=repr)
def test_wrong_types_in_the_api_are_type_or_value_errors(value):
    from trajgen import CsvOptions, Optimal, Outputs, default_scenario, run, verify
    from trajgen.plots import plot_coordination

    scenario = default_scenario()
    route = scenario.route()
    calls = [
        lambda: make_schedule(value, LIMITS),
        lambda: make_schedule(route, value),
        lambda: make_schedule(route, scenario.limits, method=value if value is not None else 0),
        lambda: verify(value),
        lambda: certify(value),
        lambda: run(value),
        lambda: run(scenario, outputs=value if value is not None else 0),
        lambda: Outputs(csv_dir=value) if not isinstance(value, str | None) else Outputs(csv=value),
        lambda: CsvOptions(delimiter=value),
        lambda: Optimal(nodes=value if not isinstance(value, int) else -value),
        lambda: plot_coordination(value),
        lambda: write_profiles(value, ("a", "b"), "unused"),
    ]
    for call in calls:
        with pytest.raises((TypeError, ValueError)):
            call()


def test_a_long_leg_name_is_quoted_short(tmp_path, capsys):
    long_leg = "X" * 5000
    content = GOOD.replace("A = 10.0,", f"{long_leg} = 10.0,").replace("A = 90.0,", f"{long_leg} = 90.0,")
    assert main(["schedule", _scenario(tmp_path, content), "--csv", str(tmp_path / "out")]) == EXIT_BAD_INPUT
    assert len(capsys.readouterr().err) < 400


def test_a_folder_name_the_file_system_refuses_exits_2(tmp_path, capsys):
    folder = tmp_path / ("d" * 300)
    assert main(["schedule", str(SWAP_FILE), "--method", "exact", "--csv", str(folder)]) == EXIT_BAD_INPUT
    assert "File name too long" in capsys.readouterr().err


@pytest.mark.parametrize(("limit", "code"), [(6750, EXIT_BAD_INPUT), (6751, EXIT_OK)])
def test_the_row_limit_counts_rows(tmp_path, capsys, limit, code):
    output = tmp_path / "out"
    argv = ["schedule", str(SWAP_FILE), "--method", "exact", "--csv", str(output), "--max-rows", str(limit)]
    assert main(argv) == code
    if code == EXIT_OK:  # 67.5 s every 10 ms: rows at 0, 0.01, ..., 67.5
        assert len((output / "agv1.csv").read_text().splitlines()) == 1 + 6751


def test_csv_options_of_the_wrong_type_are_an_option_error(tmp_path):
    from trajgen.errors import OptionError

    verified = certify(
        Exact().schedule(route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10")), LIMITS)
    )
    with pytest.raises(OptionError, match="CSV options must be CsvOptions, got str"):
        write_profiles(verified, ("a", "b"), tmp_path, options="x")  # type: ignore[arg-type]


# -- destinations that take no file: refused before anything is computed, naming the user's path -------


@pytest.fixture
def nothing_scheduled(monkeypatch):
    """Fail the test if a schedule is computed."""
    import trajgen.pipeline

    def refuse(*args, **kwargs):
        raise AssertionError("a schedule was computed although the output cannot be written")

    monkeypatch.setattr(trajgen.pipeline, "make_schedule", refuse)


@pytest.fixture
def immutable_folder(tmp_path):
    """A folder with the immutable attribute (``chattr +i``), where the platform allows it."""
    import shutil
    import subprocess

    folder = tmp_path / "locked"
    folder.mkdir()
    if shutil.which("chattr") is None:
        pytest.skip("no chattr here")
    if subprocess.run(["chattr", "+i", str(folder)], capture_output=True).returncode != 0:
        pytest.skip("this file system or user cannot make a folder immutable")
    yield folder
    subprocess.run(["chattr", "-i", str(folder)], capture_output=True, check=True)


@pytest.mark.usefixtures("nothing_scheduled")
@pytest.mark.parametrize("option", ["--csv", "--plot"])
def test_a_destination_under_proc_exits_2_before_solving_naming_it(capsys, option):
    # /proc takes no new file, not even from root
    assert main(["schedule", str(SWAP_FILE), option, "/proc/trajgen-out"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "cannot write '/proc/trajgen-out/" in err
    assert "folder '/proc' takes no new file" in err
    assert "trajgen-tmp" not in err
    assert "trajgen-probe" not in err


@pytest.mark.usefixtures("nothing_scheduled")
@pytest.mark.slow  # chattr, a process
def test_an_immutable_folder_exits_2_before_solving_naming_the_file_asked_for(immutable_folder, capsys):
    argv = ["schedule", str(SWAP_FILE), "--csv", str(immutable_folder / "out"), "--method", "exact"]
    assert main(argv) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"cannot write '{immutable_folder / 'out' / 'agv1.csv'}'" in err
    assert "trajgen-tmp" not in err
    assert list(immutable_folder.iterdir()) == []


@pytest.mark.slow  # chattr, a process
def test_a_folder_locked_during_the_commit_is_reported_by_the_path_asked_for(immutable_folder):
    """The last line of defence: the commit's own error names the file, not its hidden temporary."""
    import subprocess

    from trajgen.errors import OutputError
    from trajgen.export import commit_files

    subprocess.run(["chattr", "-i", str(immutable_folder)], check=True)

    def content():
        yield b"first row\n"
        subprocess.run(["chattr", "+i", str(immutable_folder)], check=True)  # locked mid-commit
        yield b"second row\n"

    target = immutable_folder / "profile.csv"
    with pytest.raises(OutputError, match=rf"cannot write '{target}': Operation not permitted"):
        commit_files({target: content()})
    assert not target.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        pytest.param(["--dialect", "siemens"], "dialect 'siemens' is unknown", id="dialect"),
        pytest.param(["--homotopy", "both"], "homotopy choice 'both' is unknown", id="homotopy-choice"),
        pytest.param(["--units", "inch"], "argument --units: invalid choice: 'inch'", id="units"),
    ],
)
def test_an_unknown_option_value_is_named_in_words(capsys, argv, message):
    assert main(["schedule", str(SWAP_FILE), *argv]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert message in err
    assert "dialectname" not in err
    assert "homotopychoice" not in err


def test_table_files_are_one_per_vehicle_of_the_schedule(tmp_path):
    verified = certify(
        Exact().schedule(route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10")), LIMITS)
    )
    with pytest.raises(InputError, match=r"vehicle names \('a', 'b', 'c'\): expected 2, one per vehicle"):
        write_tables(verified, ("a", "b", "c"), tmp_path, dialect="codesys-xy")
    assert list(tmp_path.iterdir()) == []
