"""The command line: output, JSON summary and exit status."""

from __future__ import annotations

import json

import pytest

from trajgen.cli import EXIT_BAD_INPUT, EXIT_OK, main


def test_demo_prints_the_worked_example_route(capsys):
    assert main(["demo"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "counterclockwise" in out
    assert "(A:1, C:1)" in out
    assert "(B:1, A:1)" in out


def test_plan_json_summary(capsys):
    argv = ["plan", "--legs", "A=10,B=8,C=15", "--start", "A:3", "B:2", "--goal", "C:4", "C:9"]
    assert main([*argv, "--min-separation", "1.5", "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["instruction"] == "shortest"
    assert summary["regions"] == ["Q(A,B)", "Q(A,C)", "T(C,1)"]
    assert summary["waypoints"][1][1] == {"leg": "B", "s_m": pytest.approx(20 / 3)}


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        pytest.param(
            ["plan", "--legs", "A=10,B=8", "--start", "A:1", "B:1", "--goal", "A:2", "B:2"],
            "exactly 3 legs",
            id="two-legs",
        ),
        pytest.param(
            ["plan", "--legs", "A=10,B=8,C=x", "--start", "A:1", "B:1", "--goal", "A:2", "B:2"],
            "'C=x' is malformed",
            id="bad-length",
        ),
        pytest.param(
            ["plan", "--legs", "A=10,B=8,C=5", "--start", "A:1", "B:1", "--goal", "D:2", "B:2"],
            "unknown leg 'D'",
            id="unknown-leg",
        ),
        pytest.param(
            [
                "plan",
                "--legs",
                "A=10,B=8,C=5",
                "--start",
                "A:1",
                "A:1.2",
                "--goal",
                "A:2",
                "B:2",
                "--min-separation",
                "1",
            ],
            "0.19999999999999996 m apart",
            id="too-close",
        ),
        pytest.param(["nonsense"], "invalid choice", id="unknown-command"),
    ],
)
def test_bad_input_exits_2_with_a_message(argv, match, capsys):
    assert main(argv) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert match in captured.err
