"""Schedules: exact vs toppra, stops and reversals, and the verifier catching broken schedules.

On a Y and on junctions of 4 to 8 legs (the scenarios of :mod:`tests.support.star_scenarios`);
a test of what holds for any number of legs is parametrized over it (``legs3``, ``legs4`` ...).
Track graphs after: timing the route's moves, the schedule model, its rows and its verifier.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.cases import case
from tests.support.fleets import FLEETS, SEPARATION
from tests.support.graph_cases import random_routes, verified_example
from tests.support.graph_rows import ScenarioFile, check_profiles
from tests.support.grid_oracle import random_case
from tests.support.helpers import AGV, LIMITS, MIXED, SLOW, legs_cases, legs_id, route_of, too_close
from tests.support.sampled_verifier import sampled_verify
from tests.support.star_scenarios import STAR_METHODS, STAR_SCENARIOS, leg_index, star_scenario, star_schedule
from tests.support.strategies import planned_junction_route, star_queries
from topology import (
    JUNCTION_INDEX,
    Configuration,
    EdgePoint,
    InfeasibleError,
    Position,
    TrackGraph,
    WayRound,
    YGraph,
    class_signature,
    plan,
    plan_graph,
    plan_graph_classes,
)
from trajgen import METHODS, Exact, Schedule, Toppra, certify, make_schedule, verify
from trajgen.cli import main
from trajgen.errors import InputError, OptionError, VerificationError
from trajgen.export import DIALECTS, write_profiles
from trajgen.export.csv import CsvOptions, profile_chunk_pair
from trajgen.methods.optimal import Optimal
from trajgen.model.analysis import lower_bound
from trajgen.model.axes import route_axes, straight_pieces
from trajgen.model.blended import ToppraKinematics
from trajgen.model.graph_schedule import GraphSchedule, GraphSection
from trajgen.model.junction_route import junction_graph_route
from trajgen.model.profiles import PiecewiseCubic, rest_to_rest_time, scurve_phases
from trajgen.model.schedule import CubicKinematics, FallbackReason, TimingMethod
from trajgen.pipeline import Outputs, run
from trajgen.scenario import BuiltinScenario, builtin_scenario, load_scenario
from trajgen.scenario.sampling import random_scenarios
from trajgen.verification.graph_route import TrackDistances

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))
TRACK = YGraph({"A": 12.0, "B": 8.0, "C": 15.0})
RANDOM = random_scenarios(12, seed=7, track=TRACK, limits=MIXED)


def exact_schedule(route, limits, *, jerk=True):
    return Exact(jerk=jerk).schedule(route, limits)


def toppra_schedule(route, limits):
    return Toppra().schedule(route, limits)


def test_swap_exact_reference_duration():
    # three straight pieces of 20 m each (merged through the junction), 22.5 s each
    schedule = exact_schedule(route_of(*SWAP), LIMITS)
    assert len(schedule.sections) == 3
    assert schedule.duration == pytest.approx(67.5)
    assert verify(schedule).passed


def test_vehicles_stop_where_the_direction_changes_and_reverse_with_negative_velocity():
    route = route_of(*SWAP)
    schedule = exact_schedule(route, LIMITS)
    for section in schedule.sections:
        state = schedule.state([section.start_time, section.start_time + section.duration])
        assert np.allclose(state.velocity, 0.0, atol=1e-12)
    # vehicle 2 drives B -> O -> C forward, then backs out of C to A
    state = schedule.sample(0.5)
    assert state.velocity[1].max() == pytest.approx(1.0)
    assert state.velocity[1].min() == pytest.approx(-1.0)
    assert state.axis[1, -1] == pytest.approx(0.0, abs=1e-9)  # back to where its odometer started
    axes = route_axes(route).axes
    assert straight_pieces(axes) == [(0, 2), (2, 4), (4, 6)]


@pytest.mark.parametrize("scenario", RANDOM, ids=[s.source for s in RANDOM])
def test_exact_and_toppra_pass_the_verifier_and_toppra_is_never_slower(scenario):
    route = scenario.route()
    exact = exact_schedule(route, scenario.limits)
    timed = toppra_schedule(route, scenario.limits)
    no_jerk = exact_schedule(route, scenario.limits, jerk=False)
    assert verify(exact).passed, verify(exact).failures
    report = verify(timed)
    assert report.passed, report.failures
    assert timed.duration <= no_jerk.duration + 1e-9
    assert no_jerk.duration <= exact.duration + 1e-9  # a jerk limit never makes a move faster
    assert not timed.jerk_limited
    assert "jerk is not limited" in " ".join(timed.notes)


# Found by the 600-scenario stress run of benchmarks/bench_optimal.py (--random 300): a
# velocity peak inside a long grid interval of a blend, 4e-6 m/s above the limit, fell between
# the samples the time stretch used to look at; the stretch now uses the closed-form peak.
STRESS = random_scenarios(300, seed=2026, track=TRACK, limits=MIXED)


@pytest.mark.parametrize("index", [90, 241], ids=["stress-90", "stress-241"])
def test_toppra_velocity_peaks_between_grid_points_are_within_limits(index):
    scenario = STRESS[index]
    timed = toppra_schedule(scenario.route(), scenario.limits)
    report = verify(timed)
    assert report.passed, report.failures


@pytest.mark.parametrize("index", [90, 241, 0, 1, 2], ids=lambda i: f"stress-{i}")
def test_closed_form_velocity_peaks_agree_with_dense_sampling(index):
    scenario = STRESS[index]
    timed = toppra_schedule(scenario.route(), scenario.limits)
    sections = [s.kinematics for s in timed.sections if isinstance(s.kinematics, ToppraKinematics)]
    assert sections
    for kinematics in sections:
        # 400 samples inside every grid interval: close to the true maximum, never above it
        fine = np.linspace(0.0, 1.0, 402)[1:-1]
        times = (kinematics.times[:-1, None] + np.diff(kinematics.times)[:, None] * fine).ravel()
        sampled = np.max(np.abs(kinematics.evaluate(times)[:, 1]), axis=1)
        ends = np.max(np.abs(kinematics.evaluate(kinematics.times[:-1])[:, 1]), axis=1)
        peaks = kinematics.interior_velocity_peaks()
        assert np.all(np.maximum(peaks, ends) >= sampled - 1e-12)
        assert np.all(peaks <= np.maximum(sampled, ends) + 1e-6)


def test_toppra_on_the_swap_rounds_corners_and_beats_exact():
    route = route_of(*SWAP)
    timed = toppra_schedule(route, LIMITS)
    assert verify(timed).passed
    assert timed.duration < exact_schedule(route, LIMITS, jerk=False).duration - 1.0
    assert "1 of 2 corners rounded" in timed.notes[0]  # vehicle 2 reverses: the other corner is a stop


def test_toppra_on_a_single_straight_move_is_the_trapezoid():
    route = route_of((10.0, 8.0, 15.0), ("A:2", "O"), ("A:10", "O"))
    timed = toppra_schedule(route, LIMITS)
    assert timed.duration == pytest.approx(exact_schedule(route, LIMITS, jerk=False).duration, rel=1e-12)


def test_method_lookup():
    assert METHODS.lookup("TOPPRA") is Toppra
    with pytest.raises(
        OptionError, match=r"method 'fast' is unknown: expected one of \['exact', 'toppra', 'optimal'\]"
    ):
        make_schedule(route_of(*SWAP), LIMITS, method="fast")


# -- schedules on junctions of 4 to 8 legs verify ----------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("method", sorted(STAR_METHODS))
@pytest.mark.parametrize("k", sorted(STAR_SCENARIOS), ids=legs_id)
def test_every_method_verifies_on_k_legs(k, method):
    scenario = star_scenario(k)
    schedule = star_schedule(k, method)
    assert scenario.track.leg_count == k
    assert schedule.fallback_reason is None
    report = verify(schedule)
    assert report.passed, report.failures
    # separation and limits
    assert report.min_separation >= scenario.limits.min_separation - 1e-9
    for ratio in (report.velocity_ratio, report.acceleration_ratio):
        assert max(ratio) <= 1.0 + 1e-6
    if schedule.jerk_limited:
        assert max(report.jerk_ratio) <= 1.0 + 1e-6
    # exactly the scenario's start and goal, at rest
    assert report.start_error <= 1e-9
    assert report.goal_error <= 1e-9
    ends = schedule.state([0.0, schedule.duration])
    for index, configuration in ((0, scenario.start), (-1, scenario.goal)):
        for vehicle, position in enumerate(configuration):
            assert int(ends.leg[vehicle, index]) == leg_index(scenario, position)
            assert float(ends.s[vehicle, index]) == pytest.approx(position.s, abs=1e-9)
            assert abs(float(ends.velocity[vehicle, index])) <= 1e-9
    # the class of its route, which is one of the planner's two
    assert report.regions_match
    route = schedule.route
    planned = plan(
        scenario.track,
        scenario.start,
        scenario.goal,
        min_separation=scenario.limits.min_separation,
        homotopy=route.homotopy,
    )
    assert route.region_keys == planned.region_keys
    assert route.way_round is WayRound.NOT_APPLICABLE
    # a second opinion from samples: legs in range, separation, limits, class
    second = sampled_verify(schedule, period=2e-3)
    assert second.passed, second.failures
    state = schedule.sample(0.05)
    assert np.all((state.leg >= JUNCTION_INDEX) & (state.leg < k))


@pytest.mark.slow
@pytest.mark.parametrize("k", sorted(STAR_SCENARIOS), ids=legs_id)
def test_optimal_is_no_slower_than_exact_on_k_legs(k):
    assert star_schedule(k, "optimal").duration <= star_schedule(k, "exact").duration * (1 + 1e-9)


@pytest.mark.slow
@settings(max_examples=25, derandomize=True, deadline=None)
@given(query=star_queries(4, 8))
def test_exact_schedules_of_random_star_queries_verify(query):
    graph, start, goal, separation = query
    # (a vehicle within ~1e-20 m of the junction: its exact schedule loses the piece below time
    # resolution on three legs as on more; not what this test is about)
    assume(all(p.s == 0.0 or p.s >= 1e-9 for p in (*start, *goal)))
    limits = Limits((AGV, SLOW), separation)
    schedule = Exact().schedule(plan(graph, start, goal, min_separation=separation), limits)
    report = verify(schedule)
    assert report.passed, report.failures
    assert report.regions_match
    assert report.min_separation >= separation - 1e-9


# -- the verifier catches broken schedules ------------------------------------------------------------


def _relabelled(schedule: Schedule, **changes) -> Schedule:
    return Schedule(
        changes.get("route", schedule.route),
        changes.get("limits", schedule.limits),
        schedule.method,
        schedule.sections,
        schedule.jerk_limited,
    )


def test_verifier_catches_a_schedule_that_is_too_fast():
    fast = VehicleLimits(max_velocity=1.2, max_acceleration=0.6, max_jerk=1.2)
    schedule = exact_schedule(route_of(*SWAP), Limits(vehicles=(fast, fast), min_separation=1.5))
    broken = _relabelled(schedule, limits=LIMITS)
    report = verify(broken)
    assert not report.passed
    assert report.velocity_ratio[0] == pytest.approx(1.2)
    assert any("velocity reaches 1.2 m/s" in f and "exceeds its max_velocity 1" in f for f in report.failures)
    with pytest.raises(VerificationError, match="exceeds its max_velocity"):
        certify(broken)


def test_verifier_catches_vehicles_too_close():
    schedule = exact_schedule(route_of(*SWAP), LIMITS)
    broken = too_close(schedule)
    report = verify(broken)
    assert report.separation_margin == pytest.approx(-0.5)
    assert any("below the minimum 10.5 m" in f for f in report.failures)


def test_verifier_catches_a_wrong_goal():
    schedule = exact_schedule(route_of(*SWAP), LIMITS)
    other = route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "C:10"))
    report = verify(_relabelled(schedule, route=other))
    assert report.goal_error == pytest.approx(20.0)
    assert any("goal is off" in f for f in report.failures)


#: The regions the verifier names when a swap's exact schedule claims the other class's route:
#: the demo swap (its other class clockwise round the circle) and the crossing's (the other class
#: has agv1 wait in E rather than agv2 in E; in the schedule agv1 waits in E).
OTHER_CLASS_FAILURES = {
    3: "schedule visits [Q(A,B) Q(A,C) Q(B,C) Q(B,A)], route [Q(A,B) Q(C,B) Q(C,A) Q(B,A)]",
    4: "schedule visits [Q(N,S) Q(E,S) Q(E,N) Q(S,N)], route [Q(N,S) Q(N,E) Q(S,E) Q(S,N)]",
}


@pytest.mark.parametrize("legs", legs_cases(sorted(OTHER_CLASS_FAILURES), slow={4}))
def test_verifier_catches_the_other_homotopy_class(legs):
    if legs == 3:
        route, limits = route_of(*SWAP), LIMITS
    else:
        scenario = star_scenario(legs)
        route, limits = scenario.route(), scenario.limits
    # same start and goal, the other class
    other = plan(route.graph, route.start, route.goal, min_separation=limits.min_separation, homotopy="other")
    assert (other.start, other.goal) == (route.start, route.goal)
    assert other.region_keys != route.region_keys
    if legs == 3:  # the swap clockwise: the swap back, reversed
        back = route_of((10.0, 10.0, 10.0), SWAP[2], SWAP[1])
        assert other.waypoints == back.waypoints[::-1]
        assert other.indexed_waypoints == back.indexed_waypoints[::-1]
        assert other.regions != route.regions
    schedule, detour = exact_schedule(route, limits), exact_schedule(other, limits)
    for relabelled in (_relabelled(detour, route=route), _relabelled(schedule, route=other)):
        report = verify(relabelled)
        assert not report.passed
        assert not report.regions_match
        failure = next(f for f in report.failures if "another class than their route" in f)
    assert OTHER_CLASS_FAILURES[legs] in failure
    assert verify(schedule).passed  # each a fine schedule of its own route
    assert verify(detour).passed


def test_verifier_catches_a_broken_position_map():
    schedule = exact_schedule(route_of(*SWAP), LIMITS)
    section = schedule.sections[1]
    first, second = section.maps
    shifted = dataclasses.replace(first, s_start=first.s_start + 0.5)
    broken = dataclasses.replace(
        schedule,
        sections=(
            schedule.sections[0],
            dataclasses.replace(section, maps=(shifted, second)),
            schedule.sections[2],
        ),
    )
    report = verify(broken)
    assert any("jumps" in f or "do not join" in f for f in report.failures), report.failures


@pytest.mark.slow
@pytest.mark.parametrize(
    ("k", "leg"),
    [(4, 4), (4, 7), (8, 8), (8, -2)],
    ids=["legs4-leg4", "legs4-leg7", "legs8-leg8", "legs8-leg-minus-2"],
)
def test_the_verifier_rejects_a_vehicle_on_a_leg_the_track_lacks(k, leg):
    schedule = star_schedule(k, "exact")
    # the first section whose first vehicle passes the junction: its map names two legs
    index, section = next((i, s) for i, s in enumerate(schedule.sections) if s.maps[0].legs.size > 1)
    first, second = section.maps
    legs = first.legs.copy()
    legs[-1] = leg
    sections = list(schedule.sections)
    sections[index] = dataclasses.replace(section, maps=(dataclasses.replace(first, legs=legs), second))
    report = verify(dataclasses.replace(schedule, sections=tuple(sections)))
    assert not report.passed
    expected = f"are not track legs: expected -1 (the junction) or a leg index 0 to {k - 1} ({k} legs)"
    assert any(f"map legs {legs.tolist()} {expected}" in f for f in report.failures), report.failures


@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
@pytest.mark.parametrize("period", [0.005, 0.01, 0.5], ids=lambda p: f"{p}s")
def test_the_last_sample_is_the_goal_at_rest_with_no_jerk(method, period):
    schedule = make_schedule(route_of(*SWAP), LIMITS, method=method)
    state = schedule.sample(period)
    assert state.t[-1] == schedule.duration
    assert np.all(state.jerk[:, -1] == 0.0)
    assert np.all(np.abs(state.velocity[:, -1]) < 1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
@pytest.mark.parametrize("scenario", RANDOM[:6], ids=[s.source for s in RANDOM[:6]])
def test_the_closed_form_verifier_agrees_with_the_sampled_second_opinion(scenario, method):
    schedule = make_schedule(scenario.route(), scenario.limits, method=method)
    certified, sampled = verify(schedule), sampled_verify(schedule)
    assert certified.passed, certified.failures
    assert sampled.passed, sampled.failures
    # the closed form sees every instant, so it finds the samples' extremes or worse ones, never better
    assert certified.min_separation <= sampled.min_separation + 1e-12
    assert certified.min_separation >= sampled.min_separation - 1e-3  # and the samples are 1 ms apart
    for name in ("velocity", "acceleration"):
        closed = getattr(certified, f"{name}_ratio")
        assert all(c >= s - 1e-12 for c, s in zip(closed, sampled.ratios[name], strict=True))


def test_a_toppra_failure_falls_back_to_exact_without_jerk_limits_flagged(monkeypatch):
    import toppra.algorithm

    from trajgen import FallbackReason

    def broken(*args, **kwargs):
        raise RuntimeError("simulated TOPPRA failure")

    monkeypatch.setattr(toppra.algorithm, "TOPPRA", broken)
    route = route_of(*SWAP)
    schedule = toppra_schedule(route, LIMITS)
    assert schedule.fallback_reason is FallbackReason.SOLVER_FAILED
    assert schedule.method == Exact(jerk=False)
    assert "simulated TOPPRA failure" in schedule.notes[0]
    assert schedule.duration == exact_schedule(route, LIMITS, jerk=False).duration
    assert verify(schedule).passed


def test_a_toppra_section_it_cannot_time_keeps_its_stops(monkeypatch):
    import toppra.algorithm

    real = toppra.algorithm.TOPPRA

    class Uncontrollable(real):
        def compute_parameterization(self, *args, **kwargs):
            super().compute_parameterization(*args, **kwargs)
            self.problem_data.sd_vec = None  # what TOPPRA returns when it finds the path uncontrollable

    monkeypatch.setattr(toppra.algorithm, "TOPPRA", Uncontrollable)
    route = route_of(*SWAP)
    schedule = toppra_schedule(route, LIMITS)
    assert schedule.fallback_reason is None
    assert any("TOPPRA failed on a section" in note for note in schedule.notes)
    assert schedule.duration == pytest.approx(exact_schedule(route, LIMITS, jerk=False).duration)
    assert verify(schedule).passed


def test_a_round_off_first_move_neither_sets_nor_reverses_the_axis():
    """A planner's 2e-14 m first move is no move: the axis grows in the direction of the real first one.

    Seed 12 of the online campaign, scenario 742: re-planned from where the vehicles stood, the
    route began with vehicle 1 moving 2.1e-14 m outward, then 7.96 m inward. Read as its first move,
    the sliver made the axis run backwards over the real one, and the executor, whose paths ignore
    such slivers, drove the vehicle away from its path.
    """
    lengths = (22.207407464799427, 27.615988714746972, 0.5943996977234312)
    graph = YGraph(dict(zip("ABC", lengths, strict=True)))
    start = Configuration(Position("A", 7.955232103637798), Position("C", 0.5943996977234296))
    goal = Configuration(Position("B", 27.615988714746972), Position("C", 0.5943))
    route = plan(graph, start, goal, min_separation=0.3730053062408387)
    first, second = route.indexed_waypoints[:2]
    assert 0.0 < second[1] - first[1] < 1e-12  # the sliver is there
    axes = route_axes(route).axes
    assert np.all(np.diff(axes, axis=0) >= 0.0), axes  # each vehicle one way: its axis never runs back
    assert axes[-1, 0] == pytest.approx(7.955232103637798 + 27.615988714746972, abs=1e-9)
    assert axes[-1, 1] == pytest.approx(0.5943996977234296 - 0.5943, abs=1e-9)
    schedule = certify(make_schedule(route, Limits(LIMITS.vehicles, 0.3730053062408387))).schedule
    assert schedule.state(0.5).velocity[0, 0] > 0.0  # the plan's first real move is its axis's + direction


def test_the_csv_leg_column_is_the_states_leg_plus_one_and_leg_names_read_both(tmp_path):
    """One convention, documented where the value appears: CSV 1-based with 0 at the junction."""
    from topology import JUNCTION_NAME
    from trajgen import certify, default_scenario, write_profiles

    scenario = default_scenario()
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    first, _ = write_profiles(verified, scenario.names, tmp_path)
    rows = [line.split(";") for line in first.read_text().splitlines()[1:]]
    t = np.array([float(row[0]) for row in rows])
    column = np.array([int(row[5]) for row in rows])
    state = verified.schedule.state(t)
    np.testing.assert_array_equal(column, state.leg[0] + 1)
    names = state.leg_names(verified.schedule.track)
    assert set(names[0]) == {"A", "B", JUNCTION_NAME}  # agv1 drives A -> O -> (C) -> O -> B
    assert all(
        names[0][k] == (JUNCTION_NAME if c == 0 else scenario.track.names[c - 1])
        for k, c in enumerate(column)
    )
    with pytest.raises(ValueError, match="read-only"):
        names[0, 0] = "C"


# -- track graphs: timing the route's moves --------------------------------------------------------------


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


# -- track graphs: the schedule model, its rows and its verifier -----------------------------------------


CROSS = TrackGraph.from_edges({leg: ("J", leg.upper(), 6.0) for leg in "abcd"})


def _csv_texts(verified, options=None) -> tuple[str, str]:
    first, second = profile_chunk_pair(verified, options)
    return b"".join(first).decode("ascii"), b"".join(second).decode("ascii")


@pytest.mark.parametrize("name", FEASIBLE)
@pytest.mark.parametrize("jerk", [True, False], ids=["s-curves", "trapezoids"])
def test_every_example_graph_is_timed_verified_and_its_csv_rows_hold_the_separation_and_limits(name, jerk):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact(jerk=jerk)))
    report = verified.report
    assert report.passed
    assert report.regions_match
    assert report.min_separation >= scenario.limits.min_separation - 1e-9
    figures = check_profiles(ScenarioFile(EXAMPLES / f"{name}.toml"), _csv_texts(verified), jerk=jerk)
    assert figures["closest"] >= scenario.limits.min_separation - 1e-6
    assert figures["closest"] <= report.min_separation + 0.05  # the rows come near the verified closest
    # the exact schedule drives each vehicle at its limit somewhere: the rows show it
    assert figures["v"] > 0.99
    assert figures["a"] > 0.99


@pytest.mark.parametrize("name", FEASIBLE)
def test_the_exact_makespan_is_the_sum_of_each_moves_closed_form_s_curve(name):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    route = scenario.route()
    expected = 0.0
    for move in route.moves:
        v = scenario.limits.vehicles[move.vehicle]
        expected += rest_to_rest_time(move.length, v.max_velocity, v.max_acceleration, v.max_jerk)
    assert make_schedule(route, scenario.limits, method="exact").duration == pytest.approx(
        expected, rel=1e-12
    )


def test_the_h_takes_the_closed_form_time_of_its_three_moves():
    # moves of 7.5, 20.5 and 15.5 m at v 1, a 0.5, j 1: each D/v + v/a + a/j = D + 2.5 s
    scenario = load_scenario(EXAMPLES / "h.toml")
    assert make_schedule(scenario.route(), scenario.limits, method="exact").duration == pytest.approx(51.5)


def _crossing() -> tuple:
    route = plan_graph(CROSS, ("A", "B"), ("C", "D"), min_separation=1.5)
    return route, Limits((AGV, AGV), 1.5)


def test_the_verifier_finds_a_schedule_that_passes_a_conflict_in_the_other_order():
    route, limits = _crossing()
    assert certify(make_schedule(route, limits, method="exact")).report.regions_match
    reversed_route = dataclasses.replace(route, moves=tuple(reversed(route.moves)))
    other_order = dataclasses.replace(make_schedule(reversed_route, limits, method="exact"), route=route)
    report = verify(other_order)
    assert not report.passed
    assert not report.regions_match
    with pytest.raises(VerificationError, match="passes a conflict in another order than the route"):
        certify(other_order)


def _together(route, limits) -> GraphSchedule:
    """Both vehicles driving at once from t = 0, each its whole path in one S-curve."""
    schedule = make_schedule(route, limits, method="exact")
    moves = []
    for vehicle, path in enumerate(schedule.paths):
        v = limits.vehicles[vehicle]
        phases = [
            (d, math.nan, j)
            for d, j in scurve_phases(path.length, v.max_velocity, v.max_acceleration, v.max_jerk)
        ]
        moves.append(phases)
    duration = max(sum(d for d, _, _ in phases) for phases in moves)
    profiles = [  # the one that arrives first waits there: both motions end with the section
        PiecewiseCubic.from_phases(
            0.0, [*phases, (duration - sum(d for d, _, _ in phases), 0.0, 0.0)], end=path.length
        )
        for phases, path in zip(moves, schedule.paths, strict=True)
    ]
    return dataclasses.replace(schedule, sections=(GraphSection(0.0, CubicKinematics(tuple(profiles))),))


def test_the_verifier_finds_two_vehicles_too_close_between_samples():
    route, limits = _crossing()
    report = verify(_together(route, limits))
    assert not report.passed
    assert report.min_separation < 1.5
    with pytest.raises(VerificationError, match=r"separation .* m at t=.* is below the minimum 1.5 m"):
        certify(_together(route, limits))


def test_the_verifier_finds_a_vehicle_that_turns_back_without_stopping():
    scenario = load_scenario(EXAMPLES / "h.toml")  # agv1 parks in c and turns back
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    assert schedule.paths[0].cusps.size == 1
    merged = _together(scenario.route(), scenario.limits)  # one S-curve through the cusp
    with pytest.raises(
        VerificationError, match=r"vehicle 1 turns back at 15.5 m of travel .* m/s: expected at rest"
    ):
        certify(merged)
    del schedule


def test_the_verifier_finds_a_schedule_faster_than_the_limits():
    route, limits = _crossing()
    schedule = make_schedule(route, limits, method="exact")
    faster = dataclasses.replace(
        schedule, limits=Limits((dataclasses.replace(AGV, max_velocity=0.9), AGV), 1.5)
    )
    with pytest.raises(
        VerificationError, match=r"vehicle 1 velocity reaches 1 m/s .* exceeds its max_velocity 0.9"
    ):
        certify(faster)


def test_the_verifier_finds_a_path_that_is_not_the_routes():
    route, limits = _crossing()
    schedule = make_schedule(route, limits, method="exact")
    other = plan_graph(CROSS, ("A", "B"), ("D", "C"), min_separation=1.5)
    with pytest.raises(
        VerificationError, match=r"vehicle 1's path goal is 6 m off the route's|path is .* off move"
    ):
        certify(dataclasses.replace(schedule, route=other))


def test_a_graph_run_writes_both_csv_files_and_refuses_a_spline_dialect_without_jerk_limits(tmp_path):
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    result = run(scenario, outputs=Outputs(csv_dir=tmp_path / "csv"))
    assert result.method.name == "exact"
    assert result.verified.report.passed
    assert sorted(p.name for p in result.files) == ["agv1.csv", "agv2.csv"]
    assert result.summary()["route"]["travel_m"] == list(result.route.travel)
    with pytest.raises(OptionError, match="dialect 'logix-time-cam' interpolates a cubic spline"):
        run(scenario, method="toppra", outputs=Outputs(csv_dir=tmp_path / "t", dialect="logix-time-cam"))
    assert not (tmp_path / "t").exists()


def test_the_schedule_command_times_a_graph_and_writes_its_csv(tmp_path, capsys):
    assert main(["schedule", str(EXAMPLES / "h.toml"), "--csv", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "method: exact  duration: 51.500 s  verified: True" in out
    assert "agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D" in out
    header = (tmp_path / "agv1.csv").read_text().splitlines()[0]
    assert header == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m;x_m;y_m"


def test_a_graph_without_coordinates_has_no_xy_columns_and_millimetres_scale_every_length(tmp_path):
    track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    verified = certify(make_schedule(route, Limits((AGV, AGV), 1.5), method="exact"))
    metres, _ = _csv_texts(verified)
    millimetres, _ = _csv_texts(verified, CsvOptions(units="mm", delimiter=",", decimal="."))
    assert metres.splitlines()[0] == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m"
    assert millimetres.splitlines()[0] == "t_s,axis_mm,v_mmps,a_mmps2,j_mmps3,edge,s_mm"
    row_m = metres.splitlines()[500].split(";")
    row_mm = millimetres.splitlines()[500].split(",")
    assert row_m[5] == row_mm[5]
    assert row_m[0] == row_mm[0]
    for k in (1, 2, 3, 4, 6):
        assert float(row_mm[k]) == pytest.approx(1000.0 * float(row_m[k]), abs=1e-5)


def test_an_edge_name_holding_the_delimiter_is_refused_naming_it():
    track = TrackGraph.from_edges({"a;1": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    verified = certify(make_schedule(route, Limits((AGV, AGV), 1.5), method="exact"))
    with pytest.raises(OptionError, match=r"edge name 'a;1' holds the CSV delimiter ';'"):
        profile_chunk_pair(verified)
    assert _csv_texts(verified, CsvOptions(delimiter=","))[0].count("a;1") > 0


def test_a_method_that_does_not_time_graphs_says_so_naming_itself():
    route, limits = _crossing()

    class Junctions(Exact):
        name = "junctions-only"
        schedule_graph = TimingMethod.schedule_graph

    with pytest.raises(InputError, match="method 'junctions-only' does not time a track graph yet"):
        make_schedule(route, limits, method=Junctions())


@pytest.mark.slow  # seeded random graphs, each timed, verified and written: a campaign
def test_seeded_random_graphs_are_timed_and_verified_with_the_rows_safe(tmp_path):
    checked = 0
    for seed in range(400):
        case = random_case(seed, loops=seed % 2 == 1)
        if case is None:
            continue
        edges, start, goal, separation = case
        track = TrackGraph.from_edges(edges)
        try:
            route = plan_graph(track, start, goal, min_separation=separation)
        except InfeasibleError:
            continue
        limits = Limits((AGV, dataclasses.replace(AGV, max_velocity=1.4, max_jerk=2.0)), separation)
        verified = certify(make_schedule(route, limits, method="exact"))
        state = verified.schedule.sample(0.05)
        gaps = track.distances(state.edge[0], state.s[0], state.edge[1], state.s[1])
        assert np.all(gaps >= separation - 1e-9), seed
        assert verified.report.min_separation <= gaps.min() + 1e-12
        checked += 1
        if checked == 60:
            break
    assert checked == 60


def _with_acceleration_step(
    schedule: GraphSchedule, section: int, interval: int, step: float
) -> GraphSchedule:
    """The schedule with vehicle 1's acceleration stepped by ``step`` at the start of one interval."""
    profile = schedule.sections[section].kinematics.vehicles[0]
    initial = np.array(profile.initial)
    initial[interval, 2] += step
    stepped = PiecewiseCubic(profile.times, initial, profile.jerk)
    other = schedule.sections[section].kinematics.vehicles[1]
    sections = list(schedule.sections)
    sections[section] = GraphSection(sections[section].start_time, CubicKinematics((stepped, other)))
    return dataclasses.replace(schedule, sections=tuple(sections))


