"""The command line: output, JSON summary, files, and exit status 0 / 1 / 2."""

from __future__ import annotations

import json

import pytest

import trajgen.cli
from tests.conftest import REPO
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main

SWAP = str(REPO / "examples" / "swap.toml")


def test_plan_prints_the_route(capsys):
    assert main(["plan", SWAP]) == EXIT_OK
    out = capsys.readouterr().out
    assert "counterclockwise" in out
    assert "(A:10, C:10)" in out


def test_plan_json_summary(capsys):
    assert main(["plan", SWAP, "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["instruction"] == "counterclockwise"
    assert summary["regions"] == ["Q(A,B)", "Q(A,C)", "Q(B,C)", "Q(B,A)"]
    assert summary["waypoints"][2] == [{"leg": "A", "s_m": 10.0}, {"leg": "C", "s_m": 10.0}]


@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
def test_schedule_writes_verified_csv_and_plots(tmp_path, capsys, method):
    csv_dir, plot_dir = tmp_path / "csv", tmp_path / "plots"
    argv = ["schedule", SWAP, "--method", method, "--csv", str(csv_dir), "--plot", str(plot_dir), "--json"]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["method"] == method
    assert summary["verified"] is True
    assert summary["duration_s"] > 0
    assert summary["worst_margins"]["separation_margin_m"] >= 0
    assert summary["jerk_limited"] is (method != "toppra")
    assert summary["fallback_reason"] is None
    assert sorted(p.name for p in csv_dir.iterdir()) == ["agv1.csv", "agv2.csv"]
    for name in ("speed.png", "separation.png", "coordination.png"):
        assert (plot_dir / name).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_schedule_human_summary_and_options(tmp_path, capsys):
    argv = [
        "schedule",
        SWAP,
        "--csv",
        str(tmp_path),
        "--units",
        "mm",
        "--decimal",
        ",",
        "--delimiter",
        "tab",
        "--sample-period",
        "0.5",
    ]
    assert main(argv) == EXIT_OK
    out = capsys.readouterr().out
    assert "verified: True" in out
    # the default method is optimal: the swap takes well under half the exact 67.5 s
    assert "method: optimal" in out
    duration = float(out.split("duration: ")[1].split(" s")[0])
    assert 22.5 <= duration <= 0.5 * 67.5
    assert (tmp_path / "agv1.csv").read_text().splitlines()[0].split("\t")[1] == "axis_mm"


def test_demo_runs_the_default_scenario_end_to_end(tmp_path, capsys):
    output = tmp_path / "demo"
    assert main(["demo", "--output", str(output)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "verified: True" in out
    assert sorted(p.name for p in output.iterdir()) == [
        "agv1.csv",
        "agv2.csv",
        "configuration.png",
        "coordination.png",
        "separation.png",
        "speed.png",
    ]


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        pytest.param(["plan", "absent.toml"], "cannot read the scenario file", id="missing-file"),
        pytest.param(["schedule", SWAP, "--method", "fast"], "method 'fast' is unknown", id="bad-method"),
        pytest.param(
            ["schedule", SWAP, "--sample-period", "-1"], "sample period must be > 0 s", id="bad-period"
        ),
        pytest.param(["schedule", SWAP, "--delimiter", ",", "--decimal", ","], "both ','", id="same-marks"),
        pytest.param(["nonsense"], "invalid choice", id="unknown-command"),
        pytest.param(["schedule"], "the following arguments are required: scenario", id="missing-argument"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, argv, match, capsys):
    output = tmp_path / "out"
    extra = ["--csv", str(output)] if argv[0] == "schedule" and len(argv) > 1 else []
    assert main(argv + extra) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert match in captured.err
    assert not output.exists()


def test_bad_scenario_file_exits_2_naming_the_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text((REPO / "examples" / "swap.toml").read_text().replace("max_jerk = 1.0", "max_jerk = 0", 1))
    assert main(["schedule", str(bad), "--csv", str(tmp_path / "out")]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert str(bad) in err
    assert "max_jerk must be > 0" in err
    assert not (tmp_path / "out").exists()


def test_a_schedule_failing_verification_exits_1_and_writes_nothing(tmp_path, capsys, monkeypatch):
    from tests.support.helpers import too_close
    from trajgen import make_schedule, pipeline

    def broken(route, limits, *, method):
        return too_close(make_schedule(route, limits, method=method))

    monkeypatch.setattr(pipeline, "make_schedule", broken)
    output = tmp_path / "out"
    assert main(["schedule", SWAP, "--csv", str(output), "--plot", str(output)]) == EXIT_FAILURE
    captured = capsys.readouterr()
    assert "failed verification" in captured.err
    assert captured.out == ""
    assert not output.exists()
    assert trajgen.cli.EXIT_FAILURE == 1
