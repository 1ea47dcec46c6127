"""``optimal`` over the two shortest homotopy classes, and its accuracy (issue 10).

Closed-form and stored reference values (the issue's swaps and its long track, the two classes
of a 4-way crossing), agreement with a converged solve, the class lower bound in both classes,
and the ``homotopy`` option in Python and on the command line.
"""

from __future__ import annotations

import json
import logging
import math
import re

import pytest

from limits import Limits, VehicleLimits
from tests.support.helpers import AGV, LIMITS, MIXED, SLOW, route_of
from topology import Homotopy, WayRound, plan
from trajgen import FallbackReason, Optimal, SolverCache, builtin_scenario, lower_bound, verify
from trajgen.cli import EXIT_BAD_INPUT, EXIT_OK, main
from trajgen.methods.optimal import Solver, Source
from trajgen.model.analysis import class_lower_bound
from trajgen.model.summary import class_label
from trajgen.scenario.sampling import random_scenarios

FAST = VehicleLimits(2.0, 1.0, 2.0)
QUARTER = VehicleLimits(0.5, 0.25, 0.5)
#: The issue's swaps: legs, vehicles, the prioritized baseline it measured, optimal at 32 fixed nodes then.
ISSUE_SWAPS = [
    pytest.param((10.0, 10.0, 10.0), (FAST, QUARTER), 42.5, 50.56, id="10-10-10-four-times-faster"),
    pytest.param((12.0, 8.0, 15.0), (AGV, SLOW), 34.24, 37.51, id="12-8-15-mixed"),
]
TRACK_LEGS = (12.0, 8.0, 15.0)
RANDOM = random_scenarios(
    4, seed=1010, track=route_of(TRACK_LEGS, ("A:1", "B:1"), ("A:2", "B:2")).graph, limits=MIXED
)


def swap_route(legs):
    return route_of(legs, (f"A:{legs[0]}", f"B:{legs[1]}"), (f"B:{legs[1]}", f"A:{legs[0]}"))


@pytest.mark.parametrize(("legs", "vehicles", "baseline", "before"), ISSUE_SWAPS)
def test_the_faster_class_wins_the_issue_swaps(legs, vehicles, baseline, before):
    limits = Limits(vehicles, 1.5)
    route = swap_route(legs)
    fastest = Optimal().schedule(route, limits)
    paper = Optimal(homotopy="planned").schedule(route, limits)
    report = verify(fastest)
    assert report.passed, report.failures
    assert report.regions_match  # the regions of the class it says it took
    assert fastest.fallback_reason is None
    assert paper.fallback_reason is None
    assert fastest.route.homotopy is Homotopy.OTHER
    assert fastest.route.way_round is WayRound.CLOCKWISE  # a swap's paper class is counterclockwise
    assert fastest.route.regions != route.regions
    assert paper.route.homotopy is Homotopy.PLANNED
    assert paper.route.regions == route.regions
    assert fastest.duration <= baseline * (1 + 1e-4)  # never slower than the issue's prioritized baseline
    assert fastest.duration < 0.93 * paper.duration
    assert paper.duration < before  # the paper's class is faster too than with the fixed grid
    classes = fastest.info.classes
    assert [(c.homotopy, c.chosen) for c in classes] == [(Homotopy.PLANNED, False), (Homotopy.OTHER, True)]
    assert classes[1].makespan == pytest.approx(fastest.duration, rel=1e-12)
    assert classes[0].makespan == pytest.approx(paper.duration, rel=2e-3)
    assert all(c.lower_bound <= c.makespan * (1 + 1e-9) for c in classes)