def test_the_verifier_finds_an_acceleration_step_and_allows_a_sign_change_only_where_the_path_turns_back():
    scenario = load_scenario(EXAMPLES / "h.toml")
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    # mid-move (the cruise of the first move): a step of 0.2 m/s^2 is a jump
    with pytest.raises(VerificationError, match=r"vehicle 1 acceleration jumps by 0.2"):
        certify(_with_acceleration_step(schedule, 0, 3, 0.2))


@pytest.mark.slow
def test_the_optimal_h_reverses_smoothly_at_the_cusp_and_verifies():
    """agv1 turns back in c at full deceleration.

    Its travel's acceleration goes -0.5 -> +0.5 m/s^2 there, the acceleration along its axis is
    continuous; the verifier allows that sign change at the cusp only.
    """
    scenario = load_scenario(EXAMPLES / "h.toml")
    optimal = make_schedule(scenario.route(), scenario.limits, method=Optimal(homotopy="planned"))
    assert optimal.fallback_reason is None
    assert certify(optimal).report.passed
    t = np.linspace(0.0, optimal.duration, 400_001)
    travel = optimal.travel(t)[0]
    k = int(np.argmin(np.abs(travel[0] - optimal.paths[0].cusps[0]) + 10.0 * np.abs(travel[1])))
    assert travel[2, k - 2] < -0.4
    assert travel[2, k + 2] > 0.4
    state = optimal.state(t[k - 2 : k + 3])
    assert np.ptp(state.acceleration[0]) < 0.01  # along the axis: no step


