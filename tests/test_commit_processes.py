"""One commit for all files of a run, across processes: concurrent runs, crashes and SIGKILL."""

from __future__ import annotations

import multiprocessing
import os
import signal
import time

import pytest

from trajgen.export import atomic, commit_files
from trajgen.export.atomic import JOURNAL_NAME, recover_folder

pytestmark = pytest.mark.slow

FORK = multiprocessing.get_context("fork")


def _hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _slow(tag: str):
    """File content as chunks, slowly, so that concurrent commits overlap."""
    for k in range(3):
        time.sleep(0.002)
        yield f"{tag} part {k}\n".encode()


def _commit(folder: str, tag: str) -> None:
    commit_files({os.path.join(folder, "agv1.csv"): _slow(tag), os.path.join(folder, "agv2.csv"): _slow(tag)})


def test_concurrent_runs_into_one_folder_leave_one_run_s_files(tmp_path):
    for round_ in range(8):
        workers = [FORK.Process(target=_commit, args=(str(tmp_path), f"run {round_}.{k}")) for k in range(8)]
        for worker in workers:
            worker.start()
        for worker in workers:
            worker.join(timeout=60)
            assert worker.exitcode == 0
        first, second = (tmp_path / "agv1.csv").read_text(), (tmp_path / "agv2.csv").read_text()
        assert first == second, (round_, first, second)
        assert _hidden(tmp_path) == []


def _crash_between_renames(folder: str) -> None:
    real = os.replace

    def replace(source, target):
        if str(target).endswith("agv2.csv"):
            os._exit(9)  # the process dies after agv1.csv was renamed into place, before agv2.csv
        return real(source, target)

    atomic.os.replace = replace
    commit_files({os.path.join(folder, "agv1.csv"): b"new 1", os.path.join(folder, "agv2.csv"): b"new 2"})


@pytest.mark.parametrize("how", ["recover_folder", "next_commit"])
def test_a_crash_between_two_renames_is_undone(tmp_path, how):
    (tmp_path / "agv1.csv").write_bytes(b"old 1")
    (tmp_path / "agv2.csv").write_bytes(b"old 2")
    child = FORK.Process(target=_crash_between_renames, args=(str(tmp_path),))
    child.start()
    child.join(timeout=60)
    assert child.exitcode == 9
    assert (tmp_path / "agv1.csv").read_bytes() == b"new 1"  # the half-done state the crash left
    assert (tmp_path / JOURNAL_NAME).exists()
    if how == "recover_folder":
        recover_folder(tmp_path)
        assert (tmp_path / "agv1.csv").read_bytes() == b"old 1"
        assert (tmp_path / "agv2.csv").read_bytes() == b"old 2"
    else:  # the next run into the folder undoes it first, then writes its own files
        commit_files({tmp_path / "other.png": b"png"})
        assert (tmp_path / "agv1.csv").read_bytes() == b"old 1"
        assert (tmp_path / "other.png").read_bytes() == b"png"
    assert _hidden(tmp_path) == []


def _killed_while_writing(folder: str) -> None:
    def chunks():
        yield b"x" * 1_000_000
        os.kill(os.getpid(), signal.SIGKILL)
        yield b"never"

    commit_files({os.path.join(folder, "agv1.csv"): chunks()})


def test_sigkill_while_writing_leaves_nothing_under_the_target_names_and_is_cleaned_next_time(tmp_path):
    (tmp_path / "agv1.csv").write_bytes(b"old")
    child = FORK.Process(target=_killed_while_writing, args=(str(tmp_path),))
    child.start()
    child.join(timeout=60)
    assert child.exitcode == -signal.SIGKILL
    assert (tmp_path / "agv1.csv").read_bytes() == b"old"
    assert len(_hidden(tmp_path)) == 1  # the megabyte the run was writing, under a hidden name
    commit_files({tmp_path / "agv2.csv": b"next run"})
    assert _hidden(tmp_path) == []
    assert (tmp_path / "agv1.csv").read_bytes() == b"old"


def _crash_at_the_commit_point(first: str, second: str) -> None:
    import pathlib

    real = pathlib.Path.unlink

    def unlink(self, *args, **kwargs):
        if self.name == JOURNAL_NAME and str(self.parent) == second:
            os._exit(9)  # the primary journal is gone (committed), the other folder's is not yet
        return real(self, *args, **kwargs)

    pathlib.Path.unlink = unlink
    commit_files({os.path.join(first, "agv1.csv"): b"new 1", os.path.join(second, "agv2.csv"): b"new 2"})


def test_a_crash_after_the_commit_point_keeps_every_new_file(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    commit_files({first / "agv1.csv": b"old 1", second / "agv2.csv": b"old 2"})
    child = FORK.Process(target=_crash_at_the_commit_point, args=(str(first), str(second)))
    child.start()
    child.join(timeout=60)
    assert child.exitcode == 9
    assert (second / JOURNAL_NAME).exists()
    recover_folder(second)  # its journal's commit had reached its commit point: finish, do not undo
    assert (first / "agv1.csv").read_bytes() == b"new 1"
    assert (second / "agv2.csv").read_bytes() == b"new 2"
    assert _hidden(second) == []


@pytest.mark.parametrize(
    "journal",
    [
        pytest.param("[1]", id="not-an-object"),
        pytest.param('{"folders": 5, "entries": []}', id="bad-folders"),
        pytest.param(
            '{"commit": "x", "primary": "/", "folders": [], "entries": [["../victim", null]]}', id="escape"
        ),
        pytest.param("{not json", id="cut-short"),
    ],
)
def test_a_damaged_or_hostile_journal_stops_the_commit_and_touches_nothing(tmp_path, journal):
    from trajgen.errors import OutputError

    (tmp_path / "victim").write_bytes(b"keep me")
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / JOURNAL_NAME).write_text(journal)
    (folder / ".agv1.csv.0123.trajgen-bak").write_bytes(b"a backup")
    with pytest.raises(OutputError, match="restore its folder by hand"):
        commit_files({folder / "agv1.csv": b"new"})
    assert (tmp_path / "victim").read_bytes() == b"keep me"
    assert (folder / ".agv1.csv.0123.trajgen-bak").read_bytes() == b"a backup"
    assert not (folder / "agv1.csv").exists()


def test_recovering_a_missing_folder_is_an_output_error(tmp_path):
    from trajgen.errors import OutputError

    with pytest.raises(OutputError, match="is not a folder: nothing to recover"):
        recover_folder(tmp_path / "missing")
