"""Messages an engineer reads (issue 38, items 6 and 8).

A verifier's failure says in plain words what is wrong: the quantity, its value and limit, the
vehicle, when (seconds) and where on the track. Where it lies in the schedule's arrays
(``sections[1].kinematics.vehicles[0]...``) is in the report's and the error's ``details`` and in
``--verbose`` output only. And every summary names a route's class in one vocabulary:
``planned (...)`` or ``other (...)``, the same words from ``trajgen plan``, ``schedule`` and
``check``, never "the paper's" on a star or a track graph.
"""

from __future__ import annotations

import dataclasses
import pickle
import re

import pytest

from tests.conftest import REPO
from trajgen import Exact, Outputs, certify, load_scenario, make_schedule, run, write_profiles
from trajgen.cli import EXIT_FAILURE, EXIT_OK, main
from trajgen.errors import VerificationError

SWAP = REPO / "examples" / "swap.toml"
CROSSING = REPO / "examples" / "crossing.toml"
H = REPO / "examples" / "graphs" / "h.toml"

#: What an array path looks like in a message: ``sections[0]``, ``maps[1]``, ``vehicles[0]``, ...
ARRAY_PATH = re.compile(r"\w\[\d+\]|\bsections\b|\bkinematics\b")


def _plain(text: str) -> bool:
    """Whether ``text`` names no array of a schedule."""
    return ARRAY_PATH.search(text) is None


def _exact(scenario):
    """The exact schedule of a junction's scenario along the planner's route."""
    from topology import plan

    route = plan(scenario.track, scenario.start, scenario.goal, min_separation=scenario.limits.min_separation)
    return make_schedule(route, scenario.limits, method=Exact())


@pytest.fixture(scope="module")
def moved_point(tmp_path_factory):
    """Siemens cam tables of the exact swap, one point of agv1 moved by 1 cm (as in example 07)."""
    folder = tmp_path_factory.mktemp("siemens")
    run(load_scenario(SWAP), method="exact", outputs=Outputs(csv_dir=folder, dialect="siemens-xy"))
    path = folder / "agv1.csv"
    lines = path.read_bytes().decode("ascii").split("\r\n")
    x, y = lines[300].split(";")
    lines[300] = f"{x};{float(y) + 10.0:.9f}"
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    return folder


# -- item 6: plain messages, the arrays in the details ----------------------------------------------------


def test_a_moved_table_point_is_told_in_plain_words_and_its_arrays_are_in_the_details(moved_point):
    from trajgen.export.plc.check import check_profiles

    verdict = check_profiles(load_scenario(SWAP), moved_point, dialect="siemens-xy")
    assert not verdict.passed
    assert all(_plain(failure) for failure in verdict.failures), verdict.failures
    velocity = next(f for f in verdict.failures if "velocity reaches" in f and "(from the table" not in f)
    # which vehicle, the value, when, where on the track, and the limit
    assert re.fullmatch(
        r"vehicle 1 velocity reaches [0-9.]+ m/s at t=[0-9.]+ s "
        r"\(on leg '[ABC]', [0-9.]+ m from the junction\) exceeds its max_velocity 1 m/s",
        velocity,
    ), velocity
    details = verdict.check.report.details
    assert len(details) == len(verdict.check.report.failures)
    assert any(d.startswith(velocity + ": sections[") and ".kinematics.vehicles[0]" in d for d in details)


@pytest.mark.parametrize("where", ["after", "before"])
def test_check_speaks_plainly_and_its_verbose_flag_prints_the_arrays(moved_point, capsys, where):
    argv = ["check", str(SWAP), "--csv", str(moved_point), "--dialect", "siemens-xy"]
    assert main(argv) == EXIT_FAILURE
    plain = capsys.readouterr()
    assert "violation: vehicle 1 velocity reaches" in plain.out
    assert _plain(plain.out + plain.err), plain.out + plain.err
    verbose = [*argv, "--verbose"] if where == "after" else ["--verbose", *argv]
    assert main(verbose) == EXIT_FAILURE
    told = capsys.readouterr()
    assert told.out == plain.out  # the verdict is the same; the details go to stderr
    assert "sections[" in told.err
    assert ".kinematics.vehicles[0].{times,initial,jerk} interval " in told.err


