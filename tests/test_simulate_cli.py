"""``trajgen simulate``: fault specs refused before anything runs, the trace, the plot and the exit status.

On the demo swap, and under faults on the built-in 4-way crossing.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import re

import numpy as np
import pytest

import trajgen.simulation_pipeline
from tests.conftest import REPO
from tests.support.star_scenarios import CROSSING, read_csv
from topology import JUNCTION_INDEX
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main
from trajgen.errors import InputError
from trajgen.execution.faults import FaultError
from trajgen.execution.goals import schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.plots import plot_simulation, png_bytes
from trajgen.scenario import load_scenario
from trajgen.simulation_pipeline import format_simulation, run_simulation

pytestmark = pytest.mark.slow


def simulation_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_simulation(...)``."""
    return png_bytes(plot_simulation(*arguments, **options))


SWAP = str(REPO / "examples" / "swap.toml")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
HEADER = b"t_s;axis_m;v_mps;a_mps2;j_mps3;leg;s_m;x_m;y_m\r\n"
SUMMARY_KEYS = {
    "reached_goal",
    "makespan_s",
    "planned_s",
    "holds",
    "emergency_brakes",
    "time_lost_s",
    "min_separation_m",
    "certified_separation_m",
    "velocity_ratio",
    "acceleration_ratio",
    "jerk_ratio",
    "replans",
    "rejected_goals",
    "violations",
    "separation_violations",
    "limit_violations",
    "cycles",
    "faults",
    "events",
    "files",
}


@dataclasses.dataclass
class Run:
    status: int
    out: str
    err: str
    result: object
    trace: object
    plot: object