@pytest.mark.slow
def test_optimal_fastest_on_a_crossing_takes_the_faster_of_two_classes(capsys):
    # the slow vehicle 1 would dodge into a side leg in the planner's class; in the other class the
    # fast vehicle 2 dodges, which is much faster
    scenario = builtin_scenario("crossing")
    limits = Limits((QUARTER, FAST), 1.5)
    route = scenario.route()
    fastest = Optimal().schedule(route, limits)
    report = verify(fastest)
    assert report.passed, report.failures
    assert report.regions_match
    assert fastest.fallback_reason is None
    classes = fastest.info.classes
    assert [(c.homotopy, c.chosen) for c in classes] == [(Homotopy.PLANNED, False), (Homotopy.OTHER, True)]
    assert [c.summary()["class"] for c in classes] == [
        "shortest route on G_4",
        "second-shortest route on G_4",
    ]
    assert classes[1].makespan == pytest.approx(fastest.duration, rel=1e-12)
    assert classes[0].makespan is None or classes[0].makespan > 1.05 * classes[1].makespan
    assert all(c.lower_bound <= (c.makespan or math.inf) * (1 + 1e-9) for c in classes)
    other = plan(scenario.track, scenario.start, scenario.goal, min_separation=1.5, homotopy="other")
    assert fastest.route.region_keys == other.region_keys
    assert fastest.route.travel == (20.0, 40.0)  # the fast vehicle 2 drives the detour
    assert class_label(fastest.route) == "other (second-shortest route on G_4)"


@pytest.mark.slow
@pytest.mark.accuracy
def test_the_four_times_faster_swap_reaches_its_closed_form_lower_bound():
    # the fast vehicle dodges into C while the slow one drives straight through: the slow vehicle's
    # own rest-to-rest S-curve over 20 m is the lower bound, and the faster class meets it
    route = swap_route((10.0, 10.0, 10.0))
    limits = Limits((FAST, QUARTER), 1.5)
    bound = lower_bound(route, limits)
    assert bound == pytest.approx(20.0 / 0.5 + 0.5 / 0.25 + 0.25 / 0.5)
    assert bound <= Optimal().schedule(route, limits).duration <= bound * (1 + 2e-3)


@pytest.mark.slow
@pytest.mark.parametrize("scenario", RANDOM, ids=[s.source for s in RANDOM])
def test_the_class_lower_bound_holds_in_both_classes(scenario):
    paper = scenario.route()
    if paper.arc_length == 0.0:
        pytest.skip("start and goal retract to one boundary point: one class only")
    other = plan(paper.graph, paper.start, paper.goal, min_separation=paper.min_separation, homotopy="other")
    for route in (paper, other):
        schedule = Optimal(homotopy="planned").schedule(route, scenario.limits)  # the route's own class
        assert schedule.route.regions == route.regions
        assert verify(schedule).passed
        bound = class_lower_bound(route, scenario.limits)
        assert lower_bound(route, scenario.limits) <= bound <= schedule.duration * (1 + 1e-9)


#: Converged solves (stored reference values): makespan of each class, seconds, the faster first, from
#: ``Optimal(nodes=64, refinements=12, refinement_tolerance=1e-5)`` (trajgen 0.7).
CONVERGED = {
    "into-one-leg": ((13.500020756816056, Homotopy.PLANNED), (21.68482261852551, Homotopy.OTHER)),
    "swap-CA-mixed": ((41.15476274144109, Homotopy.PLANNED), (47.47637861555721, Homotopy.OTHER)),
    "2-30-5-swap": ((64.09144697338594, Homotopy.PLANNED), (64.09150030677102, Homotopy.OTHER)),
}


@pytest.mark.slow
@pytest.mark.accuracy
@pytest.mark.parametrize(
    ("legs", "start", "goal", "limits", "converged"),
    [
        pytest.param(
            (12.0, 8.0, 15.0),
            ("A:3", "B:2"),
            ("C:4", "C:9"),
            LIMITS,
            CONVERGED["into-one-leg"],
            id="into-one-leg",
        ),
        pytest.param(
            (12.0, 8.0, 15.0),
            ("A:12", "C:15"),
            ("C:15", "A:12"),
            MIXED,
            CONVERGED["swap-CA-mixed"],
            id="swap-CA-mixed",
        ),
        pytest.param(
            (2.0, 30.0, 5.0),
            ("A:2", "B:30"),
            ("B:30", "A:2"),
            LIMITS,
            CONVERGED["2-30-5-swap"],
            id="2-30-5-swap",
        ),
    ],
)
def test_the_default_agrees_with_a_converged_solve(legs, start, goal, limits, converged):
    default = Optimal().schedule(route_of(legs, start, goal), limits)
    (fastest, its_class), (slower, _) = converged
    assert fastest * (1 - 1e-6) <= default.duration <= fastest * 1.002
    if slower > 1.005 * fastest:  # one class clearly faster: the default picks it
        assert default.route.homotopy is its_class