def _slower(schedule, max_velocity: float):
    """``schedule`` held to a lower velocity limit for vehicle 1 (a failing schedule)."""
    first, second = schedule.limits.vehicles
    limits = dataclasses.replace(
        schedule.limits, vehicles=(dataclasses.replace(first, max_velocity=max_velocity), second)
    )
    return dataclasses.replace(schedule, limits=limits)


def test_a_failed_certificate_says_what_where_and_when_and_carries_the_arrays():
    schedule = _slower(_exact(load_scenario(SWAP)), 0.9)
    expected = (
        "vehicle 1 velocity reaches 1 m/s at t=25.000000 s (on leg 'A', 8.750 m from the junction) "
        "exceeds its max_velocity 0.9 m/s"
    )
    with pytest.raises(
        VerificationError, match=re.escape(f"schedule failed verification: {expected}")
    ) as caught:
        certify(schedule)
    error = caught.value
    assert _plain(str(error)), str(error)
    assert error.details == (
        f"{expected}: sections[1].kinematics.vehicles[0].{{times,initial,jerk}} interval 2, "
        "sections[1].maps[0].{axis_start,axis_end,s_start}",
    )
    assert pickle.loads(pickle.dumps(error)).details == error.details  # across processes too


def test_a_separation_failure_says_where_both_vehicles_are():
    schedule = _exact(load_scenario(SWAP))
    tight = dataclasses.replace(schedule, limits=dataclasses.replace(schedule.limits, min_separation=10.5))
    with pytest.raises(VerificationError) as caught:
        certify(tight)
    (message,) = [f for f in str(caught.value).split("; ") if "below the minimum 10.5 m" in f]
    assert re.search(
        r"separation [0-9.]+ m at t=[0-9.]+ s is below the minimum 10\.5 m "
        r"\(vehicle 1 (on leg '[ABC]', [0-9.]+ m from the junction|in the junction) and "
        r"vehicle 2 (on leg '[ABC]', [0-9.]+ m from the junction|in the junction)\)",
        message,
    ), message
    assert _plain(str(caught.value))
    assert all("sections[" in detail for detail in caught.value.details)


def test_broken_numbers_are_told_as_whose_and_when_with_their_arrays_in_the_details():
    from trajgen import verify

    schedule = _exact(load_scenario(SWAP))
    sections = list(schedule.sections)
    sections[1] = dataclasses.replace(sections[1], start_time=sections[1].start_time + 0.5)
    report = verify(dataclasses.replace(schedule, sections=tuple(sections)))
    assert report.failures == (
        "section 2 of 3 starts at t=23.0 s: expected 22.5 s, where the section before it ends",
        "section 3 of 3 starts at t=45.0 s: expected 45.5 s, where the section before it ends",
    )
    assert report.details == tuple(
        f"{failure}: sections[{k}].start_time is {failure.split('t=')[1]}"
        for k, failure in enumerate(report.failures, start=1)
    )


def test_the_command_line_prints_a_verification_errors_details_only_when_verbose(monkeypatch, capsys):
    import trajgen.cli.schedule

    def failing(*args, **kwargs):
        raise VerificationError(
            "schedule failed verification: vehicle 1 velocity reaches 1.2 m/s",
            details=(
                "vehicle 1 velocity reaches 1.2 m/s: sections[0].maps[0].{axis_start,axis_end,s_start}",
            ),
        )

    monkeypatch.setattr(trajgen.cli.schedule, "run", failing)
    assert main(["schedule", str(SWAP)]) == EXIT_FAILURE
    err = capsys.readouterr().err
    assert "vehicle 1 velocity reaches 1.2 m/s" in err
    assert _plain(err), err
    assert main(["schedule", str(SWAP), "-v"]) == EXIT_FAILURE
    err = capsys.readouterr().err
    assert "trajgen: detail: vehicle 1 velocity reaches 1.2 m/s: sections[0].maps[0]" in err