# -- any number of vehicles below the planners ------------------------------------------------------------


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_every_vehicle_of_a_fleet_is_timed_and_its_csv_rows_keep_every_pair_apart(case, method, tmp_path):
    """Three or four vehicles: verified, and from the CSV rows alone every pair keeps the separation."""
    verified = case.verified(method)
    schedule, route = verified.schedule, case.route()
    assert verified.report.passed, verified.report.failures
    assert schedule.count == len(verified.report.velocity_ratio) == case.count
    assert verified.report.min_separation == pytest.approx(SEPARATION, abs=1e-6)
    if method == "toppra":
        assert schedule.duration <= case.verified("exact").schedule.duration
    files = write_profiles(verified, route.names, tmp_path)
    assert [path.name for path in files] == [f"{name}.csv" for name in route.names]
    generic = DIALECTS.lookup("generic")
    rows = [generic.read(path.read_bytes(), source=path.name) for path in files]
    track = schedule.track
    distances = TrackDistances(track)  # the verifier's own Dijkstra, not the track's
    number = {edge.name: k for k, edge in enumerate(track.edges)}
    places = [
        [
            EdgePoint(number[edge], float(s))
            for edge, s in zip(row.columns["edge"], row.columns["s"], strict=True)
        ]
        for row in rows
    ]
    assert len({len(p) for p in places}) == 1  # one row per sample, the same instants in every file
    closest = min(
        distances.between(a, b)
        for i, j in itertools.combinations(range(case.count), 2)
        for a, b in zip(places[i], places[j], strict=True)
    )
    assert closest >= SEPARATION - 1e-9
    for vehicle, goal in enumerate(route.goal):
        assert distances.between(places[vehicle][-1], goal) <= 1e-9


