"""Every numbered example runs headless and finishes cleanly.

The examples run in the test process (as ``python examples/NN_name.py`` would run them, with
``__name__ == "__main__"``): a worker imports NumPy, CasADi and matplotlib once for all of them
and shares the solver cache. One example also runs as its own process, exactly as a user starts it.
"""

from __future__ import annotations

import os
import re
import runpy
import subprocess
import sys

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

EXAMPLES = sorted((REPO / "examples").glob("[0-9][0-9]_*.py"))


#: One figure each example must print: (pattern with one number, expected value, tolerance).
FIGURES = {
    "01_plan_a_swap": (r"vehicle 2 drives ([0-9.]+) m", 48.0, 1e-9),
    "02_schedule_and_export": (r"exact makespan: ([0-9.]+) s", 67.5, 0.005),
    "03_optimal_swap": (r"optimal / exact = ([0-9.]+)", 0.4076, 0.0005),
    # the plan keeps 1.5 m + twice the 0.05 m margin; the stopped vehicle never gets closer
    "04_online_stop_in_the_junction": (r"closest approach ([0-9.]+) m", 1.550, 0.003),
    # equal vehicles: the paper's class; both move at once, the waiting one parks only as deep as needed
    "05_unequal_legs": (r"optimal / exact = ([0-9.]+)", 0.364, 0.005),
    # docs/timing.md: 37.45 s in the paper's class, 33.83 s in the other (tests/test_docs_figures.py)
    "06_two_different_vehicles": (r"time saved by the other class: ([0-9.]+) s", 3.62, 0.05),
    # a point moved by 1 cm breaks the velocity (closed form), acceleration and jerk (divided
    # differences), and makes a velocity step no drive follows within 1 mm
    "07_export_for_a_plc_and_check": (r"violations after moving one point by 1 cm: ([0-9]+)", 4, 0),
    # agv2 turns back 1.5 m into C at 13.756 s; only then may agv1 be released through the junction
    "08_vda5050_export": (r"agv1 may pass the junction at t = ([0-9.]+) s", 13.756, 0.02),
    # the 27.51-s optimal swap at 10 frames per second, in real time: a frame every 0.1 s and one at the goal
    "09_animate_the_swap": (r"frames: ([0-9]+) at 10 per second, real time", 277, 1),
    # the head-on crossing: one AGV waits in a side leg; the same 27.51 s against 67.5 s as the Y swap
    "10_four_way_crossing": (r"head-on optimal / exact = ([0-9.]+)", 0.4076, 0.0005),
    # released node by node (a node every metre): at closest, one stands at a node 1.61 m from the other
    "11_live_over_mqtt": (r"closest approach on the true positions: ([0-9.]+) m", 1.610, 0.002),
    # head-on on a line with a passing loop: agv2 takes the loop (11.5 m against the main's 10 m)
    "12_plan_a_track_graph": (r"agv2 drives ([0-9.]+) m", 30.5, 1e-9),
    # the H: 33.586 s optimal (agv1 waits in c) against 51.5 s of moves one at a time
    "13_time_a_track_graph": (r"optimal / exact = ([0-9.]+)", 0.6522, 0.002),
    # the optimal H as orders: released node by node, with the hold nodes at each junction's zone
    "14_export_a_track_graph": (r"the orders with their waits take ([0-9.]+) s", 36.612, 0.01),
    # the exact H in closed loop with a 5-s stop: off the plan's clock both drive in its order at once
    "15_simulate_a_track_graph": (r"the run with the stop takes ([0-9.]+) s", 41.10, 0.05),
    # the H live: agv1 ends at its goal D, placed by its last node alone (its last edge curves)
    "16_live_on_a_track_graph": (r"agv1 stands at D, ([0-9.]+) m from its goal", 0.0, 1e-9),
}


def _check_figure(script, stdout: str) -> None:
    pattern, expected, tolerance = FIGURES[script.stem]
    found = re.search(pattern, stdout)
    assert found, f"{script.name} should print {pattern!r}:\n{stdout}"
    assert float(found.group(1)) == pytest.approx(expected, abs=tolerance)


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(script, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("TRAJGEN_EXAMPLE_OUTPUT", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script)])
    runpy.run_path(str(script), run_name="__main__")
    out = capsys.readouterr().out
    _check_figure(script, out)
    # what a user reads names no array of a schedule (those are in the details, and --verbose)
    assert re.search(r"\bsections\[\d+\]|\.kinematics\.", out) is None, out
    for line in out.splitlines():  # what it wrote, named by absolute paths, is kept in the folder given
        if line.startswith("wrote "):
            path = line.removeprefix("wrote ").split(" (")[0]
            assert os.path.isabs(path), line
            assert os.path.exists(path), line


def test_an_example_runs_as_its_own_process_as_a_user_starts_it(tmp_path):
    """As a user runs it, without TRAJGEN_EXAMPLE_OUTPUT: absolute paths, and nothing left behind."""
    script = REPO / "examples" / "08_vda5050_export.py"
    env = {k: v for k, v in os.environ.items() if k != "TRAJGEN_EXAMPLE_OUTPUT"}
    env |= {"MPLBACKEND": "Agg", "TMPDIR": str(tmp_path)}
    result = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stderr
    _check_figure(script, result.stdout)
    written = [
        line.removeprefix("wrote ") for line in result.stdout.splitlines() if line.startswith("wrote ")
    ]
    assert written
    assert all(os.path.isabs(path) and path.startswith(str(tmp_path)) for path in written), written
    assert list(tmp_path.iterdir()) == []  # its temporary folder is gone


def test_every_example_has_its_figure():
    assert sorted(FIGURES) == [p.stem for p in EXAMPLES]