# -- item 8: one vocabulary for a class -----------------------------------------------------------------


def _class_line(text: str) -> str:
    """The words after ``class: `` on the line that names the class."""
    found = re.findall(r"(?:^|; )class: (.+)$", text, flags=re.M)
    assert len(found) == 1, text
    return found[0]


#: Each kind of track: its scenario and the class its planner's route is in, as every summary names it.
TRACKS = {
    "y": (SWAP, "planned (counterclockwise)"),
    "star": (CROSSING, "planned (shortest route on G_4)"),
    "graph": (H, "planned (agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D)"),
}


@pytest.mark.parametrize("track", list(TRACKS))
def test_schedule_check_and_plan_name_the_class_in_the_same_words(tmp_path, capsys, track):
    scenario, expected = TRACKS[track]
    csv = ["--csv", str(tmp_path), "--sample-period", "0.05"]
    assert main(["schedule", str(scenario), "--method", "exact", *csv]) == EXIT_OK
    scheduled = capsys.readouterr().out
    assert main(["check", str(scenario), "--csv", str(tmp_path)]) == EXIT_OK
    checked = capsys.readouterr().out
    assert main(["plan", str(scenario)]) == EXIT_OK
    planned = capsys.readouterr().out
    assert _class_line(scheduled) == _class_line(checked) == expected
    if track != "graph":  # a graph's plan lists the moves themselves
        assert _class_line(planned).startswith(f"{expected}, regions ")
    if track != "y":  # the paper's planner is the Y's
        assert "paper" not in scheduled + checked + planned


@pytest.mark.parametrize(
    ("track", "expected"), [("y", "other (clockwise)"), ("star", "other (second-shortest route on G_4)")]
)
def test_a_schedule_of_the_other_class_is_named_alike_by_its_summary_and_by_check(
    tmp_path, capsys, track, expected
):
    from topology import plan
    from trajgen.export import CsvOptions
    from trajgen.model.summary import format_run
    from trajgen.pipeline import RunResult

    scenario = load_scenario(TRACKS[track][0])
    other = plan(
        scenario.track,
        scenario.start,
        scenario.goal,
        min_separation=scenario.limits.min_separation,
        homotopy="other",
    )
    verified = certify(make_schedule(other, scenario.limits, method=Exact()))
    write_profiles(verified, scenario.names, tmp_path, options=CsvOptions(sample_period=0.05))
    summary = format_run(RunResult(scenario, Exact(), other, verified, ()).summary())
    assert main(["check", str(scenario.source), "--csv", str(tmp_path)]) == EXIT_OK
    checked = capsys.readouterr().out
    assert _class_line(summary) == _class_line(checked) == expected
    assert "paper" not in summary + checked


def test_a_graph_schedule_of_another_class_is_named_other_by_its_summary_and_by_check(tmp_path, capsys):
    from topology import plan_graph_classes
    from trajgen.export import CsvOptions
    from trajgen.model.summary import class_label, format_run
    from trajgen.pipeline import RunResult

    scenario = load_scenario(H)
    routes = plan_graph_classes(
        scenario.track,
        scenario.start,
        scenario.goal,
        min_separation=scenario.limits.min_separation,
        names=scenario.names,
    )
    other = routes[1]  # where the other vehicle yields
    verified = certify(make_schedule(other, scenario.limits, method=Exact()))
    write_profiles(verified, scenario.names, tmp_path, options=CsvOptions(sample_period=0.05))
    summary = format_run(RunResult(scenario, Exact(), other, verified, (), planned_class=False).summary())
    assert main(["check", str(H), "--csv", str(tmp_path)]) == EXIT_OK
    checked = capsys.readouterr().out
    expected = class_label(other, planned=False)
    assert expected.startswith("other (agv")
    assert _class_line(summary) == _class_line(checked) == expected
    assert "paper" not in summary + checked