@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_optimal_on_more_than_two_vehicles_plays_exact_and_says_why(case):
    verified = case.verified("optimal")
    assert verified.schedule.fallback_reason is FallbackReason.SETUP_FAILED
    assert verified.schedule.duration == case.verified("exact").schedule.duration
    expected = f"times two vehicles at once, the route moves {case.count}: expected exact or toppra"
    assert expected in verified.schedule.notes[0]


# -- a junction's route on its track graph: the one route every method times ---------------------------


@settings(max_examples=25)
@given(query=star_queries(3, 8), homotopy=st.sampled_from(["planned", "other"]), jerk=st.booleans())
def test_a_junctions_route_on_its_track_graph_is_timed_exactly_as_the_junction_times_it(
    query, homotopy, jerk
):
    """Two independent ways to the ``exact`` schedule: the junction's axes and the graph's travel."""
    route = planned_junction_route(query, homotopy)
    separation = query[3]
    limits = Limits(vehicles=(AGV, SLOW), min_separation=separation)
    junction = Exact(jerk=jerk).schedule(route, limits)
    on_graph = Exact(jerk=jerk).schedule_graph(junction_graph_route(route), limits)
    assert on_graph.duration == pytest.approx(junction.duration, rel=1e-12, abs=1e-12)
    # the last instant left out: at rest there a trapezoid's acceleration jumps, and each takes a side
    t = np.linspace(0.0, junction.duration, 101)[:-1]
    ours, theirs = on_graph.state(t), junction.state(t)
    # a path leaves out a move shorter than MOVE_RESOLUTION (1 nm) that a junction's axis keeps
    for name in ("axis", "velocity", "acceleration"):
        assert_allclose(getattr(ours, name), getattr(theirs, name), rtol=0, atol=2e-9, err_msg=name)
    track = on_graph.track
    for v in (0, 1):
        apart = track.distances(ours.edge[v], ours.s[v], theirs.edge[v], theirs.s[v])
        assert np.max(apart) <= 2e-9
    report = verify(on_graph)
    assert report.passed, report.failures


@pytest.mark.parametrize(
    ("name", "method"),
    [
        *((name, "toppra") for name in ("y", "4-leg", "8-leg")),
        # the 4- and 8-leg stars take optimal 7 and 21 s: benchmarks/bench_junction_on_graph.py has them
        pytest.param("y", "optimal", marks=pytest.mark.slow),
    ],
)
def test_every_method_times_a_junctions_route_on_its_track_graph_and_the_verifier_passes_it(name, method):
    scenario = case(name).scenario()
    route = junction_graph_route(scenario.route(), names=scenario.names)
    schedule = METHODS.create(method).schedule_graph(route, scenario.limits)
    report = verify(schedule)
    assert report.passed, report.failures
    assert schedule.fallback_reason is None
    exact = Exact().schedule_graph(route, scenario.limits)
    assert schedule.duration < exact.duration  # each overlaps the moves the exact one makes one by one
