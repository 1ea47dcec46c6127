"""The pipeline: every output rendered from verified schedules, then all files committed or none."""

from __future__ import annotations

import logging
import os

import pytest

from tests.conftest import REPO
from tests.support.helpers import too_close
from trajgen import Outputs, Toppra, default_scenario, run
from trajgen.cli import EXIT_BAD_INPUT, main
from trajgen.errors import InputError, OptionError, OutputError
from trajgen.export import atomic, commit_files

SWAP = str(REPO / "examples" / "swap.toml")


def _hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_commit_writes_every_file_and_leaves_no_temporary(tmp_path):
    files = commit_files({tmp_path / "a" / "x.csv": b"x", tmp_path / "b" / "y.png": b"y"})
    assert [p.read_bytes() for p in files] == [b"x", b"y"]
    assert _hidden(tmp_path / "a") == _hidden(tmp_path / "b") == []


def _fail_renames_onto(monkeypatch, name: str) -> None:
    """Make every rename onto a file called ``name`` fail, as a full or read-only disk would."""
    real = os.replace

    def replace(source, target):
        if str(target).endswith(name):
            raise PermissionError(13, "Permission denied", str(target))
        return real(source, target)

    monkeypatch.setattr(atomic.os, "replace", replace)


def test_a_failed_rename_puts_every_earlier_file_back(tmp_path, monkeypatch):
    (tmp_path / "agv1.csv").write_bytes(b"old 1")
    (tmp_path / "agv2.csv").write_bytes(b"old 2")
    _fail_renames_onto(monkeypatch, "agv2.csv")
    with pytest.raises(OutputError, match=r"cannot write '.*agv2\.csv': Permission denied"):
        commit_files({tmp_path / "agv1.csv": b"new 1", tmp_path / "agv2.csv": b"new 2"})
    assert (tmp_path / "agv1.csv").read_bytes() == b"old 1"
    assert (tmp_path / "agv2.csv").read_bytes() == b"old 2"
    assert _hidden(tmp_path) == []


def test_a_journal_that_cannot_be_put_in_place_leaves_nothing(tmp_path, monkeypatch):
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "agv1.csv").write_bytes(b"old 1")
    _fail_renames_onto(monkeypatch, ".trajgen-journal")
    with pytest.raises(OutputError, match=r"Permission denied"):
        commit_files({tmp_path / "old" / "agv1.csv": b"new 1", tmp_path / "new" / "agv2.csv": b"new 2"})
    assert (tmp_path / "old" / "agv1.csv").read_bytes() == b"old 1"
    assert _hidden(tmp_path / "old") == []
    assert not (tmp_path / "new").exists()


