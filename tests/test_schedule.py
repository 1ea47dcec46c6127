"""Schedules: exact vs toppra, stops and reversals, and the verifier catching broken schedules.

On a Y and on junctions of 4 to 8 legs (the scenarios of :mod:`tests.support.star_scenarios`);
a test of what holds for any number of legs is parametrized over it (``legs3``, ``legs4`` ...).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import assume, given, settings

from limits import Limits, VehicleLimits
from tests.support.helpers import AGV, LIMITS, MIXED, SLOW, legs_cases, legs_id, route_of, too_close
from tests.support.sampled_verifier import sampled_verify
from tests.support.star_scenarios import STAR_METHODS, STAR_SCENARIOS, leg_index, star_scenario, star_schedule
from tests.support.strategies import star_queries
from topology import JUNCTION_INDEX, Configuration, Position, WayRound, YGraph, plan
from trajgen import METHODS, Exact, Schedule, Toppra, certify, make_schedule, verify
from trajgen.errors import OptionError, VerificationError
from trajgen.model.axes import route_axes, straight_pieces
from trajgen.model.blended import ToppraKinematics
from trajgen.scenario.sampling import random_scenarios

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
