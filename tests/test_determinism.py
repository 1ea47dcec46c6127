"""The same scenario gives the same schedule, whatever the load and wherever its NLP came from.

The optimal method's effort is fixed by iteration limits, refinement passes and a tolerance; the
only wall-clock limit is a safety stop far above the usual solve time. These tests run the
command line as a user does, twice: first alone with an empty store of compiled NLPs (every
NLP is built), then all the cases at once, topped up with CPU-bound processes so that every core
stays busy, with the store the first run filled (every NLP is loaded). The CSV files are
byte-identical, and so is ``simulate``'s plan. A forced fallback is reported in the JSON of every
command that plans.
"""

from __future__ import annotations

import concurrent.futures
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
def _every_core_busy(busy: int):
    """CPU-bound processes beside ``busy`` runs of ours, one more than the cores in all, for the block."""
    hogs = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"])
        for _ in range(max(0, (os.cpu_count() or 1) + 1 - busy))
    ]
    try:
        yield
    finally:
        for hog in hogs:
            hog.kill()
        for hog in hogs:
            hog.wait()


def _schedule_and_simulate(scenario: Path, out: Path, store: Path) -> tuple[dict[str, bytes], list[dict]]:
    """A junction's CSV files, and its ``schedule --json`` and ``simulate --json``."""
    summary = json.loads(
        _trajgen(
            "schedule", str(scenario), "--method", "optimal", "--csv", str(out), "--json", store=store
        ).stdout
    )
    simulated = json.loads(_trajgen("simulate", str(scenario), "--json", store=store).stdout)
    files = {path.name: path.read_bytes() for path in sorted(out.iterdir())}
    return files, [summary, simulated]


def _two_dialects(scenario: Path, out: Path, store: Path) -> tuple[dict[str, bytes], list[dict]]:
    """A track graph's generic CSV and SIMATIC tables, and each ``schedule --json``."""
    files, summaries = {}, []
    for dialect in ("generic", "siemens-xy"):
        folder = out / dialect
        arguments = ("schedule", str(scenario), "--method", "optimal", "--csv", str(folder))
        summary = json.loads(_trajgen(*arguments, "--dialect", dialect, "--json", store=store).stdout)
        summaries.append(summary)
        files |= {f"{dialect}/{path.name}": path.read_bytes() for path in sorted(folder.iterdir())}
    return files, summaries


#: name: (the scenario file in a folder, the commands run on it, whether its NLPs are stored). The
#: passing loop's optimal plan solves two classes (agv1 waits on the main line or on the loop) and
#: keeps the faster, as the H's does, in a fraction of the H's time; a track graph's formulation is
#: built for each solve, not stored.
CASES = {
    "swap": (lambda folder: REPO / "examples" / "swap.toml", _schedule_and_simulate, True),
    "crossing": (lambda folder: REPO / "examples" / "crossing.toml", _schedule_and_simulate, True),
    "y": (lambda folder: _scenario("y", folder), _schedule_and_simulate, True),
    "passing-loop": (lambda folder: REPO / "examples" / "graphs" / "passing-loop.toml", _two_dialects, False),
}


def test_the_optimal_plans_are_byte_identical_alone_and_under_load_built_and_loaded(tmp_path):
    """Every case alone with an empty store, then every case at once beside CPU-bound processes.

    The loaded runs of all the cases run at the same time, each the others' load, topped up with
    CPU-bound processes to one more than the cores: every core stays busy without spending a
    core's time on nothing but load.
    """
    runs = {}
    for name, (scenario_of, commands, stored) in CASES.items():
        folder = tmp_path / name
        folder.mkdir()
        runs[name] = (scenario_of(folder), folder / "store")
        alone = commands(runs[name][0], folder / "alone", runs[name][1])
        kept = any(runs[name][1].rglob("*.nlp"))
        assert kept is stored, f"{name}: the first run keeps the NLPs it built: {kept}, expected {stored}"
        runs[name] += (alone,)
    with _every_core_busy(len(CASES)), concurrent.futures.ThreadPoolExecutor(len(CASES)) as pool:
        loaded = dict(
            zip(
                CASES,
                pool.map(
                    lambda name: CASES[name][1](runs[name][0], tmp_path / name / "loaded", runs[name][1]),
                    CASES,
                ),
                strict=True,
            )
        )
    for name, (_scenario_path, _store, (alone_files, alone_summaries)) in runs.items():
        loaded_files, loaded_summaries = loaded[name]
        assert alone_files, name
        assert set(alone_files) == set(loaded_files), name
        for file_name, data in alone_files.items():
            assert data == loaded_files[file_name], f"{name}: {file_name} differs between the runs"
        for summary in (*alone_summaries, *loaded_summaries):
            assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == (
                "optimal",
                "optimal",
                None,
            ), name
            assert summary["time_limit_reached"] is False, name
        if CASES[name][2]:
            assert alone_summaries[0]["solver"]["built"] is True, name
            assert loaded_summaries[0]["solver"]["built"] is False, name
            assert loaded_summaries[0]["solver"]["loaded"] is True, name
        for alone_summary, loaded_summary in zip(alone_summaries, loaded_summaries, strict=True):
            for key in ("duration_s", "planned_s", "makespan_s"):
                assert alone_summary.get(key) == loaded_summary.get(key), f"{name}: {key}"


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