@pytest.fixture(scope="module")
def stopped_run(tmp_path_factory):
    """The swap with agv1 stopped for 3 s at 8 s, through the CLI with --trace, --plot and --json."""
    folder = tmp_path_factory.mktemp("stopped")
    trace, plot = folder / "trace", folder / "plot"
    results = []

    def recording(*args, **kwargs):
        result, spool = simulate(*args, **kwargs)
        results.append(result)
        return result, spool

    out, err = io.StringIO(), io.StringIO()
    argv = [
        "simulate",
        SWAP,
        "--fault",
        "stop:agv1@8+3",
        "--trace",
        str(trace),
        "--plot",
        str(plot),
        "--json",
    ]
    with (
        pytest.MonkeyPatch.context() as patch,
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        patch.setattr(trajgen.simulation_pipeline, "simulate", recording)
        status = main(argv)
    assert len(results) == 1
    return Run(status, out.getvalue(), err.getvalue(), results[0], trace, plot)


def test_a_stop_is_recovered_from_exit_0_and_the_summary_has_every_key(stopped_run):
    assert stopped_run.status == EXIT_OK, stopped_run.err
    summary = json.loads(stopped_run.out)
    assert set(summary) >= SUMMARY_KEYS
    assert summary["reached_goal"] is True
    assert summary["violations"] == 0
    assert summary["faults"] == ["stop:agv1@8+3"]
    # a 3 s stop costs at most its own length plus the slack (often nothing: re-timing catches up)
    assert summary["makespan_s"] <= summary["planned_s"] + 3.0 + 3.0 * (1.0 / 0.5 + 0.5 / 1.0) + 1.0
    assert summary["replans"] == 0
    assert summary["emergency_brakes"] == 0
    assert summary["min_separation_m"] >= 1.5
    assert summary["files"] == [
        str(stopped_run.trace / "agv1.csv"),
        str(stopped_run.trace / "agv2.csv"),
        str(stopped_run.plot / "simulation.png"),
    ]


@pytest.mark.parametrize("name", ["agv1", "agv2"])
def test_the_trace_is_one_crlf_csv_row_per_cycle_ending_at_the_makespan(stopped_run, name):
    data = (stopped_run.trace / f"{name}.csv").read_bytes()
    summary = json.loads(stopped_run.out)
    assert data.startswith(HEADER)
    assert data.endswith(b"\r\n")
    assert data.count(b"\n") == data.count(b"\r\n")  # CRLF after every line, no bare LF
    lines = data.decode("ascii").split("\r\n")[1:-1]
    assert len(lines) == summary["cycles"] + 1  # t = 0, then one row per control period
    assert float(lines[-1].split(";")[0]) == pytest.approx(summary["makespan_s"], abs=1e-6)
    assert float(lines[0].split(";")[0]) == 0.0


def test_the_plot_is_a_png_and_only_the_asked_files_are_written(stopped_run):
    assert (stopped_run.plot / "simulation.png").read_bytes().startswith(PNG_MAGIC)
    assert sorted(p.name for p in stopped_run.trace.iterdir()) == ["agv1.csv", "agv2.csv"]
    assert sorted(p.name for p in stopped_run.plot.iterdir()) == ["simulation.png"]


def test_the_human_summary_names_outcome_margins_and_events(stopped_run):
    summary = {**stopped_run.result.summary(), "files": ["out/agv1.csv"]}
    text = format_simulation(summary, min_separation=1.5)
    assert text.startswith("reached goal: yes")
    assert f"planned {stopped_run.result.planned_s:.3f} s" in text
    assert "(required 1.5 m)" in text
    assert "violations: 0" in text
    assert "fault: stop:agv1@8+3" in text
    events = [line for line in text.splitlines() if line.startswith("event")]
    assert len(events) == len(stopped_run.result.events) > 0
    assert text.splitlines()[-1] == "wrote out/agv1.csv"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        pytest.param({"reached_goal": False}, "did not reach the goal", id="missed-goal"),
        pytest.param({"separation_violations": 2}, "had 2 violations", id="violations"),
    ],
)
def test_a_failed_run_exits_1_and_still_writes_its_evidence(
    stopped_run, tmp_path, capsys, monkeypatch, change, message
):
    failed = dataclasses.replace(stopped_run.result, **change)
    monkeypatch.setattr(trajgen.simulation_pipeline, "simulate", lambda *args, **kwargs: (failed, None))
    plot = tmp_path / "plot"
    assert main(["simulate", SWAP, "--plot", str(plot)]) == EXIT_FAILURE
    captured = capsys.readouterr()
    assert message in captured.err
    assert "reached goal:" in captured.out  # the summary is printed all the same
    assert (plot / "simulation.png").read_bytes().startswith(PNG_MAGIC)


def test_the_trace_takes_the_csv_dialect(stopped_run, tmp_path, capsys):
    trace = tmp_path / "trace"
    argv = ["simulate", SWAP, "--trace", str(trace), "--units", "mm", "--delimiter", "tab", "--decimal", ","]
    assert main(argv) == EXIT_OK
    assert "reached goal: yes" in capsys.readouterr().out
    header, first = (trace / "agv2.csv").read_bytes().split(b"\r\n")[:2]
    assert header.split(b"\t")[:3] == [b"t_s", b"axis_mm", b"v_mmps"]
    assert first.startswith(b"0,000000\t")