@pytest.mark.slow
def test_the_converged_references_are_what_a_converged_solve_gives():
    # one of the stored converged solves, recomputed (the cheapest): the references are not stale
    route = route_of((12.0, 8.0, 15.0), ("A:3", "B:2"), ("C:4", "C:9"))
    converged = Optimal(
        nodes=64, refinements=12, refinement_tolerance=1e-5, time_limit=60.0, cache=SolverCache()
    ).schedule(route, LIMITS)
    makespans = sorted((c.makespan, c.homotopy) for c in converged.info.classes)
    assert makespans[0][1] is CONVERGED["into-one-leg"][0][1]
    for (value, _), (stored, _) in zip(makespans, CONVERGED["into-one-leg"], strict=True):
        assert value == pytest.approx(stored, rel=1e-6)


@pytest.mark.slow
@pytest.mark.accuracy
def test_mesh_refinement_makes_a_long_track_accurate():
    # issue 10: on 200/120/80 m the fixed 32-node grid was 1.1 % over the converged 404.00 s
    route = swap_route((200.0, 120.0, 80.0))
    refined = Optimal(homotopy="planned").schedule(route, LIMITS)
    first_grid = Optimal(homotopy="planned", refinements=0).schedule(route, LIMITS)
    assert verify(refined).passed
    assert refined.info.refinements >= 1
    assert refined.info.source is Source.NLP
    assert 404.0 * (1 - 1e-6) <= refined.duration <= 404.0 * 1.002
    assert first_grid.duration > 404.0 * 1.005  # what refinement buys
    assert lower_bound(route, LIMITS) <= refined.duration


def test_a_class_that_cannot_beat_the_exact_schedule_is_not_solved():
    # vehicle 2 drives 5 m out of the junction into B while vehicle 1 stays at the end of A: the
    # exact S-curve (7.5 s) meets both classes' lower bounds, so no NLP is solved at all
    route = route_of(TRACK_LEGS, ("A:12", "O"), ("A:12", "B:5"))
    schedule = Optimal().schedule(route, LIMITS)
    assert schedule.info.source is Source.EXACT
    assert schedule.info.attempts == ()
    assert schedule.duration == pytest.approx(lower_bound(route, LIMITS), rel=1e-12)
    assert "every class's lower bound" in schedule.notes[0]
    assert verify(schedule).passed


def test_a_clearly_beaten_class_is_not_refined_and_the_diagnostics_cover_both():
    schedule = Optimal().schedule(swap_route((12.0, 8.0, 15.0)), MIXED)
    info = schedule.info
    paper, other = info.classes
    assert info.solve_time > 0.0
    # the paper's class is 10 % slower on its first grid, more than refinement could gain (5 %):
    # it is not refined; the other class is, once
    assert paper.makespan > 1.05 * other.makespan
    assert len(info.attempts) == 3
    assert all(a.solver is Solver.FATROP for a in info.attempts)
    assert info.refinements == 1
    assert "pass 2 of 2 (mesh refinement)" in schedule.notes[0]


SCENARIO = """
[track]
legs = {{ A = 12.0, B = 8.0, C = 15.0 }}

[safety]
min_separation = 1.5

[[vehicle]]
name = "agv1"
max_velocity = 1.0
max_acceleration = 0.5
max_jerk = 1.0
start = "A:12"
goal = "B:8"

[[vehicle]]
name = "agv2"
max_velocity = {slow}
max_acceleration = 0.35
max_jerk = 0.6
start = "B:8"
goal = "A:12"
"""


