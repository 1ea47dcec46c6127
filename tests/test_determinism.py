"""The same scenario gives the same schedule, whatever the load and wherever its NLP came from.

The optimal method's effort is fixed by iteration limits, refinement passes and a tolerance; the
only wall-clock limit is a safety stop far above the usual solve time. These tests run the
command line as a user does, twice: first alone with an empty store of compiled NLPs (every
NLP is built), then beside CPU-bound processes that keep every core busy, with the store the
first run filled (every NLP is loaded). The CSV files are byte-identical, and so is
``simulate``'s plan. A forced fallback is reported in the JSON of every command that plans.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

#: The issue's Y: legs of 6, 9.5 and 14 m, a 1.2 m/s and a 0.8 m/s vehicle swapping.
Y_SCENARIO = """
[track]
legs = { A = 6.0, B = 9.5, C = 14.0 }

[safety]
min_separation = 1.5

[[vehicle]]
name = "fast"
max_velocity = 1.2
max_acceleration = 0.5
max_jerk = 1.0
start = "A:6.0"
goal = "B:9.5"

[[vehicle]]
name = "slow"
max_velocity = 0.8
max_acceleration = 0.5
max_jerk = 1.0
start = "B:9.5"
goal = "A:6.0"
"""


def _scenario(name: str, folder: Path) -> Path:
    if name == "y":
        path = folder / "y.toml"
        path.write_text(Y_SCENARIO, encoding="utf-8")
        return path
    return REPO / "examples" / f"{name}.toml"


def _trajgen(*args: str, store: Path) -> subprocess.CompletedProcess:
    environment = {**os.environ, "TRAJGEN_CACHE_DIR": str(store)}
    done = subprocess.run(
        [sys.executable, "-m", "trajgen", *args],
        cwd=REPO,
        env=environment,
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )
    # whatever it writes to stderr (warnings, the solvers' messages) carries the program's prefix
    assert all(line.startswith("trajgen: ") for line in done.stderr.splitlines()), done.stderr
    return done


@contextlib.contextmanager
def _every_core_busy():
    """CPU-bound processes, one more than the cores, for as long as the block runs."""
    hogs = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range((os.cpu_count() or 1) + 1)
    ]
    try:
        yield
    finally:
        for hog in hogs:
            hog.kill()
        for hog in hogs:
            hog.wait()


def _schedule_and_simulate(scenario: Path, out: Path, store: Path) -> tuple[dict[str, bytes], dict, dict]:
    """The CSV files, ``schedule --json`` and ``simulate --json`` of one run."""
    summary = json.loads(
        _trajgen(
            "schedule", str(scenario), "--method", "optimal", "--csv", str(out), "--json", store=store
        ).stdout
    )
    simulated = json.loads(_trajgen("simulate", str(scenario), "--json", store=store).stdout)
    files = {path.name: path.read_bytes() for path in sorted(out.iterdir())}
    return files, summary, simulated


@pytest.mark.parametrize("name", ["swap", "crossing", "y"])
def test_the_optimal_plan_is_byte_identical_alone_and_under_load_built_and_loaded(name, tmp_path):
    scenario = _scenario(name, tmp_path)
    store = tmp_path / "store"
    alone, alone_summary, alone_simulated = _schedule_and_simulate(scenario, tmp_path / "alone", store)
    assert any(store.rglob("*.nlp")), "the first run keeps the NLPs it built"
    with _every_core_busy():
        loaded, loaded_summary, loaded_simulated = _schedule_and_simulate(
            scenario, tmp_path / "loaded", store
        )
    assert alone
    assert set(alone) == set(loaded)
    for file_name, data in alone.items():
        assert data == loaded[file_name], f"{file_name} differs between the runs"
    for summary in (alone_summary, loaded_summary, alone_simulated, loaded_simulated):
        assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == (
            "optimal",
            "optimal",
            None,
        )
        assert summary["time_limit_reached"] is False
    assert alone_summary["solver"]["built"] is True
    assert loaded_summary["solver"]["built"] is False
    assert loaded_summary["solver"]["loaded"] is True
    assert alone_summary["duration_s"] == loaded_summary["duration_s"]
    assert alone_simulated["planned_s"] == loaded_simulated["planned_s"]
    assert alone_simulated["makespan_s"] == loaded_simulated["makespan_s"]


def _failing_solve(*_arguments, **_options):
    """The optimal method's solver chain, made to fail: every class falls back to ``exact``."""
    from trajgen.methods.optimal import Outcome, Solver, SolverAttempt
    from trajgen.methods.optimal.solve import SolveResult

    return SolveResult(None, (SolverAttempt(Solver.FATROP, Outcome.NOT_CONVERGED, 1, "made to fail"),))


@pytest.mark.parametrize("command", ["schedule", "simulate"])
def test_a_forced_fallback_is_reported_in_the_json_and_the_text(command, monkeypatch, capsys, caplog):
    from trajgen.cli import main
    from trajgen.cli.entry import LogFormatter
    from trajgen.methods.optimal import class_solve as optimal_method

    monkeypatch.setattr(optimal_method, "solve", _failing_solve)
    scenario = str(REPO / "examples" / "swap.toml")
    with caplog.at_level(logging.WARNING):
        assert main([command, scenario, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == (
        "optimal",
        "exact",
        "solver-failed",
    )
    assert summary["time_limit_reached"] is False
    # the warning says why, and the command line writes it with the program's prefix: no bare line
    lines = [LogFormatter().format(record) for record in caplog.records]
    assert (
        "trajgen: warning: optimal: fell back to the exact schedule (solver-failed): "
        "no solver converged (fatrop, then Ipopt)"
    ) in lines
    assert main([command, scenario]) == 0
    text = capsys.readouterr().out
    assert "exact (fallback from optimal: solver-failed)" in text


def test_the_optimal_plan_on_a_track_graph_is_byte_identical_alone_and_under_load(tmp_path):
    """The passing loop's generic CSV and its SIMATIC tables, alone and beside CPU-bound processes.

    Its optimal plan solves two classes (agv1 waits on the main line or on the loop) and keeps the
    faster, as the H's does, in a fraction of the H's time.
    """
    scenario = REPO / "examples" / "graphs" / "passing-loop.toml"
    store = tmp_path / "store"
    runs = []
    for label in ("alone", "loaded"):
        with _every_core_busy() if label == "loaded" else contextlib.nullcontext():
            files = {}
            for dialect in ("generic", "siemens-xy"):
                out = tmp_path / label / dialect
                summary = json.loads(
                    _trajgen(
                        "schedule",
                        str(scenario),
                        "--method",
                        "optimal",
                        "--csv",
                        str(out),
                        "--dialect",
                        dialect,
                        "--json",
                        store=store,
                    ).stdout
                )
                assert summary["fallback_reason"] is None
                files |= {f"{dialect}/{path.name}": path.read_bytes() for path in sorted(out.iterdir())}
            runs.append((files, summary["duration_s"]))
    (alone, alone_duration), (loaded, loaded_duration) = runs
    assert len(alone) == 4
    assert alone == loaded
    assert alone_duration == loaded_duration