def test_a_failed_write_removes_the_folders_it_made(tmp_path, monkeypatch):
    real = atomic.tempfile.mkstemp
    calls = []

    def fail_on_second(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(atomic.tempfile, "mkstemp", fail_on_second)
    with pytest.raises(OutputError, match="No space left on device"):
        commit_files({tmp_path / "new" / "deep" / "a.csv": b"a", tmp_path / "new" / "b.csv": b"b"})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("layout", "match"),
    [
        pytest.param(
            {"x.csv": "folder"}, r"output file '.*x\.csv' exists as a folder", id="target-is-folder"
        ),
        pytest.param(
            {"out": "file"}, r"output folder '.*out' exists and is not a folder", id="parent-is-file"
        ),
    ],
)
def test_unusable_targets_are_refused_before_anything_is_written(tmp_path, layout, match):
    for name, kind in layout.items():
        (tmp_path / name).mkdir() if kind == "folder" else (tmp_path / name).write_text("a file")
    before = sorted(p.name for p in tmp_path.iterdir())
    with pytest.raises(OutputError, match=match):
        commit_files({tmp_path / "ok.csv": b"1", tmp_path / "x.csv": b"2", tmp_path / "out" / "y.png": b"3"})
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_cli_plot_onto_a_file_exits_2_and_writes_no_csv(tmp_path, capsys):
    plot = tmp_path / "plot"
    plot.write_text("a file")
    csv = tmp_path / "csv"
    assert main(["schedule", SWAP, "--csv", str(csv), "--plot", str(plot)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"output folder {str(plot)!r} exists and is not a folder" in err
    assert not csv.exists()
    assert plot.read_text() == "a file"


def test_cli_csv_target_that_is_a_folder_exits_2_and_keeps_the_other_file(tmp_path, capsys):
    (tmp_path / "agv1.csv").write_text("previous profile")
    (tmp_path / "agv2.csv").mkdir()
    assert main(["schedule", SWAP, "--method", "exact", "--csv", str(tmp_path)]) == EXIT_BAD_INPUT
    assert "agv2.csv' exists as a folder: expected a file or nothing" in capsys.readouterr().err
    assert (tmp_path / "agv1.csv").read_text() == "previous profile"


def test_cli_empty_folder_name_exits_2(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["schedule", SWAP, "--csv", ""]) == EXIT_BAD_INPUT
    assert "CSV output folder must name a folder, got ''" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_run_certifies_each_schedule_and_commits_every_file(tmp_path, caplog):
    with caplog.at_level(logging.DEBUG, logger="trajgen.verification"):
        result = run(
            default_scenario(), outputs=Outputs(csv_dir=tmp_path / "csv", plot_dir=tmp_path / "plots")
        )
    verifications = [r.message.split()[2] for r in caplog.records if r.message.startswith("verified a")]
    # certified once each; toppra and optimal also verify their own result to choose a fallback
    assert sorted(verifications) == ["exact", "optimal", "optimal", "toppra", "toppra"]
    assert [p.name for p in result.files] == [
        "agv1.csv",
        "agv2.csv",
        "speed.png",
        "separation.png",
        "coordination.png",
        "layout.png",
        "configuration.png",
    ]
    assert all(p.is_file() for p in result.files)
    summary = result.summary()
    assert summary["method"] == "optimal"
    assert summary["solver"]["solver"] == "fatrop"
    assert summary["fallback_reason"] is None


def test_a_compared_method_that_fails_verification_is_left_out_of_the_plot(tmp_path, monkeypatch):
    real = Toppra.schedule

    def broken(self, route, limits):
        return too_close(real(self, route, limits))

    monkeypatch.setattr(Toppra, "schedule", broken)
    result = run(default_scenario(), method="exact", outputs=Outputs(plot_dir=tmp_path))
    assert any(
        n.startswith("coordination plot: toppra left out: schedule failed verification") for n in result.notes
    )
    assert (tmp_path / "coordination.png").read_bytes().startswith(b"\x89PNG")


def test_run_refuses_what_is_not_a_scenario():
    with pytest.raises(InputError, match="run expects a Scenario or a GraphScenario, got str"):
        run("examples/swap.toml")  # type: ignore[arg-type]


def test_a_fallback_run_reports_the_method_asked_for_and_plots_its_own_schedule(tmp_path, caplog):
    from trajgen import Optimal

    failing = Optimal(max_iterations=1)  # the solvers fail
    with caplog.at_level(logging.WARNING, logger="trajgen.methods.optimal"):
        result = run(default_scenario(), method=failing, outputs=Outputs(plot_dir=tmp_path))
    summary = result.summary()
    assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == (
        "optimal",
        "exact",
        "solver-failed",
    )
    # one optimal solve in the whole run: the coordination plot shows the run's own (fallback) schedule
    assert len([r for r in caplog.records if "fell back to the exact schedule" in r.message]) == 1
    assert (tmp_path / "coordination.png").is_file()


@pytest.mark.parametrize(
    "second",
    [pytest.param("AGV1.csv", id="case"), pytest.param("link/agv1.csv", id="through-a-link")],
)
def test_one_file_asked_for_twice_under_two_spellings_is_refused(tmp_path, second):
    (tmp_path / "link").symlink_to(tmp_path, target_is_directory=True)
    with pytest.raises(OutputError, match="is asked for twice in one run"):
        commit_files({tmp_path / "agv1.csv": b"first", tmp_path / second: b"second"})
    assert not (tmp_path / "agv1.csv").exists()


def test_rollback_keeps_a_dangling_link_that_was_there(tmp_path, monkeypatch):
    (tmp_path / "a.csv").symlink_to(tmp_path / "nowhere")
    _fail_renames_onto(monkeypatch, "b.csv")
    with pytest.raises(OutputError):
        commit_files({tmp_path / "a.csv": b"a", tmp_path / "b.csv": b"b"})
    assert (tmp_path / "a.csv").is_symlink()
    assert os.readlink(tmp_path / "a.csv") == str(tmp_path / "nowhere")
    assert _hidden(tmp_path) == []


def test_written_files_get_the_permissions_a_plain_open_would_give(tmp_path):
    (path,) = commit_files({tmp_path / "x.csv": b"x"})
    reference = tmp_path / "reference"
    reference.write_bytes(b"x")
    assert path.stat().st_mode & 0o777 == reference.stat().st_mode & 0o777


def test_cli_help_lists_one_line_per_method(capsys):
    from trajgen import METHODS

    with pytest.raises(SystemExit):
        main(["schedule", "--help"])
    out = capsys.readouterr().out
    for cls in METHODS:
        assert any(line.strip().startswith(f"{cls.name}: {cls.description}") for line in out.splitlines()), (
            cls.name
        )


def test_a_schedule_longer_than_a_day_is_run_with_a_warning_and_a_note(tmp_path, caplog):
    from trajgen import load_scenario
    from trajgen.pipeline import LONG_SCHEDULE_S

    text = (REPO / "examples" / "swap.toml").read_text(encoding="utf-8")
    slow = text.replace("A = 10.0, B = 10.0, C = 10.0", "A = 100000.0, B = 100000.0, C = 100000.0")
    slow = slow.replace('"A:10.0"', '"A:100000.0"').replace('"B:10.0"', '"B:100000.0"')
    slow = slow.replace("max_velocity = 1.0", "max_velocity = 0.001")
    path = tmp_path / "slow.toml"
    path.write_text(slow, encoding="utf-8")
    with caplog.at_level(logging.WARNING, logger="trajgen.pipeline"):
        result = run(load_scenario(path), method="exact")
    duration = result.verified.schedule.duration
    assert duration > 600_000_000.0
    assert duration > LONG_SCHEDULE_S == 86_400.0
    (note,) = [n for n in result.summary()["notes"] if "more than 86,400 s" in n]
    assert "check the scenario's units" in note
    assert note in caplog.text
    # a schedule of an hour is not warned about
    assert not [n for n in run(load_scenario(REPO / "examples" / "swap.toml"), method="exact").notes]


def test_the_compared_methods_are_the_ones_named_and_no_other_is_solved(tmp_path, caplog):
    with caplog.at_level(logging.DEBUG, logger="trajgen.verification"):
        result = run(default_scenario(), method="exact", outputs=Outputs(plot_dir=tmp_path, compare=()))
    verified = [r.message.split()[2] for r in caplog.records if r.message.startswith("verified a")]
    assert verified == ["exact"]  # the run's own schedule alone: no NLP solved for the plot
    assert (tmp_path / "coordination.png").is_file()
    assert result.verified.schedule.method.name == "exact"
    assert Outputs(compare=("TOPPRA", " exact")).compare == ("toppra", "exact")
    assert Outputs().compare == ("exact", "toppra", "optimal")
    with pytest.raises(OptionError, match=r"method 'fast' is unknown: expected one of \['exact'"):
        Outputs(compare=("fast",))
    with pytest.raises(InputError, match="compare must be a tuple of method names, got 'exact'"):
        Outputs(compare="exact")
