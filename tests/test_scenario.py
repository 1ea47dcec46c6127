"""Scenario TOML files: the shipped swap, and every bad-file case."""

from __future__ import annotations

import pytest

from tests.conftest import REPO
from topology import Position
from trajgen.errors import ScenarioError
from trajgen.scenario import default_scenario, load_scenario

SWAP_FILE = REPO / "examples" / "swap.toml"
GOOD = SWAP_FILE.read_text()


def test_example_file_is_the_built_in_default():
    assert (REPO / "trajgen" / "data" / "swap.toml").read_text() == GOOD
    shipped = default_scenario()
    from_file = load_scenario(SWAP_FILE)
    assert (shipped.track, shipped.limits, shipped.start, shipped.goal) == (
        from_file.track,
        from_file.limits,
        from_file.start,
        from_file.goal,
    )


def test_swap_scenario_contents():
    scenario = load_scenario(SWAP_FILE)
    assert scenario.track.names == ("A", "B", "C")
    assert scenario.track.angles_deg == (90.0, 210.0, 330.0)
    assert scenario.names == ("agv1", "agv2")
    assert scenario.limits.min_separation == 1.5
    assert scenario.limits.first.max_jerk == 1.0
    assert scenario.start.first == Position("A", 10.0)
    assert scenario.goal == scenario.start.swapped()


def _write(tmp_path, text):
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        pytest.param(
            "[safety]",
            "[safety]\nspeed = 3",
            r"\[safety\] has unknown key\(s\) \['speed'\]",
            id="unknown-key",
        ),
        pytest.param(
            "[track]",
            "[track]\nlanes = 2",
            r"\[track\] has unknown key\(s\) \['lanes'\]",
            id="unknown-track-key",
        ),
        pytest.param(
            'name = "agv1"',
            'name = "agv1"\ncolour = "red"',
            r"\[\[vehicle\]\] 1 has unknown key",
            id="unknown-vehicle-key",
        ),
        pytest.param(
            "min_separation = 1.5",
            "",
            r"\[safety\] is missing required key\(s\) \['min_separation'\]",
            id="missing-separation",
        ),
        pytest.param(
            'goal = "B:10.0"',
            "",
            r"\[\[vehicle\]\] 1 is missing required key\(s\) \['goal'\]",
            id="missing-goal",
        ),
        pytest.param(
            'max_jerk = 1.0\nstart = "A',
            'max_jerk = "fast"\nstart = "A',
            r"\[\[vehicle\]\] 1 max_jerk must be a number, got str 'fast'",
            id="wrong-type",
        ),
        pytest.param(
            "min_separation = 1.5",
            "min_separation = true",
            "min_separation must be a number, got bool",
            id="bool-number",
        ),
        pytest.param(
            'start = "A:10.0"',
            'start = "A=10"',
            r"\[\[vehicle\]\] 1 start: position 'A=10' is malformed",
            id="malformed-position",
        ),
        pytest.param(
            'start = "A:10.0"', 'start = "D:1"', r"\[\[vehicle\]\] 1 start: unknown leg 'D'", id="unknown-leg"
        ),
        pytest.param(
            'start = "A:10.0"',
            'start = "A:12"',
            r"start: position s=12\.0 m is beyond the end of leg 'A'",
            id="beyond-leg",
        ),
        pytest.param(
            'start = "A:10.0"',
            "start = 10",
            r"start must be a string like 'A:10\.0' or 'O', got int 10",
            id="position-not-string",
        ),
        pytest.param(
            "max_velocity = 1.0",
            "max_velocity = -1.0",
            r"\[\[vehicle\]\] 1: max_velocity must be > 0 m/s, got -1\.0",
            id="negative-limit",
        ),
        pytest.param("C = 10.0 }", "C = 0.0 }", r"\[track\]: length of leg 'C' must be > 0 m", id="zero-leg"),
        pytest.param(
            "C = 10.0 }",
            "C = 10.0, D = 3.0, E = 3.0, F = 3.0, G = 3.0, H = 3.0, I = 3.0 }",
            r"\[track\]: a track has 3 to 8 legs, got 9",
            id="nine-legs",
        ),
        pytest.param(
            "min_separation = 1.5",
            "min_separation = 12.0",
            r"min_separation 12\.0 m exceeds the shortest leg 10\.0 m",
            id="separation-too-large",
        ),
        pytest.param(
            'goal = "A:10.0"',
            'goal = "B:9.0"',
            r"goal positions \(B:10, B:9\) are 1\.0 m apart",
            id="too-close-at-goal",
        ),
        pytest.param(
            'name = "agv2"', 'name = "agv1"', "name 'agv1' is used by both vehicles", id="duplicate-name"
        ),
        pytest.param(
            'name = "agv2"',
            'name = "../agv2"',
            "name '../agv2' is not a portable file name",
            id="unsafe-name",
        ),
        pytest.param(
            'name = "agv2"', 'name = "agv2\\n"', r"name 'agv2\\n' is not a portable file name", id="newline"
        ),
        pytest.param(
            'name = "agv2"', 'name = "NUL"', "'NUL' is a reserved device name on Windows", id="reserved"
        ),
        pytest.param(
            'name = "agv2"', 'name = "AGV1"', r"'AGV1' is used by both vehicles \(case ignored\)", id="case"
        ),
        pytest.param('name = "agv2"', 'name = "x"', "", id="fine-name"),
        pytest.param(
            "A = 10.0,",
            "A = 1e-300,",
            r"leg 'A' is 1e-300 m long: expected 0\.001 to 100000 m",
            id="tiny-leg",
        ),
        pytest.param(
            "max_velocity = 1.0",
            "max_velocity = 1e9",
            r"max_velocity is 1000000000\.0: expected 0\.0001 to 100",
            id="fast",
        ),
        pytest.param("[track]", "[track", "not valid TOML", id="bad-toml"),
    ],
)
def test_bad_scenario_files(tmp_path, old, new, match):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1) if "agv2" not in old else _replace_last(GOOD, old, new))
    if not match:  # a control: the edit alone is fine
        assert load_scenario(path).names[1] == "x"
        return
    with pytest.raises(ScenarioError, match=match) as caught:
        load_scenario(path)
    assert str(path) in str(caught.value)  # the message names the file


def _replace_last(text: str, old: str, new: str) -> str:
    head, _, tail = text.rpartition(old)
    return head + new + tail


def test_exactly_two_vehicles(tmp_path):
    one = GOOD[: GOOD.rindex("[[vehicle]]")]
    with pytest.raises(ScenarioError, match=r"expected exactly two \[\[vehicle\]\] tables, got 1"):
        load_scenario(_write(tmp_path, one))
    three = GOOD + GOOD[GOOD.rindex("[[vehicle]]") :].replace("agv2", "agv3")
    with pytest.raises(ScenarioError, match="got 3"):
        load_scenario(_write(tmp_path, three))


def test_missing_file_is_a_scenario_error(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read the scenario file"):
        load_scenario(tmp_path / "absent.toml")