@pytest.mark.parametrize(
    ("options", "homotopy", "way_round"),
    [
        pytest.param([], "other", "clockwise", id="default-fastest"),
        pytest.param(["--homotopy", "planned"], "planned", "counterclockwise", id="planned"),
        pytest.param(["--homotopy", "FASTEST"], "other", "clockwise", id="fastest-any-case"),
    ],
)
def test_cli_reports_the_class_and_keeps_the_papers_on_request(
    tmp_path, capsys, options, homotopy, way_round
):
    scenario = tmp_path / "mixed.toml"
    scenario.write_text(SCENARIO.format(slow=0.7))
    assert main(["schedule", str(scenario), "--json", *options]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["route"]["homotopy"] == homotopy
    assert summary["route"]["planned_class"] is (homotopy == "planned")
    assert summary["route"]["way_round"] == way_round
    assert summary["verified"] is True
    classes = summary["solver"]["classes"]
    if options[1:] == ["planned"]:
        assert classes == []
    else:
        assert [c["chosen"] for c in classes] == [False, True]
        assert classes[1]["makespan_s"] == pytest.approx(summary["duration_s"])
        assert classes[1]["makespan_s"] < classes[0]["makespan_s"]
    main(["schedule", str(scenario), *options])
    human = capsys.readouterr().out
    assert f"class: {homotopy} ({way_round})" in human


@pytest.mark.parametrize(
    ("options", "message"),
    [
        pytest.param(
            ["--homotopy", "both"],
            r"homotopy choice 'both' is unknown: expected one of \['fastest', 'planned'\]",
            id="unknown",
        ),
        pytest.param(
            ["--homotopy", "planned", "--method", "exact"],
            "--homotopy 'planned' applies to the method 'optimal' only, got --method 'exact'",
            id="not-optimal",
        ),
    ],
)
def test_cli_bad_homotopy_exits_2_and_writes_nothing(tmp_path, capsys, options, message):
    scenario = tmp_path / "mixed.toml"
    scenario.write_text(SCENARIO.format(slow=0.7))
    out = tmp_path / "out"
    assert main(["schedule", str(scenario), "--csv", str(out), *options]) == EXIT_BAD_INPUT
    assert re.search(message, capsys.readouterr().err)
    assert not out.exists()


def test_a_class_that_fails_is_reported_and_the_other_class_is_returned(monkeypatch):
    import trajgen.methods.optimal.class_solve as optimal_method

    real = optimal_method.initial_guess

    def broken_for_the_other_class(exact, *args):
        if exact.route.homotopy is Homotopy.OTHER:
            raise RuntimeError("injected setup fault")
        return real(exact, *args)

    monkeypatch.setattr(optimal_method, "initial_guess", broken_for_the_other_class)
    route = swap_route((12.0, 8.0, 15.0))
    schedule = Optimal().schedule(route, MIXED)
    assert schedule.fallback_reason is None
    assert schedule.route.homotopy is Homotopy.PLANNED  # the slower class, but the only one solved
    assert verify(schedule).passed
    paper, other = schedule.info.classes
    assert (paper.chosen, paper.failure) == (True, None)
    assert (other.makespan, other.failure) == (None, FallbackReason.SETUP_FAILED)
    assert any("not solved (setup-failed): RuntimeError: injected setup fault" in n for n in schedule.notes)
    assert schedule.info.solver is Solver.FATROP  # the solver of the returned pass


def test_a_refinement_that_raises_keeps_the_passes_solved_before(monkeypatch, caplog):
    import trajgen.methods.optimal.class_solve as optimal_method

    def broken(*args):
        raise FloatingPointError("injected refinement fault")

    monkeypatch.setattr(optimal_method, "refine", broken)
    route = swap_route((12.0, 8.0, 15.0))
    schedule = Optimal(homotopy="planned").schedule(route, LIMITS)
    assert schedule.fallback_reason is None
    assert schedule.info.refinements == 0
    assert "pass 1 of 1" in schedule.notes[0]
    assert verify(schedule).passed
    assert any("keeping its earlier passes" in r.message for r in caplog.records)


def test_a_fallback_summary_marks_no_failed_class_chosen_and_gives_the_reasons_once(capsys, caplog):
    from trajgen import Optimal, default_scenario, run
    from trajgen.model.summary import format_run

    with caplog.at_level(logging.WARNING):
        result = run(default_scenario(), method=Optimal(max_iterations=1))
    text = format_run(result.summary())
    assert result.summary()["fallback_reason"] == "solver-failed"
    class_lines = [line for line in text.splitlines() if line.startswith("class ")]
    assert len(class_lines) == 2
    assert all("failed (solver-failed)" in line for line in class_lines)
    assert not any("<- chosen" in line for line in class_lines)
    assert "(the exact fallback keeps this class)" in class_lines[0]
    # every solver attempt is listed once: in the note, not again in the log, which says why in words
    detail = "ipopt-polish did not converge"
    assert (text + caplog.text).count(detail) == text.count(detail) == 2  # two classes, one line
    assert "fell back to the exact schedule (solver-failed): no solver converged" in caplog.text