#: Bad fault specs: each refused with a message that quotes the spec and says what was expected.
BAD_FAULTS = [
    pytest.param("stop-agv1", [], "is malformed: expected KIND:NAME@T+D", id="malformed"),
    pytest.param("halt:agv1@5+3", [], "unknown kind 'halt'", id="unknown-kind"),
    pytest.param("stop:agv9@5+3", [], "unknown vehicle 'agv9'", id="unknown-vehicle"),
    pytest.param("slow:agv1@5=1.0", [], "below agv1's max_velocity 1.0 m/s", id="slow-at-max-velocity"),
    pytest.param("slow:agv2@5=1.5", [], "below agv2's max_velocity 1.0 m/s", id="slow-above-max-velocity"),
    pytest.param("lag:agv1@5=250", [], "lag 250.0 ms out of range", id="lag-over-200-ms"),
    pytest.param("jump:agv1@5=0.06", [], "jump 0.06 m out of range", id="jump-beyond-margin"),
    pytest.param(
        "jump:agv1@5=-0.03", ["--position-margin", "0.02"], "|DS| <= 0.02 m", id="jump-beyond-given-margin"
    ),
    pytest.param("goal:agv1@5=D:3", [], "unknown leg 'D'", id="goal-unknown-leg"),
    pytest.param("goal:agv1@5=A:12", [], "beyond the end of leg 'A'", id="goal-beyond-leg-end"),
    pytest.param("stop:agv1@-1+3", [], "time -1.0 s out of range", id="negative-time"),
    pytest.param("stop:agv1@5=3", [], "stop takes NAME@T+D", id="stop-without-duration"),
]


@pytest.fixture
def nothing_computed(monkeypatch):
    """Fail the test if the simulation is started."""

    def refuse(*args, **kwargs):
        raise AssertionError("simulate ran although the input was bad")

    monkeypatch.setattr(trajgen.simulation_pipeline, "simulate", refuse)


@pytest.mark.usefixtures("nothing_computed")
@pytest.mark.parametrize(("spec", "extra", "message"), BAD_FAULTS)
def test_a_bad_fault_exits_2_naming_the_spec_with_nothing_written(tmp_path, capsys, spec, extra, message):
    trace, plot = tmp_path / "trace", tmp_path / "plot"
    argv = ["simulate", SWAP, "--fault", "stop:agv2@1+1", "--fault", spec, "--trace", str(trace)]
    assert main([*argv, "--plot", str(plot), "--json", *extra]) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"fault {spec!r}" in captured.err
    assert message in captured.err
    assert not trace.exists()
    assert not plot.exists()


@pytest.mark.usefixtures("nothing_computed")
@pytest.mark.parametrize(("spec", "extra", "message"), BAD_FAULTS)
def test_run_simulation_raises_a_fault_error_naming_the_spec(tmp_path, spec, extra, message):
    margin = float(extra[1]) if extra else 0.05
    with pytest.raises(FaultError, match=re.escape(f"fault {spec!r}") + ".*" + re.escape(message)):
        run_simulation(load_scenario(SWAP), [spec], position_margin=margin, trace_dir=tmp_path / "t")
    assert not (tmp_path / "t").exists()


@pytest.mark.usefixtures("nothing_computed")
@pytest.mark.parametrize(
    ("argv", "message"),
    [
        pytest.param(
            ["--period", "0.5"], "control period must be 0.002 to 0.1 s, got 0.5", id="period-too-long"
        ),
        pytest.param(["--period", "nan"], "control period (seconds)", id="period-not-finite"),
        pytest.param(
            ["--position-margin", "0"], "position margin (m) must be a finite number > 0", id="margin-0"
        ),
        pytest.param(["--method", "fast"], "method 'fast' is unknown", id="unknown-method"),
        pytest.param(["--delimiter", ",", "--decimal", ","], "both ','", id="same-marks"),
        pytest.param(["--sample-period", "0.1"], "unrecognized arguments: --sample-period", id="no-sampling"),
        pytest.param(["--max-rows", "10"], "unrecognized arguments: --max-rows", id="no-row-limit"),
    ],
)
def test_bad_options_exit_2_with_nothing_written(tmp_path, capsys, argv, message):
    trace = tmp_path / "trace"
    assert main(["simulate", SWAP, "--trace", str(trace), *argv]) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert message in captured.err
    assert not trace.exists()


