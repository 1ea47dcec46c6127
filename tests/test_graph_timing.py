"""The three timing methods on track graphs: each verified, ordered, against the lone-vehicle bound."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.conftest import REPO
from tests.support.graph_cases import random_routes, verified_example
from tests.support.graph_rows import ScenarioFile, check_profiles
from topology import class_signature, plan_graph, plan_graph_classes
from trajgen import certify
from trajgen.cli import main
from trajgen.export.csv import profile_chunk_pair
from trajgen.methods import make_schedule
from trajgen.methods.exact import Exact
from trajgen.methods.optimal import Optimal
from trajgen.model.analysis import lower_bound
from trajgen.model.schedule import FallbackReason
from trajgen.scenario import BuiltinScenario, builtin_scenario, load_scenario

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


def _texts(verified) -> tuple[str, str]:
    first, second = profile_chunk_pair(verified)
    return b"".join(first).decode("ascii"), b"".join(second).decode("ascii")


def _star_as_graph(scenario):
    """A junction scenario's track as a track graph (the library's), its starts and goals on it."""
    star = scenario.track
    return (
        star.track_graph(),
        [star.edge_point(p) for p in scenario.start],
        [star.edge_point(p) for p in scenario.goal],
    )


@pytest.mark.parametrize("name", FEASIBLE)
def test_toppra_overlaps_the_hand_overs_verified_and_is_between_exact_and_the_bound(name):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    route = scenario.route()
    exact = certify(make_schedule(route, scenario.limits, method="exact"))
    toppra = certify(make_schedule(route, scenario.limits, method="toppra"))
    assert toppra.schedule.fallback_reason is None
    assert not toppra.schedule.jerk_limited
    assert "hand-overs between the vehicles overlapped" in toppra.schedule.notes[0]
    assert lower_bound(route, scenario.limits) < toppra.schedule.duration < exact.schedule.duration
    figures = check_profiles(ScenarioFile(EXAMPLES / f"{name}.toml"), _texts(toppra), jerk=False)
    assert figures["closest"] >= scenario.limits.min_separation - 1e-6


@pytest.mark.parametrize("name", ["passing-loop", "ring-with-spurs"])
def test_optimal_is_jerk_limited_verified_and_faster_than_toppra(name):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    route = scenario.route()
    optimal = certify(make_schedule(route, scenario.limits, method="optimal"))
    toppra = make_schedule(route, scenario.limits, method="toppra")
    assert optimal.schedule.fallback_reason is None
    assert optimal.schedule.jerk_limited
    assert lower_bound(route, scenario.limits) <= optimal.schedule.duration < toppra.duration
    classes = optimal.schedule.info.summary()["classes"]
    assert sum(c["chosen"] for c in classes) == 1
    chosen = next(c for c in classes if c["chosen"])
    assert chosen["makespan_s"] == pytest.approx(optimal.schedule.duration)
    # the fastest, a tie within a microsecond keeping the route's own class
    assert all(c["makespan_s"] >= chosen["makespan_s"] - 1e-6 for c in classes if c["makespan_s"] is not None)
    check_profiles(ScenarioFile(EXAMPLES / f"{name}.toml"), _texts(optimal), jerk=True)


@pytest.mark.slow
@pytest.mark.parametrize("name", FEASIBLE)
def test_every_method_on_every_example_is_verified_and_exact_toppra_optimal_are_ordered(name):
    durations = {}
    for method in ("exact", "toppra", "optimal"):
        scenario, verified = verified_example(name, method)
        assert verified.schedule.fallback_reason is None, verified.schedule.notes
        check_profiles(ScenarioFile(EXAMPLES / f"{name}.toml"), _texts(verified), jerk=method != "toppra")
        durations[method] = verified.schedule.duration
    assert durations["exact"] >= durations["toppra"] >= durations["optimal"]
    assert durations["optimal"] >= lower_bound(scenario.route(), scenario.limits)


def test_the_classes_of_a_route_are_distinct_and_the_shortest_comes_first():
    scenario = load_scenario(EXAMPLES / "h.toml")
    routes = plan_graph_classes(
        scenario.track, scenario.start, scenario.goal, min_separation=1.5, names=scenario.names
    )
    assert len(routes) == 2
    assert class_signature(routes[0]) == class_signature(scenario.route())
    assert len({class_signature(r) for r in routes}) == len(routes)
    assert routes[0].length <= routes[1].length
    # the other class: agv2 yields (parks in b) where the shortest has agv1 park in c
    assert routes[1].moves[0].vehicle == 1
    assert routes[1].names == ("agv1", "agv2")


def test_the_planned_homotopy_solves_the_routes_class_alone():
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    schedule = make_schedule(scenario.route(), scenario.limits, method=Optimal(homotopy="planned"))
    classes = schedule.info.summary()["classes"]
    assert [c["homotopy"] for c in classes] == ["planned"]
    assert classes[0]["chosen"]


def test_an_optimal_problem_that_cannot_be_solved_falls_back_to_exact_flagged(monkeypatch):
    from trajgen.methods import graph_optimal

    def failing(*args, **kwargs):
        raise RuntimeError("IPOPT: Infeasible_Problem_Detected")

    monkeypatch.setattr(graph_optimal, "_run", failing)
    scenario = load_scenario(EXAMPLES / "ring-with-spurs.toml")
    schedule = make_schedule(scenario.route(), scenario.limits, method="optimal")
    assert schedule.fallback_reason is FallbackReason.SOLVER_FAILED
    assert schedule.duration == make_schedule(scenario.route(), scenario.limits, method="exact").duration
    assert "Infeasible_Problem_Detected" in schedule.notes[0]
    assert certify(schedule).report.passed


@pytest.mark.parametrize("builtin", [BuiltinScenario.SWAP, BuiltinScenario.CROSSING])
def test_a_star_written_as_a_graph_plans_a_route_no_longer_than_the_star_planner(builtin):
    scenario = builtin_scenario(builtin)
    track, start, goal = _star_as_graph(scenario)
    graph_route = plan_graph(track, start, goal, min_separation=scenario.limits.min_separation)
    # the star route's travel: both vehicles' odometers along its exact schedule, piece by piece
    exact_star = make_schedule(scenario.route(), scenario.limits, method="exact")
    travelled = 0.0
    for section in exact_star.sections:
        ends = section.kinematics.evaluate(np.array([0.0, section.duration]))[:, 0]
        travelled += float(np.abs(ends[:, 1] - ends[:, 0]).sum())
    assert graph_route.length <= travelled + 1e-9
    assert graph_route.length < travelled  # strictly here: the star's instructions are not l1-shortest


@pytest.mark.slow
def test_a_star_written_as_a_graph_has_an_optimal_makespan_within_half_a_percent_of_the_stars():
    scenario = builtin_scenario(BuiltinScenario.SWAP)
    track, start, goal = _star_as_graph(scenario)
    graph_route = plan_graph(track, start, goal, min_separation=scenario.limits.min_separation)
    star = certify(make_schedule(scenario.route(), scenario.limits, method="optimal")).schedule.duration
    graph = certify(make_schedule(graph_route, scenario.limits, method="optimal")).schedule.duration
    assert abs(graph - star) <= 0.005 * star, (graph, star)


def test_the_schedule_command_lists_each_class_and_its_makespan(capsys):
    path = EXAMPLES / "passing-loop.toml"
    assert main(["schedule", str(path), "--method", "optimal", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    classes = summary["solver"]["classes"]
    assert len(classes) == 2
    assert all(c["makespan_s"] > 0 for c in classes)
    assert summary["verified"]
    assert main(["schedule", str(path), "--method", "optimal"]) == 0
    text = capsys.readouterr().out
    assert "class planned (agv1 west:1 -> main:8.5; agv2 east:9 -> W; agv1 main:8.5 -> E):" in text
    assert "class other (" in text


def test_toppra_on_seeded_random_graphs_is_verified_and_never_slower_than_exact_without_jerk():
    fallbacks = []
    for seed, route, limits in random_routes(40, 1000):
        toppra = make_schedule(route, limits, method="toppra")
        if toppra.fallback_reason is not None:  # only where its plan breaks the braking rule
            assert "the braking rule" in toppra.notes[0], (seed, toppra.notes)
            fallbacks.append(seed)
        assert certify(toppra).report.passed
        trapezoids = make_schedule(route, limits, method=Exact(jerk=False))
        assert toppra.duration <= trapezoids.duration + 1e-9, seed
    assert fallbacks == [1026]  # its follower would brake 0.72 m past its frontier


@pytest.mark.slow
def test_optimal_on_seeded_random_graphs_is_verified_or_flagged_and_never_slower_than_exact():
    solved = 0
    for seed, route, limits in random_routes(10, 2000):
        schedule = make_schedule(route, limits, method="optimal")
        assert certify(schedule).report.passed, seed
        exact = make_schedule(route, limits, method="exact")
        assert schedule.duration <= exact.duration + 1e-9, seed
        if schedule.fallback_reason is None:
            solved += 1
            assert schedule.jerk_limited
        else:  # a class the solver could not solve: the exact schedule, flagged and said
            assert schedule.duration == exact.duration
            assert schedule.notes[0].startswith("fallback to exact")
    assert solved >= 7, solved
