"""The command line: output, JSON summary, files, and exit status 0 / 1 / 2.

On the demo swap (a Y, ``legs3``) and the built-in 4-way crossing (``legs4``): a test of a command
every junction runs alike is parametrized over the number of legs.
"""

from __future__ import annotations

import json

import pytest

import trajgen.cli
from tests.conftest import REPO
from tests.support.helpers import RUN_FILES, legs_cases, legs_id
from tests.support.star_scenarios import CROSSING
from trajgen import builtin_scenario
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main
from trajgen.export.plc.check import check_profiles

SWAP = str(REPO / "examples" / "swap.toml")
#: The scenario of each number of legs: the demo swap, the built-in 4-way crossing.
SCENARIOS = {3: SWAP, 4: str(CROSSING)}


#: What ``trajgen plan`` prints, by number of legs.
PLAN_TEXT = {
    3: ["counterclockwise", "(A:10, C:10)"],
    4: [
        "instruction: shortest (of shortest, two-tied, many-tied on 4 legs)",
        "class: planned (shortest route on G_4)",
        "length on G_4: 60 m (of 240 m in all)",
        "(E:10, S:10)",  # agv1 waits in the side leg E
    ],
}


@pytest.mark.parametrize("legs", legs_cases(sorted(PLAN_TEXT), slow={4}))
def test_plan_prints_the_route(capsys, legs):
    assert main(["plan", SCENARIOS[legs]]) == EXIT_OK
    out = capsys.readouterr().out
    for line in PLAN_TEXT[legs]:
        assert line in out


#: What ``trajgen plan --json`` says, by number of legs: some keys, and the third waypoint.
PLAN_JSON = {
    3: (
        {
            "instruction": "counterclockwise",
            "regions": ["Q(A,B)", "Q(A,C)", "Q(B,C)", "Q(B,A)"],
        },
        [{"leg": "A", "s_m": 10.0}, {"leg": "C", "s_m": 10.0}],
    ),
    4: (
        {
            "legs": 4,
            "class": "shortest route on G_4",
            "way_round": "not-applicable",
            "arc_length_m": 60.0,
            "regions": ["Q(N,S)", "Q(E,S)", "Q(E,N)", "Q(S,N)"],
        },
        [{"leg": "E", "s_m": 10.0}, {"leg": "S", "s_m": 10.0}],
    ),
}


@pytest.mark.parametrize("legs", legs_cases(sorted(PLAN_JSON), slow={4}))
def test_plan_json_summary(capsys, legs):
    assert main(["plan", SCENARIOS[legs], "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    expected, third = PLAN_JSON[legs]
    assert {key: summary[key] for key in expected} == expected
    assert summary["waypoints"][2] == third


#: The class ``trajgen schedule --json`` and ``trajgen check`` name, where the route has a name of its own.
ROUTE_CLASS = {4: "shortest route on G_4"}


@pytest.mark.slow
@pytest.mark.parametrize(
    ("legs", "method"),
    [(3, "exact"), (3, "toppra"), (3, "optimal"), (4, "exact"), (4, "toppra")],
    ids=["legs3-exact", "legs3-toppra", "legs3-optimal", "legs4-exact", "legs4-toppra"],
)
def test_schedule_writes_verified_csv_and_plots_that_check_passes(tmp_path, capsys, legs, method):
    scenario = SCENARIOS[legs]
    csv_dir, plot_dir = tmp_path / "csv", tmp_path / "plots"
    argv = ["schedule", scenario, "--method", method, "--csv", str(csv_dir), "--json"]
    plots = legs == 3  # (the pictures of a star: test_pictures.py)
    if plots:
        argv += ["--plot", str(plot_dir)]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["method"] == method
    assert summary["verified"] is True
    assert summary["duration_s"] > 0
    assert summary["worst_margins"]["separation_margin_m"] >= 0
    assert summary["jerk_limited"] is (method != "toppra")
    assert summary["fallback_reason"] is None
    assert sorted(p.name for p in csv_dir.iterdir()) == ["agv1.csv", "agv2.csv"]
    if plots:
        for name in ("speed.png", "separation.png", "coordination.png"):
            assert (plot_dir / name).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    if legs in ROUTE_CLASS:
        assert summary["route"]["class"] == ROUTE_CLASS[legs]
    # and the files pass ``trajgen check`` (toppra's record that they do not limit jerk: not checked)
    assert main(["check", scenario, "--csv", str(csv_dir)]) == EXIT_OK
    text = capsys.readouterr().out
    assert ("jerk not checked" in text) is (method == "toppra")
    if legs in ROUTE_CLASS:
        assert f"class: planned ({ROUTE_CLASS[legs]})" in text
    assert "PASS" in text


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


#: ``trajgen demo`` by number of legs: (options, built-in scenario, first line, class line). The swap
#: is the default scenario (and optimal the default method).
DEMOS = {
    3: (
        [],
        "swap",
        "Demo: the built-in scenario <built-in swap.toml> (two AGVs swap ends of legs A and B).",
        None,
    ),
    4: (
        ["--scenario", "crossing", "--method", "exact"],
        "crossing",
        "Demo: the built-in scenario <built-in crossing.toml> (a 4-way crossing: two AGVs cross from N to S "
        "and S to N, one waits in a side leg).",
        "class: planned (shortest route on G_4)",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("legs", sorted(DEMOS), ids=legs_id)
def test_demo_runs_a_built_in_scenario_end_to_end(tmp_path, capsys, legs):
    options, name, first_line, class_line = DEMOS[legs]
    output = tmp_path / "demo"
    assert main(["demo", *options, "--output", str(output)]) == EXIT_OK
    out = capsys.readouterr().out
    assert out.startswith(first_line)
    assert "verified: True" in out
    if class_line is not None:
        assert class_line in out
    assert sorted(p.name for p in output.iterdir()) == RUN_FILES
    for picture in ("configuration.png", "layout.png", "speed.png"):
        assert (output / picture).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    verdict = check_profiles(builtin_scenario(name), output)
    assert verdict.passed, verdict.failures
    assert verdict.check.report.min_separation >= 1.5 - 1e-9


@pytest.mark.slow
def test_demo_refuses_an_unknown_scenario(tmp_path, capsys):
    assert main(["demo", "--scenario", "roundabout", "--output", str(tmp_path / "out")]) == EXIT_BAD_INPUT
    assert "built-in scenario 'roundabout' is unknown: expected one of ['swap', 'crossing', 'h']" in (
        capsys.readouterr().err
    )
    assert not (tmp_path / "out").exists()


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