@pytest.mark.usefixtures("nothing_computed")
def test_a_bad_scenario_exits_2_naming_the_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text((REPO / "examples" / "swap.toml").read_text().replace("max_jerk = 1.0", "max_jerk = 0", 1))
    assert main(["simulate", str(bad), "--trace", str(tmp_path / "trace")]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert str(bad) in err
    assert "max_jerk must be > 0" in err
    assert not (tmp_path / "trace").exists()


@pytest.mark.usefixtures("nothing_computed")
@pytest.mark.parametrize("option", ["--trace", "--plot"])
def test_an_output_folder_that_is_a_file_exits_2_before_computing(tmp_path, capsys, option):
    blocker = tmp_path / "taken"
    blocker.write_bytes(b"keep")
    assert main(["simulate", SWAP, option, str(blocker)]) == EXIT_BAD_INPUT
    assert "exists and is not a folder" in capsys.readouterr().err
    assert blocker.read_bytes() == b"keep"


@pytest.mark.parametrize(
    ("result", "min_separation", "match"),
    [
        pytest.param("run", 1.5, "expects a SimulationResult, got str", id="not-a-result"),
        pytest.param(None, -1.0, r"min_separation \(m\) must be a finite number >= 0", id="negative-minimum"),
    ],
)
def test_render_simulation_refuses_bad_arguments(stopped_run, result, min_separation, match):
    result = stopped_run.result if result is None else result
    with pytest.raises(InputError, match=match):
        simulation_png(result, names=("agv1", "agv2"), min_separation=min_separation)


@pytest.mark.parametrize("method", ["exact", "toppra"])
def test_the_plot_data_hold_each_vehicles_frontier_and_no_vehicle_passes_it(method):
    """What the plot draws as each vehicle's frontier: finite where a conflict binds, never overrun."""
    scenario = load_scenario(SWAP)
    verified = schedule_for_execution(scenario, method=method)
    result, _ = simulate(scenario, parse_faults(scenario, ["stop:agv1@8+3"]), verified=verified)
    plot = result.plot
    t, travel, frontier = plot["t"], plot["travel"], plot["frontier"]
    assert frontier.shape == travel.shape == (2, t.size)
    bound = np.isfinite(frontier)
    assert bound.any(axis=1).all()  # on the swap each vehicle follows at some conflict
    assert np.all(travel[bound] <= frontier[bound] + 1e-6)
    # agv1's stop (8 s to 11 s) holds agv2 back: its frontier stops advancing while agv1 stands
    standing = (t >= 8.5) & (t <= 11.0) & bound[1]
    assert standing.any()
    assert np.ptp(frontier[1, standing]) < 1e-6
    # and the frontier moves on once agv1 drives again
    assert np.nanmax(np.where(bound[1] & (t > 11.5), frontier[1], np.nan)) > frontier[1, standing][0] + 0.1


def test_a_fault_due_after_the_run_ended_is_reported_as_never_applied(capsys):
    argv = ["simulate", SWAP, "--method", "exact", "--fault", "stop:agv1@500+3", "--json"]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    # the run ends when both vehicles are at their goals: the plan's 67.5 s, not the fault's 503 s
    assert summary["makespan_s"] == pytest.approx(67.5, abs=0.011)
    assert summary["time_lost_s"] == pytest.approx(0.0, abs=0.011)
    assert summary["cycles"] <= 6752
    assert summary["unapplied_faults"] == ["stop:agv1@500+3"]
    assert main(argv[:-1]) == EXIT_OK
    assert "fault: stop:agv1@500+3 (never applied: the run ended at 67.5" in capsys.readouterr().out


def test_events_name_the_vehicles_by_their_names(capsys):
    assert main(["simulate", SWAP, "--method", "exact", "--fault", "stop:agv1@20+5", "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    details = " ".join(event["detail"] for event in summary["events"])
    assert "agv1 is off its setpoints" in details
    assert "vehicle 1" not in details
    assert "vehicle 2" not in details
    assert summary["unapplied_faults"] == []


def test_a_run_of_repeated_events_prints_as_one_line_with_its_count():
    from trajgen.simulation_pipeline import format_simulation

    events = [
        {"t_s": 10.0 + 0.01 * k, "kind": "retime", "detail": "agv2 holds: the braking check"}
        for k in range(784)
    ]
    events.append({"t_s": 30.0, "kind": "done", "detail": "both vehicles at their goals"})
    summary = {
        "reached_goal": True,
        "method": "optimal",
        "computed_by": "optimal",
        "fallback_reason": None,
        "time_limit_reached": False,
        "makespan_s": 30.0,
        "planned_s": 27.5,
        "time_lost_s": 2.5,
        "min_separation_m": 1.6,
        "certified_separation_m": 1.6,
        "velocity_ratio": 1.0,
        "acceleration_ratio": 1.0,
        "jerk_ratio": 1.0,
        "replans": 0,
        "rejected_goals": 0,
        "violations": 0,
        "separation_violations": 0,
        "limit_violations": 0,
        "cycles": 3000,
        "faults": [],
        "events": events,
    }
    lines = [line for line in format_simulation(summary, min_separation=1.5).splitlines() if "event" in line]
    assert lines == [
        "event     10.000 s  retime: agv2 holds: the braking check (x784, until 17.830 s)",
        "event     30.000 s  done: both vehicles at their goals",
    ]


def test_run_simulation_returns_a_named_result_with_its_files(tmp_path):
    from trajgen import Exact
    from trajgen.simulation_pipeline import SimulationRun

    run = run_simulation(load_scenario(SWAP), ["stop:agv1@8+3"], method=Exact(), trace_dir=tmp_path)
    assert isinstance(run, SimulationRun)
    assert run.result.reached_goal
    assert run.files == (tmp_path / "agv1.csv", tmp_path / "agv2.csv")
    assert run.summary()["files"] == [str(tmp_path / "agv1.csv"), str(tmp_path / "agv2.csv")]
    assert run.summary()["makespan_s"] == round(run.result.makespan_s, 6)


# -- faults on a 4-way crossing ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("method", "faults"),
    [
        ("optimal", ["stop:agv2@6+4"]),
        ("optimal", ["stop:agv1@10+5"]),
        ("exact", ["stop:agv2@20+10", "goal:agv1@30=W:10"]),
    ],
    ids=["optimal-stop-agv2", "optimal-stop-agv1", "exact-stop-and-new-goal-on-W"],
)
def test_simulate_under_faults_on_a_crossing_keeps_the_separation(tmp_path, capsys, method, faults):
    argv = ["simulate", str(CROSSING), "--method", method, "--trace", str(tmp_path), "--json"]
    for fault in faults:
        argv += ["--fault", fault]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["reached_goal"] is True
    assert summary["violations"] == 0
    assert summary["min_separation_m"] >= 1.5
    assert summary["certified_separation_m"] >= 1.5
    # the plan's order is kept: only a new goal re-plans, a stop never does
    new_goals = sum(f.startswith("goal:") for f in faults)
    assert summary["replans"] == new_goals
    # the executed motion, traced: legs 1-based up to 4, never closer than the separation
    traces = [read_csv(tmp_path / f"{name}.csv") for name in ("agv1", "agv2")]
    for columns in traces:
        assert set(columns["leg"].astype(int).tolist()) <= {0, 1, 2, 3, 4}
    legs = [c["leg"].astype(int) - 1 for c in traces]
    same = (legs[0] == legs[1]) & (legs[0] != JUNCTION_INDEX)
    gap = np.where(same, np.abs(traces[0]["s_m"] - traces[1]["s_m"]), traces[0]["s_m"] + traces[1]["s_m"])
    assert gap.min() >= 1.5
    if any(f.startswith("goal:") for f in faults):
        assert traces[0]["leg"][-1] == 2  # W:10
        assert traces[0]["s_m"][-1] == pytest.approx(10.0, abs=1e-3)
        replan = next(
            e["detail"] for e in summary["events"] if "new goal" in e["detail"] and e["kind"] == "replan"
        )
        assert "route on G_4" in replan
