"""The online executor: paths, the braking check, the plan's order kept under faults, goals, bad input.

On junctions, then on track graphs (the braking check and the safety guard against dense sampling,
the execution form of a path and the graph metric, the executor and closed-loop runs).

The frontier and the coordination diagram are in ``test_coordination.py``; the full 200-scenario
campaign is ``benchmarks/bench_online.py``; the CLI is in ``test_simulate_cli.py``.
"""

from __future__ import annotations

import collections
import functools
import itertools
import json
import logging
import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from ruckig import ControlInterface, InputParameter, Ruckig, Trajectory

from limits import ILLUSTRATIVE_LIMITS, Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.fleets import FLEETS, SEPARATION
from tests.support.graph_cases import CONVOY, EXAMPLES, random_routes, verified_example
from tests.support.helpers import execution_plan, stop_bound
from topology import JUNCTION_INDEX, Configuration, EdgePoint, Position, StarGraph, TrackGraph, YGraph
from topology.indexed import separation as indexed_separation
from trajgen import builtin_scenario, certify, default_scenario, load_scenario, make_schedule
from trajgen.cli import main
from trajgen.errors import InputError, UnverifiedScheduleError
from trajgen.execution import (
    BrakingCheck,
    Executor,
    Mode,
    PathState,
    VehicleState,
    execution_margin,
    schedule_for_execution,
)
from trajgen.execution.braking_check import ServiceBraking, emergency_position
from trajgen.execution.faults import Fault, FaultError, FaultKind
from trajgen.execution.messages import Command, Setpoint, checked_state
from trajgen.execution.plant import GraphBody, GraphShape, Plant
from trajgen.execution.safety_guard import SafetyGuard
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.execution.tracks import GraphTrack
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.model.paths import VehiclePath
from trajgen.plots.simulation import plot_simulation
from trajgen.scenario import GraphScenario, Scenario
from trajgen.scenario.graph_sampling import graph_campaign_faults, graph_online_campaign
from trajgen.scenario.sampling import campaign_faults, online_campaign, random_scenarios
from trajgen.simulation_pipeline import run_simulation

AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
SWAP = REPO / "examples" / "swap.toml"
CROSSING = REPO / "examples" / "crossing.toml"


@pytest.fixture(autouse=True)
def _quiet():
    logging.disable(logging.WARNING)
    yield
    logging.disable(logging.NOTSET)


@pytest.fixture(scope="module")
def swap():
    # the default method (the built-in scenario is examples/swap.toml)
    return execution_plan("swap", "optimal")


# -- paths and coordination --------------------------------------------------------------------


def test_the_swap_paths_follow_the_route():
    scenario = default_scenario()
    route = scenario.route()
    for v in (0, 1):
        path = VehiclePath.from_route(route, v)
        assert path.length == pytest.approx(route.travel[v], abs=1e-12)
        start, goal = route.start[v], route.goal[v]
        leg, s = path.locate(0.0)
        assert s == pytest.approx(start.s)
        assert scenario.track.names[leg] == start.leg
        leg, s = path.locate(path.length)
        assert s == pytest.approx(goal.s)
        assert scenario.track.names[leg] == goal.leg
        # the axis is continuous and changes by exactly the travel, reversing at each stop
        axes = [path.axis(p) for p in np.linspace(0.0, path.length, 2001)]
        assert np.max(np.abs(np.diff(axes))) <= path.length / 2000 + 1e-12
    # the swap: the vehicle that parks reverses once, the other never
    assert sorted(len(VehiclePath.from_route(route, v).stops) for v in (0, 1)) == [0, 1]


@settings(max_examples=200, derandomize=True, deadline=None)
@given(fraction=st.floats(0.0, 1.0), vehicle=st.sampled_from([0, 1]))
def test_project_undoes_locate(fraction, vehicle):
    route = default_scenario().route()
    path = VehiclePath.from_route(route, vehicle)
    p = fraction * path.length
    leg, s = path.locate(p)
    assert path.project(leg, s, p) == pytest.approx(p, abs=1e-9)


@settings(max_examples=300, derandomize=True, deadline=None)
@given(
    stops=st.lists(st.tuples(st.integers(0, 2), st.floats(0.0, 10.0)), min_size=2, max_size=6),
    fraction=st.floats(-0.05, 1.05),
    wobble=st.floats(-0.2, 0.2),
    lag=st.floats(-0.5, 0.5),
    slack=st.sampled_from([1e-9, 0.05]),
)
def test_project_takes_the_same_place_as_the_search_over_every_segment(stops, fraction, wobble, lag, slack):
    """The shortcut through ``near``'s own segment agrees with the search over all segments."""
    path = VehiclePath.from_waypoints([(leg, s, 0, 10.0) for leg, s in stops], 0)
    leg, s = path.locate(fraction * path.length)
    s = max(s + wobble, 0.0)
    near = fraction * path.length + lag
    fast = path.project(leg, s, near, slack)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(VehiclePath, "_project_on_segment_of", lambda *_: None)
        assert path.project(leg, s, near, slack) == fast


@settings(max_examples=100, derandomize=True, deadline=None)
@given(
    stops=st.lists(st.tuples(st.integers(0, 2), st.floats(0.0, 10.0)), min_size=2, max_size=6),
    ends=st.tuples(st.floats(-0.1, 1.1), st.floats(-0.1, 1.1)),
)
def test_sweep_covers_exactly_the_track_passed_over(stops, ends):
    """Every place passed over a travel range lies in the sweep, and each stretch's ends are passed."""
    path = VehiclePath.from_waypoints([(leg, s, 0, 10.0) for leg, s in stops], 0)
    lengths = (12.0, 12.0, 12.0)
    low, high = sorted(f * path.length for f in ends)
    stretches = path.sweep(low, high, lengths)
    samples = np.linspace(low, high, 2001)
    step = (high - low) / 2000 + 1e-9
    # a place on the track: the junction counts as s = 0 on every leg
    places = []
    for p in samples:
        k = path.segment(p)
        leg, s = path.locate(p)
        if p < 0.0 or p > path.length:  # the run-on of the end segments along their legs
            outward = 1.0 if path.s_to[k] > path.s_from[k] else -1.0
            leg, s = path.legs[k], min(max(path.s_from[k] + outward * (p - path.starts[k]), 0.0), 12.0)
        places.append((path.legs[k] if leg < 0 else leg, s))

    def apart(a, b):  # track distance between two places (leg, s), metres
        return abs(a[1] - b[1]) if a[0] == b[0] else a[1] + b[1]

    for place in places:
        assert any(
            place[1] <= 1e-9 or (leg == place[0] and lo - 1e-9 <= place[1] <= hi + 1e-9)
            for leg, lo, hi in stretches
        ), (place, stretches)
    for leg, lo, hi in stretches:
        assert min(apart((leg, lo), place) for place in places) <= step
        assert min(apart((leg, hi), place) for place in places) <= step


@settings(max_examples=200, derandomize=True, deadline=None)
@given(fraction=st.floats(-0.1, 1.1), vehicle=st.sampled_from([0, 1]))
def test_place_agrees_with_the_separate_lookups(fraction, vehicle):
    route = default_scenario().route()
    path = VehiclePath.from_route(route, vehicle)
    p = fraction * path.length
    leg, s, heading, axis, branch = path.place(p)
    assert (leg, s) == path.locate(p)
    assert heading == path.heading(p)
    assert axis == path.axis(p)
    k = path.segment(p)
    # the leg taken at the next junction passage: the next segment's when this one ends there
    ahead = path.legs[k + 1] if path.s_to[k] == 0.0 and k + 1 < len(path.legs) else path.legs[k]
    assert branch == ahead


def test_a_round_off_overshoot_of_a_tiny_first_move_is_not_read_as_the_far_end():
    """Campaign scenario 132: a re-plan nudged the vehicle 6.7 um outwards before turning it back.

    The drive overshot that nudge by 0.15 um; the run-on of the last segment (C, outwards past the
    goal) holds the point exactly, 26 m away. The vehicle is where it was told to be: travel ~0.
    """
    waypoints = [(2, 7.612807, 0, 2.0), (2, 7.6128137, 0, 2.0), (1, 5.6, 0, 2.0), (2, 0.8895, 0, 2.0)]
    path = VehiclePath.from_waypoints(waypoints, 0)
    assert path.legs == (2, 2, 1, 1, 2)
    p = path.project(2, 7.6128137 + 1.5e-7, near=1e-5, slack=0.05)
    assert p == pytest.approx(6.7e-6, abs=1e-6)
    # well past the goal, the run-on is the only place: a travel beyond the length
    assert path.project(2, 3.0, near=path.length, slack=0.05) == pytest.approx(path.length + 3.0 - 0.8895)


@pytest.mark.parametrize("dust", [0.0, 3.1e-15, 1.07e-14], ids=["exact", "3e-15", "1e-14"])
def test_a_pass_through_the_junction_is_one_turn_whatever_the_round_off(dust):
    """Campaign scenario 40: a timed vertex at the junction came out 3e-15 m up the leg.

    The path must still pass straight from leg B onto C (no sliver of B after the junction), so
    that on B its next leg is C: a drive told to stay on B would stop dead at the junction.
    """
    waypoints = [(1, 1.7, 0, 9.0), (1, dust, 0, 9.0), (2, 0.09, 0, 9.0), (2, 20.0, 0, 9.0)]
    path = VehiclePath.from_waypoints(waypoints, 0)
    assert path.legs == (1, 2)
    assert path.s_to[0] == 0.0
    assert path.s_from[1] == 0.0
    assert path.place(1.0)[4] == 2  # on B, heading for C
    assert path.length == pytest.approx(1.7 + 20.0, abs=1e-12)
    assert path.stops == ()


# -- the braking check ---------------------------------------------------------------------------


def one_leg_paths():
    """Vehicle 1 behind vehicle 2 on leg A, both driving outwards (A:10 -> 60, A:30 -> 80)."""
    track = YGraph({"A": 100.0, "B": 100.0, "C": 100.0})
    waypoints = [(0, 10.0, 0, 30.0), (0, 60.0, 0, 80.0)]
    return track, (VehiclePath.from_waypoints(waypoints, 0), VehiclePath.from_waypoints(waypoints, 1))


def service_distance(v: float, limits: VehicleLimits) -> float:
    """Closed form: jerk-limited braking from (v, a=0) to rest when v >= a_max**2 / j_max."""
    a, j = limits.max_acceleration, limits.max_jerk
    return v * v / (2.0 * a) + v * a / (2.0 * j)


@pytest.mark.parametrize(("offset", "safe"), [(0.01, True), (-0.01, False)], ids=["room", "1cm-short"])
def test_a_follower_must_stop_short_of_a_standing_leader(offset, safe):
    track, paths = one_leg_paths()
    check = BrakingCheck((AGV, AGV), (1.0, 1.0), track.lengths)
    gap = 5.0 + service_distance(1.0, AGV) + offset  # 5 m separation + 1.25 m to stop
    follower = PathState(0.0, 1.0, 0.0)
    leader = PathState(gap - 20.0, 0.0, 0.0)  # vehicle 2's path starts 20 m further out
    assert check.clearance(paths, (follower, leader), (follower, leader), 5.0) is safe


@pytest.mark.parametrize(("offset", "safe"), [(0.01, True), (-0.01, False)], ids=["room", "1cm-short"])
def test_a_follower_must_stop_behind_a_leader_making_an_emergency_stop(offset, safe):
    """Both at 1 m/s; the leader stops in 0.5 m (1 m/s²), the follower needs 1.25 m: 0.75 m more gap."""
    track, paths = one_leg_paths()
    check = BrakingCheck((AGV, AGV), (1.0, 1.0), track.lengths)
    gap = 5.0 + service_distance(1.0, AGV) - 0.5 + offset
    follower = PathState(0.0, 1.0, 0.0)
    leader = PathState(gap - 20.0, 1.0, 0.0)
    assert check.clearance(paths, (follower, leader), (follower, leader), 5.0) is safe


def braking_positions(state: PathState, limits: VehicleLimits, times: np.ndarray) -> np.ndarray:
    """Independent service braking along the travel: Ruckig's velocity interface, sampled."""
    generator, inp, trajectory = Ruckig(1), InputParameter(1), Trajectory(1)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position, inp.current_velocity, inp.current_acceleration = [state.p], [state.v], [state.a]
    inp.target_velocity, inp.target_acceleration = [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration = [limits.max_velocity], [limits.max_acceleration]
    inp.max_jerk = [limits.max_jerk]
    generator.calculate(inp, trajectory)
    return np.array([trajectory.at_time(min(t, trajectory.duration))[0][0] for t in times])


def _legs_and_s(path: VehiclePath, travel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``VehiclePath.locate`` of many travels at once: leg (-1 at the junction) and ``s``."""
    starts, s_from, s_to = (np.array(a) for a in (path.starts, path.s_from, path.s_to))
    k = np.maximum(np.searchsorted(starts, travel, side="right") - 1, 0)
    local = np.clip(travel - starts[k], 0.0, np.abs(s_to[k] - s_from[k]))
    s = s_from[k] + np.where(s_to[k] > s_from[k], local, -local)
    return np.where(s > 0.0, np.array(path.legs)[k], -1), s


def track_distance(paths, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Track distance at each pair of travels: ``|s1 - s2|`` on one leg, else ``s1 + s2``."""
    (leg1, s1), (leg2, s2) = _legs_and_s(paths[0], first), _legs_and_s(paths[1], second)
    return np.where((leg1 == leg2) & (leg1 >= 0), np.abs(s1 - s2), s1 + s2)


def test_the_vectorized_track_distance_agrees_with_the_planners():
    route = default_scenario().route()
    paths = tuple(VehiclePath.from_route(route, v) for v in (0, 1))
    rng = np.random.default_rng(5)
    one, two = rng.uniform(-1.0, paths[0].length + 1.0, 500), rng.uniform(-1.0, paths[1].length + 1.0, 500)
    expected = [
        indexed_separation((*paths[0].locate(p), *paths[1].locate(q))) for p, q in zip(one, two, strict=True)
    ]
    assert track_distance(paths, one, two) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("refine", [False, True], ids=["new-motion", "hold"])
@settings(max_examples=30, derandomize=True, deadline=None)
@given(
    data=st.data(),
    fraction=st.floats(0.0, 1.0),
    speeds=st.tuples(st.floats(-0.2, 1.0), st.floats(-0.2, 1.0)),
    accelerations=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),
)
def test_what_the_check_certifies_holds_under_every_braking_of_both(
    refine, data, fraction, speeds, accelerations
):
    """The braking invariant, against an independent dense simulation (1 ms) of the braking motions.

    Both vehicles of the swap somewhere along their paths; if the check certifies the pair, then with
    each vehicle braking at service (from its command) or stopping at its emergency deceleration
    (from its measurement), in all four combinations, the track distance stays above the requirement.
    Also for the check of a hold, whose unclear intervals are halved.
    """
    scenario = default_scenario()
    route = scenario.route()
    paths = tuple(VehiclePath.from_route(route, v) for v in (0, 1))
    first = fraction * paths[0].length
    second = data.draw(st.floats(0.0, paths[1].length))
    commanded = tuple(
        PathState(p, v, a) for p, v, a in zip((first, second), speeds, accelerations, strict=True)
    )
    measured = tuple(PathState(c.p - 0.001 * c.v, c.v, c.a) for c in commanded)
    required = 1.5
    check = BrakingCheck((AGV, AGV), (1.0, 1.0), scenario.track.lengths)
    if not check.clearance(paths, commanded, measured, required, refine=refine):
        return
    times = np.arange(0.0, 6.0, 0.001)
    service = [braking_positions(c, AGV, times) for c in commanded]
    emergency = [np.array([emergency_position(m, 1.0, t) for t in times]) for m in measured]
    for one in (service[0], emergency[0]):
        for two in (service[1], emergency[1]):
            # 1 ms samples: at 1 m/s each, at most 1 mm between samples
            assert track_distance(paths, one, two).min() >= required - 2e-3


def test_a_stop_that_runs_past_a_goal_at_the_junction_is_not_certified(tmp_path):
    """A vehicle 1 cm before its goal at the junction at 0.5 m/s runs past it: not certified.

    agv1's goal is the junction O, agv2's C:1.5, exactly the separation away; agv1's emergency stop
    runs 11.5 cm past O onto one of the legs (1.385 m from agv2 if it is C). The sweep stops at O
    (the end of agv1's leg A); the 11.5 cm past it are its overrun, taken off the distance, so the
    check refuses; arriving at rest, the same plan is certified.
    """
    text = (REPO / "examples" / "swap.toml").read_text()
    text = text.replace('goal = "B:10.0"', 'goal = "O"').replace(
        'start = "B:10.0"\ngoal = "A:10.0"', 'start = "B:10.0"\ngoal = "C:1.5"'
    )
    scenario_file = tmp_path / "goal_at_the_junction.toml"
    scenario_file.write_text(text)
    scenario = load_scenario(scenario_file)
    paths = tuple(VehiclePath.from_route(scenario.route(), v) for v in (0, 1))
    assert paths[0].locate(paths[0].length) == (JUNCTION_INDEX, 0.0)
    assert paths[1].locate(paths[1].length) == (2, 1.5)
    lengths = scenario.track.lengths
    assert paths[0].overrun(paths[0].length, paths[0].length + 0.115, lengths) == pytest.approx(0.115)
    # 0.115 m past O on leg C, by the planner's own track distance
    assert indexed_separation((2, 0.115, 2, 1.5)) == pytest.approx(1.385)
    check = BrakingCheck((AGV, AGV), (1.0, 1.0), lengths)
    ends = (PathState(paths[0].length, 0.0, 0.0), PathState(paths[1].length, 0.0, 0.0))
    running_on = (PathState(paths[0].length - 0.01, 0.5, 0.0), ends[1])
    assert not check.clearance(paths, ends, running_on, 1.5 - 1e-6)
    assert check.clearance(paths, ends, ends, 1.5 - 1e-6)


# -- the executor: undisturbed, every method plays its plan -------------------------------------


@pytest.fixture(scope="module")
def plans():
    """The plan for execution of each method on the swap and the crossing, computed once."""
    return {
        (name, method): execution_plan(name, method)
        for name in ("swap", "crossing")
        for method in ("exact", "toppra", "optimal")
    }


@pytest.mark.slow
@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
@pytest.mark.parametrize("name", ["swap", "crossing"])
def test_an_undisturbed_run_executes_its_plan_within_one_percent_and_never_brakes(plans, name, method):
    scenario, verified = plans[name, method]
    assert verified.schedule.fallback_reason is None, verified.schedule.notes
    result, _ = simulate(scenario, (), verified=verified)
    assert result.reached_goal
    assert result.violations == 0
    assert result.holds == 0
    assert result.emergency_brakes == 0
    assert (
        abs(result.makespan_s - result.planned_s) <= 0.01 * result.planned_s + 0.011
    )  # a cycle of round-off
    assert not [e for e in result.events if e.kind == "retime"]  # nobody left the plan's clock


# -- stops: the table, and a stop at any moment -----------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "method", "fault"),
    [
        ("swap", "exact", "stop:agv2@5+3"),
        ("swap", "exact", "stop:agv1@21.8+4.97"),
        ("swap", "toppra", "stop:agv2@23.65+4.51"),
        ("crossing", "exact", "stop:agv2@26.48+1.43"),
    ],
    ids=["swap-exact-agv2-5", "swap-exact-agv1-21.8", "swap-toppra-agv2-23.65", "crossing-exact-agv2-26.48"],
)
def test_a_stop_costs_about_its_own_length(plans, name, method, fault):
    """The runs that took 132.8 s, 70.3 s, 66.2 s and 129 s longer than planned in v0.6.0."""
    scenario, verified = plans[name, method]
    faults = parse_faults(scenario, [fault])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal
    assert result.violations == 0
    assert result.emergency_brakes == 0
    assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value), result.summary()


def _assert_a_stop_costs_at_most_its_bound(scenario, verified, spec: str) -> None:
    """The plan with the stop ``spec`` reaches its goal, keeps every limit, costs at most the bound."""
    faults = parse_faults(scenario, [spec])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal, spec
    assert result.violations == 0, spec
    assert result.emergency_brakes == 0, spec
    assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value), (
        spec,
        result.summary(),
    )


@pytest.mark.slow
@settings(max_examples=2, deadline=None)
@given(moment=st.floats(0.0, 1.0), duration=st.floats(0.2, 8.0), vehicle=st.sampled_from([0, 1]))
@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
@pytest.mark.parametrize("name", ["swap", "crossing"])
def test_a_single_stop_at_any_moment_costs_at_most_its_bound(plans, name, method, moment, duration, vehicle):
    scenario, verified = plans[name, method]
    at = round(moment * verified.schedule.duration, 3)
    _assert_a_stop_costs_at_most_its_bound(
        scenario, verified, f"stop:{scenario.names[vehicle]}@{at}+{round(duration, 3)}"
    )


def random_plans(kind: str, count: int):
    """Seeded random scenarios (a Y of random legs, or a 4-leg star) and their exact plans for execution."""
    rng = random.Random(2026)
    out = []
    for k in range(count):
        if kind == "star":
            track = StarGraph({name: rng.uniform(6.0, 14.0) for name in "NWSE"})
        else:
            track = YGraph({name: rng.uniform(4.0, 16.0) for name in "ABC"})
        (scenario,) = random_scenarios(1, seed=500 + k, track=track, limits=ILLUSTRATIVE_LIMITS)
        out.append((scenario, schedule_for_execution(scenario, method=rng.choice(["exact", "toppra"]))))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["y", "star"], ids=["random-y", "4-leg-star"])
def test_single_stops_on_random_tracks_cost_at_most_their_bound(kind):
    rng = random.Random(7)
    for scenario, verified in random_plans(kind, 4):
        vehicle = rng.randrange(2)
        at = round(rng.uniform(0.0, verified.schedule.duration), 3)
        spec = f"stop:{scenario.names[vehicle]}@{at}+{round(rng.uniform(0.5, 5.0), 3)}"
        faults = parse_faults(scenario, [spec])
        result, _ = simulate(scenario, faults, verified=verified)
        assert result.reached_goal, spec
        assert result.violations == 0, spec
        assert result.emergency_brakes == 0, spec
        assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value), spec


@pytest.mark.parametrize(("fraction", "duration"), [(0.5, 6.0), (0.2, 4.0)], ids=["half-6s", "fifth-4s"])
@pytest.mark.parametrize("name", ["swap", "crossing"])
def test_a_slowdown_costs_at_most_its_lost_distance_plus_the_slack(plans, name, fraction, duration):
    scenario, verified = plans[name, "exact"]
    vehicle = scenario.limits.vehicles[1]
    spec = f"slow:{scenario.names[1]}@3+{duration}={fraction * vehicle.max_velocity}"
    result, _ = simulate(scenario, parse_faults(scenario, [spec]), verified=verified)
    assert result.reached_goal
    assert result.violations == 0
    assert result.emergency_brakes == 0
    bound = duration * (1.0 - fraction) + stop_bound(scenario, 0.0)
    assert result.makespan_s - result.planned_s <= bound, result.summary()


def test_a_waiting_follower_starts_the_moment_its_leader_moves_on(plans):
    """agv1 stops 25 s just before it crosses to B: agv2, due out of C, waits at its frontier instead.

    The moment agv1's earliest rest point is past the conflict, agv2's frontier lifts and agv2
    starts at once with a full Ruckig profile: no creeping (v0.6.0 ramped up at 0.005 m/s² here).
    """
    scenario, verified = plans["swap", "exact"]
    records = []

    def watch(executor, measured, command):
        records.append(
            (command.time, executor.travel[1], command.frontiers[1], abs(command.setpoints[1].velocity))
        )

    result, _ = simulate(
        scenario, parse_faults(scenario, ["stop:agv1@33+25"]), verified=verified, observer=watch
    )
    assert result.reached_goal
    assert result.violations == 0
    times, travel, frontier, speed = (np.array(column) for column in zip(*records, strict=True))
    waiting = (times > 45.0) & (frontier < travel + 0.01) & (speed == 0.0)
    assert waiting.any()  # agv2 did wait at its frontier
    lifted = times[(times > times[waiting][-1]) & (frontier > travel + 1.0)][0]
    started = times[(times >= lifted) & (speed > 0.05)][0]
    assert started - lifted <= 0.2 + 1e-9  # within a few cycles of its leader moving on
    top = scenario.limits.vehicles[1].max_velocity
    assert speed[(times > started) & (times < started + 8.0)].max() >= 0.99 * top


# -- goals: the only thing that re-plans ---------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("method", ["exact", "optimal"])
def test_a_new_goal_mid_run_is_reached_with_no_violation(plans, method):
    scenario, verified = plans["swap", method]
    faults = parse_faults(scenario, ["goal:agv2@12=C:6"])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    assert result.emergency_brakes == 0
    assert result.replans == 1
    assert [e.kind for e in result.events if e.kind in ("goal-accepted", "replan")] == [
        "goal-accepted",
        "replan",
    ]


def test_nothing_but_a_goal_re_plans(plans):
    scenario, verified = plans["swap", "exact"]
    faults = parse_faults(scenario, ["stop:agv1@2+5", "slow:agv2@10+4=0.3", "lag:agv1@20=120"])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal
    assert result.violations == 0
    assert result.replans == 0


@pytest.mark.slow
@settings(max_examples=6, derandomize=True, deadline=None)
@given(
    name=st.sampled_from(["swap", "crossing"]),
    vehicle=st.sampled_from(["agv1", "agv2"]),
    when=st.floats(0.05, 0.9),
    delay=st.floats(20.0, 200.0),
)
def test_a_lagging_drive_never_moves_a_frontier_back(plans, name, vehicle, when, delay):
    """A late drive's frontier partner only gains room: frontiers never move back.

    ONLINE-EXECUTION.md 3: the set F minimises over only shrinks, also while a drive runs late.
    """
    scenario, verified = plans[name, "exact"]
    spec = f"lag:{vehicle}@{when * verified.schedule.duration:.3f}={delay:.1f}"
    seen: list[tuple[float, float]] = []

    def watch(executor, measured, command):
        seen.append(command.frontiers)

    result, _ = simulate(scenario, parse_faults(scenario, [spec]), verified=verified, observer=watch)
    assert result.reached_goal, spec
    assert result.violations == 0, spec
    assert result.emergency_brakes == 0, spec
    frontiers = np.nan_to_num(np.array(seen), posinf=1e18)  # inf: nothing binds
    assert np.all(np.diff(frontiers, axis=0) >= -1e-9), spec


def test_a_drive_still_short_of_its_reversal_is_read_before_it(swap):
    """Vehicle 2 of the swap reverses at the tip of its dodge, and its drive runs 0.2 s late.

    When its commands have turned at the tip, the drive is still short of it, moving out: one
    place, two travels (before and after the tip). It is read before the tip, where it is: its
    travel only grows. Read after the tip, its travel would run back as it drives on to the tip,
    and with it its earliest rest and vehicle 1's frontier.
    """
    _, verified = swap
    executor = Executor(verified)
    tip = executor.paths[1].stops[0]
    setpoints = collections.deque([VehicleState(*executor.paths[1].locate(0.0))] * 20, maxlen=20)
    first = VehicleState(*executor.paths[0].locate(0.0))
    readings = []
    while executor.mode is not Mode.DONE and len(readings) < 20_000:
        command = executor.step((first, setpoints[0]))  # vehicle 2 measured where it was told 20 cycles ago
        readings.append(executor.travel[1])
        first, second = (VehicleState(sp.leg, sp.s, sp.velocity, sp.acceleration) for sp in command.setpoints)
        setpoints.append(second)
    readings = np.array(readings)
    assert readings.max() > tip + 1.0  # it came out of its dodge
    assert np.all(np.diff(readings) >= -1e-9)


# -- the campaign's regressions (the full one: benchmarks/bench_online.py) ---------------------

CAMPAIGN_SEED = 11


# the three with the default method (optimal); the executor's own regressions with exact,
# whose plans reach the same situations in a fraction of the planning time
CAMPAIGN_REGRESSIONS = [(k, None) for k in (121, 180, 191)]
CAMPAIGN_REGRESSIONS += [(k, "exact") for k in (6, 113, 155, 187, 40, 132)]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("k", "method"),
    CAMPAIGN_REGRESSIONS,
    ids=[
        f"scenario-{k}-{getattr(method, 'name', method) or 'default'}" for k, method in CAMPAIGN_REGRESSIONS
    ],
)
def test_campaign_scenarios_that_failed_reach_their_goals_safely(k, method):
    """Campaign scenarios (seed 11) that failed: 121 and 191 never reached their goals in v0.6.0.

    180 broke the separation 120,562 times; the others failed during the redesign (a jump at a
    reversal, a wrong stopping bound, conflicts that touch at a point, a lag; 40: a lag through a
    junction vertex timed 3e-15 m up its leg; 132: a re-plan's 7 um first move read as its goal).
    """
    scenario = online_campaign(k + 1, seed=CAMPAIGN_SEED)[k]
    verified = schedule_for_execution(scenario, method=method)
    margin = execution_margin(scenario, 0.05)
    specs = campaign_faults(scenario, verified.schedule.duration, seed=1000 + k, margin=margin)
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, (specs, result.summary())
    assert result.separation_violations == 0, specs
    assert result.limit_violations == 0, specs
    assert result.emergency_brakes == 0, specs
    assert result.certified_separation_m >= scenario.limits.min_separation - 1e-6


#: The 1,000-scenario campaign on another seed (``bench_online.py --count 1000 --seed 12 --method exact``)
#: left these short of their goals; each checks one fix, in a few seconds.
SEED_12_REGRESSIONS = {
    71: "a vehicle whose first plan never moved: its axis taken to run the other way after a re-plan",
    742: "a re-plan whose route began with a 2e-14 m move: read as the first, it reversed the axis",
    0: "a stop, then a goal change: a re-planned route beginning with a round-off move (as 742)",
    296: "a lag, then a goal change: a re-planned route beginning with a round-off move (as 742)",
}


@pytest.mark.slow
@pytest.mark.parametrize("k", sorted(SEED_12_REGRESSIONS), ids=lambda k: f"scenario-{k}")
def test_seed_12_campaign_scenarios_that_deadlocked_reach_their_goals_safely(k):
    scenario = online_campaign(k + 1, seed=12)[k]
    verified = schedule_for_execution(scenario, method="exact")
    margin = execution_margin(scenario, 0.05)
    specs = campaign_faults(scenario, verified.schedule.duration, seed=1000 + k, margin=margin)
    assert any(spec.startswith("goal:") for spec in specs), specs  # each failed after a new goal
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, (SEED_12_REGRESSIONS[k], specs, result.summary())
    assert result.replans >= 1
    assert result.separation_violations == 0, specs
    assert result.limit_violations == 0, specs
    assert result.emergency_brakes == 0, specs


@pytest.mark.slow
@pytest.mark.parametrize("k", [52, 583, 965, 280, 495], ids=lambda k: f"scenario-{k}")
def test_seed_12_campaign_scenarios_that_braked_hard_keep_the_braking_invariant(k):
    """Followers closing on a leader still crossing the junction: holds, and no emergency brake.

    The braking check's intervals are pessimistic by about the distance both vehicles drive over
    one. With 40 of them it refused holds that kept the separation by 1.6 mm (52: 48 emergency
    cycles, 583: 2, 965: 3); a hold is now checked with unclear intervals halved until they clear
    or the tubes meet. Checked that finely, new motion crept to within a millimetre of the
    boundary, where no hold was left (280, 495: tens of thousands of emergency cycles, never at
    the goal); new motion keeps the coarse check, whose pessimism is the holds' room.
    """
    scenario = online_campaign(k + 1, seed=12)[k]
    verified = schedule_for_execution(scenario, method="exact")
    margin = execution_margin(scenario, 0.05)
    specs = campaign_faults(scenario, verified.schedule.duration, seed=1000 + k, margin=margin)
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, (specs, result.summary())
    assert result.holds > 0  # the follower did have to hold
    assert result.emergency_brakes == 0, specs
    assert result.separation_violations == 0, specs
    assert result.certified_separation_m >= scenario.limits.min_separation - 1e-6


def test_a_re_plan_continues_each_vehicles_axis_from_where_it_stands():
    """The new plan's axes start at the vehicles' measured places, not at their last setpoints.

    Seed 12, scenario 755: a throttled drive came to rest 0.4 mm short of its setpoint; the re-plan
    started there but took the setpoint's axis value, so the drive, landing on its axis setpoints,
    stayed 0.4 mm off its path ever after, short of a reversal at a leg's end that its follower
    waited for: a deadlock.
    """
    scenario = load_scenario(SWAP)
    verified = schedule_for_execution(scenario, method="exact")
    executor = Executor(verified, min_separation=scenario.limits.min_separation)
    short = 0.004  # metres: inside the position tolerance, so still on the setpoints
    states = []
    for v in (0, 1):
        leg, s = executor.paths[v].locate(short)
        states.append(VehicleState(leg, s, 0.0, 0.0))
    old = executor.paths
    assert executor.request_goal(0, scenario.goal.first).accepted
    executor.step(states)
    assert executor.replans == 1
    for v in (0, 1):
        assert executor.paths[v].axis(0.0) == pytest.approx(old[v].axis(short), abs=1e-12)
        assert executor.paths[v].locate(0.0) == pytest.approx(old[v].locate(short), abs=1e-12)


@pytest.mark.parametrize("direction", [1.0, -1.0], ids=["axis-up", "axis-down"])
def test_a_vehicle_at_rest_at_the_junction_leaves_it_onto_the_leg_its_setpoint_names(direction):
    """At the junction every move leaves it: onto the named leg, whichever way its axis runs.

    Seed 12, scenario 71 (with a path that never moved): the plant drove a vehicle parked at the
    junction along the leg it came from, the wrong one, or not at all.
    """
    scenario = load_scenario(SWAP)
    verified = schedule_for_execution(scenario, method="exact")
    plant = Plant(Executor(verified, min_separation=scenario.limits.min_separation), (), 0.01)
    body = plant.bodies[0]
    body.s = 0.0
    body.branch = 2 if body.leg != 2 else 1
    body.move(direction * 0.02, plant.lengths)
    assert (body.leg, body.s) == (body.branch, pytest.approx(0.02))


# -- requests and bad input ---------------------------------------------------------------------


def test_a_goal_too_close_to_the_other_goal_is_refused_with_the_reason(swap):
    scenario, verified = swap
    executor = Executor(verified, min_separation=1.5)
    decision = executor.request_goal(0, Position("A", 9.0))  # 1 m from vehicle 2's goal A:10
    assert not decision.accepted
    assert "expected at least 1.600 m" in decision.reason
    assert "(separation + twice the position margin" in decision.reason  # 1.5 + 2 x 0.05
    assert "A:10" in decision.reason
    assert executor.rejected_goals == 1
    assert executor.goal == scenario.goal  # the run continues to the previous goals


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda e: e.step((VehicleState(0, math.nan), VehicleState(1, 10.0))), "measured s must be a finite"),
        (lambda e: e.step((VehicleState(5, 1.0), VehicleState(1, 10.0))), "measured leg must be"),
        (lambda e: e.step((VehicleState(0, 11.0), VehicleState(1, 10.0))), r"measured s 11.0 m is off leg 0"),
        (lambda e: e.step((VehicleState(0, 1.0),)), r"states: expected 2, one per vehicle, got 1"),
        (
            lambda e: e.step(VehicleState(0, 1.0)),
            "states must be a sequence of VehicleStates, one per vehicle",
        ),
        (lambda e: e.step(((0, 1.0), VehicleState(1, 10.0))), "must be a VehicleState"),
        (lambda e: e.request_speed_limit(0, 2.0), r"speed limit of vehicle 1 must be > 0 and <= 1.0"),
        (lambda e: e.request_goal(2, Position("A", 1.0)), "vehicle must be an index from 0 to 1"),
    ],
    ids=[
        "nan-s",
        "bad-leg",
        "off-leg",
        "one-state-for-two",
        "not-a-sequence",
        "not-a-state",
        "speed-above-limit",
        "bad-vehicle",
    ],
)
def test_bad_input_to_the_executor(swap, call, match):
    executor = Executor(swap[1], min_separation=1.5)
    with pytest.raises(InputError, match=match):
        call(executor)


@pytest.mark.slow
def test_the_executor_on_a_crossing_checks_legs_by_count():
    scenario = builtin_scenario("crossing")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    executor = Executor(verified)
    with pytest.raises(
        InputError,
        match=r"measured leg must be a leg index 0 to 3 of the 4 legs or -1 \(the junction\), got 4",
    ):
        executor.step((VehicleState(4, 1.0), VehicleState(2, 10.0)))
    command = executor.step((VehicleState(0, 10.0), VehicleState(2, 10.0)))  # leg 3 (E) is known: no error
    assert len(command.setpoints) == 2


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"period": 0.5}, r"control period must be 0.002 to 0.1 s, got 0.5"),
        ({"min_separation": 3.0}, r"min_separation must be between 0 m and the schedule's"),
        ({"position_tolerance": 0.0}, r"position_tolerance \(m\) must be a finite number > 0"),
    ],
    ids=["period", "separation", "tolerance"],
)
def test_bad_executor_options(swap, options, match):
    with pytest.raises(InputError, match=match):
        Executor(swap[1], **options)


def test_the_executor_takes_only_verified_schedules():
    scenario = default_scenario()
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    with pytest.raises(UnverifiedScheduleError, match="Executor"):
        Executor(schedule)
    assert Executor(certify(schedule)).mode is Mode.FOLLOWING


def test_the_margin_shrinks_where_the_track_has_no_room():
    track = YGraph({"A": 10.0, "B": 3.0, "C": 10.0})
    start = Configuration(Position("A", 10.0), Position("B", 3.0))
    tight = Limits((AGV, AGV), min_separation=3.0)  # the shortest leg
    scenario = Scenario(track, tight, ("agv1", "agv2"), start, start.swapped(), "<test>")
    assert execution_margin(scenario, 0.05) == 0.0
    with pytest.raises(InputError, match=r"jump.*out of range: expected 0 < \|DS\| <= 0.0 m"):
        parse_faults(scenario, ["jump:agv1@1=0.01"])
    result, _ = simulate(scenario, (), method="exact")
    assert result.reached_goal
    assert result.violations == 0


def test_a_setpoint_naming_no_next_leg_leaves_the_plants_vehicle_on_a_leg(plans):
    """A parked path at the junction names no next leg: the plant keeps its vehicle on a leg.

    Seed 12 of the campaign: a re-planned path that never moves, parked at the junction, named the
    junction as the leg it takes next. A drive correction past the junction then put the simulated
    vehicle on leg -1 at s = 0.023 m, which the executor refused as off the track.
    """
    scenario, verified = plans["swap", "exact"]
    plant = Plant(Executor(verified, min_separation=scenario.limits.min_separation), (), 0.01)
    body = plant.bodies[0]
    body.s, body.v, body.a = 0.0, 0.0, 0.0  # parked exactly at the junction on its leg
    across = body.axis - body.orientation * 0.02  # 2 cm on, through the junction
    parked = Setpoint(across, 0.0, 0.0, 0.0, JUNCTION_INDEX, 0.0, JUNCTION_INDEX)
    other = plant.bodies[1]
    still = Setpoint(other.axis, 0.0, 0.0, 0.0, other.leg, other.s, other.branch)
    plant.advance(Command(0.01, (parked, still), Mode.FOLLOWING), 0.0)
    state = plant.measure()[0]
    assert state.leg >= 0 or state.s == 0.0, state
    checked_state(state, 1, scenario.track)  # what the executor reads: a place on the track


def test_a_vehicle_that_stays_put_through_a_re_plan_drives_its_next_move_the_right_way(plans):
    """A plan in which a vehicle does not move keeps the way its axis runs.

    agv1 stays put while agv2 re-plans; it drove its own next move the wrong way, off its
    setpoints, and never arrived.
    """
    scenario, verified = plans["swap", "exact"]
    planned = verified.schedule.duration
    specs = [f"goal:agv1@{planned + 3:g}=B:5", f"goal:agv2@{planned + 30:g}=A:8"]
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, result.summary()
    assert result.replans == 2
    assert result.violations == 0
    assert not any("off its setpoints" in e.detail for e in result.events), result.events


def test_step_of_two_states_is_deprecated_and_steps_as_one_sequence(swap):
    states = (VehicleState(0, 10.0), VehicleState(1, 10.0))
    with pytest.warns(DeprecationWarning, match=r"step\(first, second\) is deprecated since trajgen 0.7"):
        old = Executor(swap[1], min_separation=1.5).step(*states)
    assert old == Executor(swap[1], min_separation=1.5).step(states)


# -- track graphs: the execution form of a path and the graph metric -------------------------------------


FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


def _cases():
    """Every example's route and 12 seeded random ones (trees and loops), with both paths."""
    for name in FEASIBLE:
        scenario, verified = verified_example(name, "exact")
        yield name, scenario.track, verified.schedule.route
    for seed, route, _ in random_routes(12, 5000):
        yield f"seed {seed}", route.track, route


CASES = list(_cases())


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_place_axis_and_heading_agree_with_the_schedules_path(name, track, route):
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        p = np.linspace(0.0, path.length, 401)
        edges, s = path.locate(p)
        for k, q in enumerate(p):
            edge, along, heading, axis, _ = fast.place(float(q))
            assert fast.locate(float(q)) == (edge, along)
            assert track.distances([edge], [along], [edges[k]], [s[k]])[0] <= 1e-9, (name, q)
            assert axis == pytest.approx(float(path.axis(q)[0]), abs=1e-9)
            assert fast.heading(float(q)) == heading
        assert fast.stops == tuple(path.cusps)
        assert fast.length == path.length


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_a_place_projects_back_to_its_travel_and_an_axis_value_to_its_travel(name, track, route):
    metric = GraphMetric(track)
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track, axis_start=3.0)
        for q in np.linspace(0.0, path.length, 97):
            q = float(q)
            edge, s = fast.locate(q)
            assert fast.project(edge, s, q, metric) == pytest.approx(q, abs=1e-9), (name, q)
            if fast.edges:
                velocity = fast.heading(q)  # moving on along its path
                assert fast.travel_at_axis(fast.axis(q), max(q - 1e-3, 0.0), velocity) == pytest.approx(
                    q, abs=1e-9
                )


def test_a_position_off_the_path_does_not_project_and_one_past_its_end_runs_on():
    """Off the path: None. Past the goal along the last edge: travel beyond the length.

    The same for the edge's end node given on another of its edges (the same node).
    """
    ran_on, nodes_elsewhere = 0, 0
    for _, track, route in CASES:
        metric = GraphMetric(track)
        fast = GraphVehiclePath.from_path(graph_paths(route)[0], track)
        if not fast.edges:
            continue
        used = set(fast.edges) | set(graph_paths(route)[1].edges.tolist())
        for other in (k for k in range(track.edge_count) if k not in used):
            midway = 0.5 * track.length(other)
            if metric.distance(other, midway, *fast.locate(0.0)) > midway + 1e-6:  # not a neighbour
                assert fast.project(other, midway, 0.0, metric) is None
        k = len(fast.edges) - 1
        edge, ahead = fast.edges[k], (1.0 if fast.s_to[k] > fast.s_from[k] else -1.0)
        top = track.length(edge)
        room = top - fast.s_to[k] if ahead > 0 else fast.s_to[k]
        if room > 0.25:
            ran_on += 1
            end = fast.s_to[k] + ahead * 0.25
            assert fast.project(edge, end, fast.length, metric) == pytest.approx(fast.length + 0.25)
        node = track.ends(edge)[1 if ahead > 0 else 0]
        at_node = fast.length + room
        assert fast.project(edge, top if ahead > 0 else 0.0, at_node, metric) == pytest.approx(at_node)
        for neighbour in range(track.edge_count):
            u, v = track.ends(neighbour)
            if neighbour == edge or node not in (u, v) or neighbour in fast.edges:
                continue
            nodes_elsewhere += 1
            given = 0.0 if u == node else track.length(neighbour)
            assert fast.project(neighbour, given, at_node, metric) == pytest.approx(at_node), (
                edge,
                neighbour,
            )
    assert ran_on >= 3, ran_on
    assert nodes_elsewhere >= 3, nodes_elsewhere


def test_the_metric_agrees_with_the_tracks_vectorised_distances():
    rng = np.random.default_rng(7)
    for _, track, _ in CASES:
        metric = GraphMetric(track)
        lengths = np.array([track.length(k) for k in range(track.edge_count)])
        ea, eb = rng.integers(0, track.edge_count, 200), rng.integers(0, track.edge_count, 200)
        sa, sb = rng.random(200) * lengths[ea], rng.random(200) * lengths[eb]
        expected = track.distances(ea, sa, eb, sb)
        got = [
            metric.distance(int(a), float(x), int(b), float(y))
            for a, x, b, y in zip(ea, sa, eb, sb, strict=True)
        ]
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_the_stretch_distance_is_the_least_over_dense_samples_of_both_stretches():
    rng = np.random.default_rng(11)
    for _, track, _ in CASES[:8]:
        metric = GraphMetric(track)
        for _ in range(30):
            stretches = []
            for _ in range(2):
                edge = int(rng.integers(0, track.edge_count))
                low, high = sorted(rng.random(2) * track.length(edge))
                stretches.append((edge, float(low), float(high)))
            a, b = stretches
            u, w = np.linspace(a[1], a[2], 60), np.linspace(b[1], b[2], 60)
            uu, ww = (x.ravel() for x in np.meshgrid(u, w))
            sampled = track.distances(np.full(uu.size, a[0]), uu, np.full(ww.size, b[0]), ww).min()
            exact = metric.stretch_distance(a, b)
            # a lower bound, and within the sampling step of the samples' least
            step = max(a[2] - a[1], b[2] - b[1]) / 59.0
            assert exact <= sampled + 1e-12
            assert exact >= sampled - step - 1e-12


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_a_sweep_holds_every_place_of_its_travel_range_and_no_more(name, track, route):
    metric = GraphMetric(track)
    rng = np.random.default_rng(3)
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        for _ in range(20):
            low, high = sorted(rng.uniform(-0.5, path.length + 0.5, 2))
            swept = fast.sweep(float(low), float(high))
            samples = np.linspace(low, high, 200)
            places = [_run_on(fast, float(q)) for q in samples]
            for edge, s in places:
                assert metric.set_distance(swept, ((edge, s, s),)) <= 1e-9, (name, low, high)
            # every end of a stretch is within a sample step of a place driven
            step = (high - low) / 199.0 + 1e-9
            for edge, lo, hi in swept:
                for end in (lo, hi):
                    assert min(metric.distance(edge, end, e, s) for e, s in places) <= step + 1e-9


def _run_on(fast: GraphVehiclePath, q: float) -> tuple[int, float]:
    """Where travel ``q`` puts the vehicle, running on along the end segments' edges (clipped)."""
    if not fast.edges:
        return fast.home
    k = 0 if q < 0.0 else (len(fast.edges) - 1 if q > fast.length else fast.segment(q))
    sign = 1.0 if fast.s_to[k] > fast.s_from[k] else -1.0
    s = fast.s_from[k] + sign * (q - fast.starts[k])
    if 0.0 <= q <= fast.length:
        return fast.locate(q)
    return fast.edges[k], min(max(s, 0.0), fast.edge_lengths[fast.edges[k]])


def test_an_axis_given_the_other_way_round_flips_every_heading():
    _, track, route = CASES[0]
    path = graph_paths(route)[1]
    along = GraphVehiclePath.from_path(path, track)
    direction = 1 if path.s_to[0] > path.s_from[0] else -1
    against = GraphVehiclePath.from_path(path, track, axis_start=2.0, orientation=-direction)
    assert against.headings == tuple(-h for h in along.headings)
    for q in np.linspace(0.0, path.length, 21):
        assert against.axis(float(q)) == pytest.approx(2.0 - along.axis(float(q)))


def test_a_vehicle_that_stays_put_sweeps_its_home_and_any_travel_off_it_is_overrun():
    """Its path does not say which way it would go: travel off 0 is all overrun, in any direction."""
    still = 0
    for _, track, route in CASES:
        for path in graph_paths(route):
            if path.edges.size:
                continue
            still += 1
            fast = GraphVehiclePath.from_path(path, track)
            assert fast.sweep(-1.0, 0.5) == ((path.home.edge, path.home.s, path.home.s),)
            assert fast.overrun(-1.0, 0.5) == 1.0
            assert fast.overrun(0.0, 0.0) == 0.0
            assert all(fast.locate(q) == fast.home for q in (-1.0, 0.0, 1.0))
    assert still >= 1


def test_the_overrun_is_what_runs_past_the_end_segments_edge_ends_only():
    """Within the end segments' edges the sweep holds the run-on: no overrun; past them, the rest."""
    for _, track, route in CASES:
        fast = GraphVehiclePath.from_path(graph_paths(route)[0], track)
        if not fast.edges:
            continue
        assert fast.overrun(0.0, fast.length) == 0.0
        k = len(fast.edges) - 1
        room = track.length(fast.edges[k]) - fast.s_to[k] if fast.s_to[k] > fast.s_from[k] else fast.s_to[k]
        assert fast.overrun(0.0, fast.length + room) == pytest.approx(0.0, abs=1e-12)
        assert fast.overrun(0.0, fast.length + room + 0.3) == pytest.approx(0.3)
        top = track.length(fast.edges[0])
        back = fast.s_from[0] if fast.s_to[0] > fast.s_from[0] else top - fast.s_from[0]
        assert fast.overrun(-back - 0.2, fast.length) == pytest.approx(0.2)


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_the_branch_is_the_edge_the_vehicle_is_on_once_it_leaves_its_segment(name, track, route):
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        for k in range(len(fast.edges)):
            end = fast.starts[k + 1] if k + 1 < len(fast.edges) else fast.length
            middle = 0.5 * (fast.starts[k] + end)
            after = fast.place(min(end + 1e-6, fast.length))[0] if k + 1 < len(fast.edges) else fast.edges[k]
            assert fast.place(middle)[4] == after, (name, k)


# -- track graphs: the braking check and the safety guard ------------------------------------------------


EMERGENCY = (1.0, 1.0)


def _paths(name: str):
    scenario, verified = verified_example(name, "exact")
    track = scenario.track
    paths = tuple(GraphVehiclePath.from_path(p, track) for p in graph_paths(verified.schedule.route))
    return track, GraphMetric(track), paths


@pytest.mark.slow  # a sampled campaign over every example's plan
@pytest.mark.parametrize("name", ["h", "ring-with-spurs", "main-line-with-sidings"])
def test_what_the_braking_check_certifies_keeps_the_distance_at_every_sampled_instant(name):
    """Random states along both paths: a certified pair never comes closer than required when sampled."""
    track, metric, paths = _paths(name)
    graph_path_pair = graph_paths(verified_example(name, "exact")[1].schedule.route)
    check = BrakingCheck((AGV, AGV), EMERGENCY, metric)
    rng = np.random.default_rng(5)
    outcomes = []
    for _ in range(60):
        states = []
        for path in paths:
            p = float(rng.uniform(0.0, path.length)) if path.edges else 0.0
            v = float(rng.uniform(0.0, AGV.max_velocity)) if path.edges else 0.0
            states.append(PathState(p, v, 0.0))
        required = 1.5
        certified = check.clearance(paths, tuple(states), tuple(states), required)
        least = _least_distance_of_places(track, graph_path_pair, states, states, steps=300, samples=3)
        if certified:
            assert least >= required - 1e-9, (name, states, least)
        outcomes.append((certified, least >= required))
    # neither always yes nor always no, and rarely pessimistic where the sample has room
    assert any(c for c, _ in outcomes)
    assert not all(c for c, _ in outcomes)
    roomy = [c for c, room in outcomes if room]
    assert sum(roomy) >= 0.8 * len(roomy)


def test_the_guard_takes_a_track_graph_and_measures_its_track_distance():
    track, metric, paths = _paths("h")
    limits = Limits((AGV, AGV), 1.5)
    guard = SafetyGuard(limits, track)

    class Measured:
        def __init__(self, place):
            self.leg, self.s = place

    # the vehicles at their starts: the guard's required distance is the separation, or what they have
    first, second = paths[0].locate(0.0), paths[1].locate(0.0)
    apart = metric.distance(*first, *second)
    assert guard.required((Measured(first), Measured(second))) == pytest.approx(
        (min(1.5 - 1e-6, apart - 1e-12),)
    )
    at_rest = (PathState(0.0, 0.0, 0.0), PathState(0.0, 0.0, 0.0))
    assert guard.certifies(paths, at_rest, at_rest, guard.required((Measured(first), Measured(second))))


def _beyond(track, edge: int, s: float) -> list[tuple[int, float]]:
    """Every place ``s`` metres along ``edge`` can be, ``s`` possibly beyond the edge's ends.

    Past an end node the vehicle is on one of the node's edges (any: the track does not say which),
    as far from the node as it ran past it. Written from the track alone, not from the sweep.
    """
    length = track.length(edge)
    if 0.0 <= s <= length:
        return [(edge, s)]
    node, past = (track.ends(edge)[0], -s) if s < 0.0 else (track.ends(edge)[1], s - length)
    places = []
    for other in range(track.edge_count):
        u, v = track.ends(other)
        reach = min(past, track.length(other))
        if u == node:
            places.append((other, reach))
        if v == node:
            places.append((other, track.length(other) - reach))
    return places


def _places(track, path, p: float) -> list[tuple[int, float]]:
    """Where a vehicle whose path is ``path`` (a GraphPath) can be at travel ``p``."""
    if path.edges.size == 0:
        edge, s = path.home.edge, path.home.s
        return _beyond(track, edge, s - abs(p)) + _beyond(track, edge, s + abs(p))
    if 0.0 <= p <= path.length:
        edges, s = path.locate(p)
        return [(int(edges[0]), float(s[0]))]
    if p < 0.0:
        return _beyond(track, int(path.edges[0]), float(path.s_from[0] + path.directions[0] * p))
    return _beyond(track, int(path.edges[-1]), float(path.s_to[-1] + path.directions[-1] * (p - path.length)))


def _least_distance_of_places(track, graph_path_pair, commanded, measured, steps: int, samples: int) -> float:
    """The least track distance between the places the two braking vehicles can be (a dense sample).

    At ``steps`` instants and ``samples`` travel values across each vehicle's range there.
    """
    trajectories = [ServiceBraking(AGV).trajectory(state) for state in commanded]
    horizon = max(
        *(t.duration for t in trajectories), *(abs(m.v) / e for m, e in zip(measured, EMERGENCY, strict=True))
    )
    least = np.inf
    for t in np.linspace(0.0, horizon, steps):
        places = []
        for v in (0, 1):
            trajectory = trajectories[v]
            upper = trajectory.at_time(min(t, trajectory.duration))[0][0]
            lower = emergency_position(measured[v], EMERGENCY[v], t)
            places.append(
                [q for p in np.linspace(lower, upper, samples) for q in _places(track, graph_path_pair[v], p)]
            )
        first = np.array([(e, s) for e, s in places[0] for _ in places[1]])
        second = np.array([(e, s) for _ in places[0] for e, s in places[1]])
        apart = track.distances(first[:, 0].astype(int), first[:, 1], second[:, 0].astype(int), second[:, 1])
        least = min(least, float(apart.min()))
    return least


def test_a_stop_that_runs_past_a_goal_at_a_track_node_is_not_certified(tmp_path):
    """A vehicle 1 cm before its goal at a track node at 0.5 m/s runs past it: not certified.

    agv1 parks at node J exactly the separation behind agv2 (at e:1.5); its emergency stop runs
    11.5 cm past J onto e, 1.385 m from agv2. The sweep stops at J (the end of agv1's edge w);
    what runs past J is the path's overrun, taken off the distance. Arriving at rest, the same
    plan is certified.
    """
    text = CONVOY.replace('goal = "e:5.5"', 'goal = "J"').replace('goal = "e:7"', 'goal = "e:1.5"')
    scenario_file = tmp_path / "convoy_at_node.toml"
    scenario_file.write_text(text)
    route = load_scenario(scenario_file).route()
    track = route.track
    graph_path_pair = graph_paths(route)
    paths = tuple(GraphVehiclePath.from_path(p, track) for p in graph_path_pair)
    check = BrakingCheck((AGV, AGV), EMERGENCY, GraphMetric(track))
    ends = (PathState(paths[0].length, 0.0, 0.0), PathState(paths[1].length, 0.0, 0.0))
    required = 1.5 - 1e-6
    assert paths[0].overrun(paths[0].length, paths[0].length + 0.115) == pytest.approx(0.115)
    running_on = (PathState(paths[0].length - 0.01, 0.5, 0.0), ends[1])
    truth = _least_distance_of_places(track, graph_path_pair, ends, running_on, steps=400, samples=5)
    assert truth == pytest.approx(1.385, abs=1e-3)
    assert not check.clearance(paths, ends, running_on, required)
    assert check.clearance(paths, ends, ends, required)


def test_a_vehicle_that_should_stay_put_and_moves_is_not_certified_by_its_home_point():
    """A path with no segments sweeps its home point; travel away from it is overrun, any way."""
    _, metric, _ = _paths("h")
    still = GraphVehiclePath((), (), (), (), (), (0.0,), 0.0, (), (0, 3.0), metric.lengths)
    assert still.sweep(-0.5, 0.25) == ((0, 3.0, 3.0),)
    assert still.overrun(-0.5, 0.25) == 0.5
    assert still.overrun(0.0, 0.0) == 0.0


# -- track graphs: the executor and closed-loop runs -----------------------------------------------------


NAMES = ["h", "passing-loop", "main-line-with-sidings", "ring-with-spurs"]


@functools.cache
def plan(name: str, method: str):
    """The example ``name``'s scenario and its verified plan for execution by ``method``, once."""
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    return scenario, schedule_for_execution(scenario, method=method)


@pytest.mark.parametrize("method", ["exact", pytest.param("toppra", marks=pytest.mark.slow)])  # exact fast
@pytest.mark.parametrize("name", NAMES)
def test_an_undisturbed_run_on_a_graph_plays_its_plan_and_never_brakes(name, method):
    scenario, verified = plan(name, method)
    result, _ = simulate(scenario, verified=verified)
    assert result.reached_goal
    assert abs(result.makespan_s - result.planned_s) <= 0.01 * result.planned_s + 0.02, result.summary()
    assert result.violations == 0
    assert result.holds == 0
    assert result.emergency_brakes == 0
    assert [e.kind for e in result.events] == ["done"], result.events
    # the conflicts keep the separation and the margin; the plan keeps a second margin of clearance
    assert result.certified_separation_m >= scenario.limits.min_separation + result.position_margin - 1e-6


@pytest.mark.slow  # a stop at every moment: a campaign, as on a junction
@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", ["h", "passing-loop"])
def test_a_stop_at_any_moment_on_the_h_and_the_passing_loop_costs_at_most_its_bound(name, method):
    """Seeded stops of either vehicle, anywhere in the run, 0.5 to 10 s: the issue's bound, 0 violations."""
    scenario, verified = plan(name, method)
    rng = random.Random(f"{name}-{method}")
    for _ in range(6):
        vehicle = rng.choice(scenario.names)
        spec = (
            f"stop:{vehicle}@{rng.uniform(0.0, verified.schedule.duration):.2f}+{rng.uniform(0.5, 10.0):.2f}"
        )
        _assert_a_stop_costs_at_most_its_bound(scenario, verified, spec)


@pytest.mark.parametrize(
    ("name", "method", "spec"),
    [
        # agv1 waits at its frontier for agv2 to clear J2; a jump back sets its drive closing the gap
        ("passing-loop", "exact", "jump:agv1@22.4=-0.04"),
        ("ring-with-spurs", "exact", "jump:agv1@32.07=-0.04"),
        # agv1 stops while agv2, on the plan's clock, drives a toppra plan at its frontier
        ("h", "toppra", "stop:agv1@10+5"),
    ],
    ids=["jump-while-waiting-loop", "jump-while-waiting-ring", "toppra-follower-at-its-frontier"],
)
def test_the_runs_that_overshot_a_frontier_and_deadlocked_now_reach_the_goal(name, method, spec):
    """Each ran past its frontier into the conflict and both waited for ever (holds, no goal)."""
    scenario, verified = plan(name, method)
    faults = parse_faults(scenario, [spec])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    assert result.emergency_brakes == 0
    if faults[0].kind.value == "stop":
        assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value)


@pytest.mark.parametrize(
    "name",
    ["h", pytest.param("main-line-with-sidings", marks=pytest.mark.slow)],  # the H in the fast set
)
def test_slowdowns_lags_and_jumps_on_a_graph_keep_the_separation_and_reach_the_goal(name):
    scenario, verified = plan(name, "exact")
    margin = execution_margin(scenario, 0.05)
    rng = random.Random(name)
    for _ in range(6):
        vehicle = rng.choice(scenario.names)
        at = rng.uniform(0.0, verified.schedule.duration)
        spec = rng.choice(
            [
                f"slow:{vehicle}@{at:.2f}+{rng.uniform(1.0, 8.0):.2f}=0.3",
                f"lag:{vehicle}@{at:.2f}=150",
                f"jump:{vehicle}@{at:.2f}={rng.choice([-1, 1]) * margin * 0.8:.4f}",
            ]
        )
        result, _ = simulate(scenario, parse_faults(scenario, [spec]), verified=verified)
        assert result.reached_goal, spec
        assert result.violations == 0, spec
        assert result.emergency_brakes == 0, spec


@pytest.mark.parametrize(
    "spec",
    ["goal:agv1@10=C", "goal:agv2@5=b:3", "goal:agv1@15=J2", "goal:agv1@12=e:6"],
)
def test_a_new_goal_on_a_graph_stops_both_replans_and_reaches_it(spec):
    """The vehicles stop, the exact planner plans from where they stand, and the new goal is reached.

    The re-planned paths continue each vehicle's own axis, also where it stands at a node and leaves
    on another edge: after the re-plan no vehicle is off its setpoints.
    """
    scenario, verified = plan("h", "toppra")
    faults = parse_faults(scenario, [spec])
    final = []

    def observe(executor, measured, command):
        final[:] = [measured, executor.goal]

    result, _ = simulate(scenario, faults, verified=verified, observer=observe)
    assert result.reached_goal, result.summary()
    assert result.replans == 1
    assert result.violations == 0
    assert result.emergency_brakes == 0
    kinds = [e.kind for e in result.events]
    assert "replan" in kinds
    after = result.events[kinds.index("replan") :]
    assert not any("off its setpoints" in e.detail for e in after), result.events
    measured, goal = final
    track = scenario.track
    wanted = track.point(faults[0].goal)
    assert goal[faults[0].vehicle] == wanted
    for state, point in zip(measured, goal, strict=True):
        assert track.distance(EdgePoint(state.leg, state.s), point) <= 0.05


def test_a_goal_too_close_to_the_other_vehicles_is_refused_and_the_run_goes_on():
    scenario, verified = plan("h", "exact")
    result, _ = simulate(scenario, parse_faults(scenario, ["goal:agv1@8=A"]), verified=verified)
    assert result.reached_goal
    assert result.replans == 0
    assert result.rejected_goals == 1
    refused = [e.detail for e in result.events if e.kind == "goal-refused"]
    assert refused
    assert "goal (A, A) leaves the vehicles 0.000 m apart: expected at least 1.600 m" in refused[0]
    assert "(separation + twice the position margin" in refused[0]  # 1.5 + 2 x 0.05


def test_a_goal_fault_off_the_graph_names_the_spec():
    scenario, _ = plan("h", "exact")
    with pytest.raises(FaultError, match=r"fault 'goal:agv1@3=zz:1': goal: .*zz"):
        parse_faults(scenario, ["goal:agv1@3=zz:1"])


def test_a_measured_state_off_the_track_graph_is_refused_naming_the_edge():
    scenario, verified = plan("h", "exact")
    executor = Executor(verified, names=scenario.names)
    ok = VehicleState(0, 6.0)
    with pytest.raises(InputError, match=r"vehicle 1 measured edge must be an edge index 0 to 4 .* got 7"):
        executor.step((VehicleState(7, 1.0), ok))
    with pytest.raises(
        InputError, match=r"vehicle 2 measured s 9\.0 m is off edge 'a': expected 0 to 6\.0 m"
    ):
        executor.step((ok, VehicleState(0, 9.0)))
    with pytest.raises(InputError, match=r"vehicle 1 measured velocity must be a finite number, got nan"):
        executor.step((VehicleState(0, 6.0, float("nan")), ok))
    track = GraphTrack(scenario.track)
    assert track.check_state(VehicleState(0, 6.0 + 5e-7), 1).s == 6.0  # round-off at the end is on it


def test_a_body_passes_a_node_onto_the_edge_it_is_steered_to():
    """Closed form: through J2 from m onto e and onto c and back onto m; a dead end stops it."""
    track = TrackGraph.from_edges(
        {"m": ("J1", "J2", 8.0), "e": ("J2", "D", 6.5), "c": ("C", "J2", 6.0), "a": ("J1", "A", 6.0)}
    )
    shape = GraphShape(track)
    m, e, c, a = (track.edge(name) for name in "meca")

    class Steer:
        def __init__(self, leg, branch):
            self.leg, self.branch = leg, branch

    body = GraphBody(m, 7.9, 1, 0.0)
    body.steer(Steer(m, e))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.orientation, body.axis) == (e, pytest.approx(0.2), 1, pytest.approx(0.3))
    body = GraphBody(m, 7.9, 1, 0.0)  # onto c, whose "to" node is J2: s counts down from its length
    body.steer(Steer(c, c))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.orientation) == (c, pytest.approx(5.8), -1)
    body.steer(Steer(m, m))  # and back through J2 onto m, driving the axis the other way
    body.move(-0.5, shape)
    assert (body.leg, body.s, body.orientation) == (m, pytest.approx(7.7), 1)
    body = GraphBody(a, 5.9, 1, 0.0)  # A is a dead end: the vehicle stops there, at rest
    body.v = 0.5
    body.steer(Steer(a, a))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.axis, body.v) == (a, 6.0, pytest.approx(0.1), 0.0)


def test_simulate_on_the_h_writes_a_trace_whose_rows_keep_the_separation(tmp_path):
    """``trajgen simulate`` on a graph: the trace's rows, read back and measured by the track alone."""
    code = main(
        [
            "simulate",
            str(EXAMPLES / "h.toml"),
            "--method",
            "exact",
            "--fault",
            "stop:agv1@10+5",
            "--trace",
            str(tmp_path / "trace"),
            "--json",
        ]
    )
    assert code == 0
    scenario = load_scenario(EXAMPLES / "h.toml")
    track = scenario.track
    rows = []
    for name in scenario.names:
        lines = (tmp_path / "trace" / f"{name}.csv").read_text().splitlines()
        assert lines[0] == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m;x_m;y_m"
        fields = [line.split(";") for line in lines[1:]]
        edges = np.array([track.edge(f[5]) for f in fields])
        s = np.array([float(f[6]) for f in fields])
        rows.append((edges, s))
    assert rows[0][0].size == rows[1][0].size > 1000
    apart = track.distances(rows[0][0], rows[0][1], rows[1][0], rows[1][1])
    assert apart.min() >= scenario.limits.min_separation - 1e-6
    start = [
        track.distance(EdgePoint(int(r[0][0]), r[1][0]), p) for r, p in zip(rows, scenario.start, strict=True)
    ]
    goal = [
        track.distance(EdgePoint(int(r[0][-1]), r[1][-1]), p)
        for r, p in zip(rows, scenario.goal, strict=True)
    ]
    assert max(start) <= 1e-9
    assert max(goal) <= 0.01


def test_simulate_json_on_a_graph_reports_the_run(capsys):
    code = main(["simulate", str(EXAMPLES / "passing-loop.toml"), "--method", "exact", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["reached_goal"] is True
    assert summary["separation_violations"] == 0
    assert summary["emergency_brakes"] == 0


def test_the_margin_on_a_graph_shrinks_to_what_the_start_and_goal_leave():
    track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    scenario = GraphScenario(track, Limits((agv, agv), 1.5), ("agv1", "agv2"), ("a:1.56", "b:0"), ("A", "B"))
    # the start leaves 1.56 m: 0.03 m each side of the separation
    assert execution_margin(scenario, 0.05) == pytest.approx(0.03)
    result, _ = simulate(scenario, method="exact")
    assert result.reached_goal
    assert result.violations == 0


@pytest.mark.slow  # simulations of seeded random tracks with faults
@pytest.mark.parametrize("method", ["exact", "toppra"])
def test_seeded_random_track_graphs_with_faults_reach_their_goals_without_a_violation(method):
    """Trees and graphs with loops, random limits, one to three faults each (the bench's campaign)."""
    for k, scenario in enumerate(graph_online_campaign(8, seed=23)):
        verified = schedule_for_execution(scenario, method=method)
        margin = execution_margin(scenario, 0.05)
        specs = graph_campaign_faults(scenario, verified.schedule.duration, seed=k, margin=margin)
        result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
        assert result.reached_goal, (k, specs)
        assert result.violations == 0, (k, specs, result.summary())
        assert result.emergency_brakes == 0, (k, specs)


def test_the_campaign_draws_trees_and_loops_whose_start_and_goal_keep_the_separation():
    scenarios = graph_online_campaign(6, seed=5)
    assert scenarios == graph_online_campaign(6, seed=5)  # seeded: the same draw
    for k, scenario in enumerate(scenarios):
        track = scenario.track
        cycle = track.edge_count - len(track.nodes) + 1  # independent loops of a connected graph
        assert (cycle > 0) == (k % 2 == 1), k
        for pair in (scenario.start, scenario.goal):
            assert track.distance(*pair) >= scenario.limits.min_separation
        scenario.route()  # a route exists


def test_a_throttled_drive_brakes_down_to_its_cap_no_harder_than_its_max_acceleration():
    """A slow fault caps agv1 at 0.2 m/s while it drives at 1 m/s: it slows at most at 0.5 m/s².

    A drive dropping to its cap within one cycle (80 m/s² here) made the braking check assume the
    worst of it and brake both hard (a campaign run on a random graph: 5 emergency-brake cycles); a
    drive slowing at its emergency deceleration still stepped its speed beyond what it can (issue 38).
    """
    scenario, verified = plan("h", "exact")
    vehicle = scenario.limits.vehicles[0]
    accelerations, speeds = [], []

    def observe(executor, measured, command):
        accelerations.append(measured[0].acceleration)
        speeds.append(abs(measured[0].velocity))

    result, _ = simulate(
        scenario, parse_faults(scenario, ["slow:agv1@3=0.2"]), verified=verified, observer=observe
    )
    assert result.reached_goal
    assert result.violations == 0
    assert result.emergency_brakes == 0
    assert max(speeds[290:310]) > 0.9  # it was at speed when the cap came
    assert min(accelerations) >= -vehicle.max_acceleration - 1e-9
    assert np.max(np.abs(np.diff(speeds))) <= vehicle.max_acceleration * 0.01 * (1 + 1e-6)
    settled = 300 + math.ceil((max(speeds[290:310]) - 0.2) / vehicle.max_acceleration / 0.01) + 2
    assert max(speeds[settled:]) <= 0.2 + 1e-9  # and then kept to the cap


def test_a_vehicle_that_stays_put_through_a_re_plan_on_a_track_graph_drives_its_next_move_the_right_way():
    """A plan in which a vehicle does not move keeps the way its axis runs.

    agv1's axis runs against ``s`` (it starts by driving towards J); a new goal for agv2 leaves it
    where it stands; its own next goal must then be driven towards A (it drove towards J).
    """
    track = TrackGraph.from_edges({"a": ("J", "A", 10.0), "b": ("J", "B", 10.0), "c": ("J", "C", 10.0)})
    drive = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits((drive, drive), 1.5)
    scenario = GraphScenario(track, limits, ("agv1", "agv2"), ("a:8", "b:5"), ("a:3", "b:5"))
    verified = schedule_for_execution(scenario, method="exact")
    final = []

    def observe(executor, measured, command):
        final[:] = measured

    faults = parse_faults(scenario, ["goal:agv2@12=b:8", "goal:agv1@30=a:9"])
    result, _ = simulate(scenario, faults, verified=verified, observer=observe)
    assert result.reached_goal, result.summary()
    assert result.replans == 2
    assert not any("off its setpoints" in e.detail for e in result.events), result.events
    assert (final[0].leg, final[1].leg) == (0, 1)
    assert final[0].s == pytest.approx(9.0, abs=0.05)
    assert final[1].s == pytest.approx(8.0, abs=0.05)


@pytest.mark.parametrize(
    ("seed", "k", "specs", "emergency"),
    [
        # a jump back leaves the drive closing the gap faster than planned: restarted at that
        # speed, it could not stop at its reversal and waited there for ever
        (9, 7, ("jump:agv1@6.476=-0.04289",), False),
        (9, 7, ("jump:agv1@6.476=-0.04289", "slow:agv2@2.121=0.4481"), False),
        # a lagging drive braked hard stops short of its setpoint; the check took it anywhere up to
        # the setpoint, too close to the other, and braked both, at rest, for ever
        (12, 3, ("lag:agv1@4.143=174", "slow:agv1@4.814=1.1585"), True),
    ],
    ids=["jump", "jump-slow", "lag-slow"],
)
def test_campaign_runs_that_never_reached_the_goal_with_toppra_now_do(seed, k, specs, emergency):
    scenario = graph_online_campaign(k + 1, seed=seed)[k]
    verified = schedule_for_execution(scenario, method="toppra")
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    if not emergency:
        assert result.emergency_brakes == 0
    else:  # the lag hides the drive from its setpoints: braking hard is right, but only until at rest
        assert result.emergency_brakes < 100


# -- any number of vehicles below the planners ------------------------------------------------------------


def _fleet_plan(case):
    """The fleet's exact schedule with the separation 0.2 m under its route's: room for the margins."""
    limits = Limits(case.limits().vehicles, SEPARATION - 0.2)
    return certify(make_schedule(case.route(), limits, method="exact"))


def _play_fleet(verified, faults=(), *, cycles: int = 100_000):
    """The executor against the plant (``faults``) until every vehicle is at its goal; the closest pair."""
    executor = Executor(verified, names=verified.schedule.route.names)
    plant = Plant(executor, faults, executor.period)
    metric = GraphMetric(verified.schedule.track)
    closest = math.inf
    t = 0.0
    for _ in range(cycles):
        measured = plant.measure()
        if executor.mode is Mode.DONE:
            break
        command = executor.step(measured)
        plant.advance(command, t)
        t += executor.period
        places = [(state.leg, state.s) for state in plant.measure()]
        for (edge_a, s_a), (edge_b, s_b) in itertools.combinations(places, 2):
            closest = min(closest, metric.distance(edge_a, s_a, edge_b, s_b))
    return executor, closest


@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_a_fleet_is_executed_to_every_goal_keeping_every_pair_apart_on_time_when_undisturbed(case):
    verified = _fleet_plan(case)
    executor, closest = _play_fleet(verified)
    assert executor.mode is Mode.DONE
    assert executor.emergency_brakes == 0
    assert closest >= verified.schedule.limits.min_separation - 1e-6
    assert executor.time == pytest.approx(verified.schedule.duration, rel=0.01, abs=0.05)
    assert len(executor.diagrams) == math.comb(case.count, 2)


@pytest.mark.parametrize(
    "stopped", [pytest.param(0, marks=pytest.mark.slow), 1, pytest.param(2, marks=pytest.mark.slow)]
)  # the middle vehicle in the fast set
@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_a_stop_of_any_vehicle_of_a_fleet_holds_its_followers_and_costs_about_its_length(case, stopped):
    """Each vehicle in turn stops for 4 s halfway through its first move: orders kept, nobody brakes hard.

    The exact plan moves one vehicle at a time, a section each.
    """
    verified = _fleet_plan(case)
    schedule = verified.schedule
    move = next(k for k, m in enumerate(schedule.route.moves) if m.vehicle == stopped)
    at = schedule.sections[move].start_time + 0.5 * schedule.sections[move].duration
    stop = Fault(FaultKind.STOP, stopped, at, 4.0)
    executor, closest = _play_fleet(verified, (stop,))
    assert executor.mode is Mode.DONE
    assert executor.emergency_brakes == 0
    assert closest >= verified.schedule.limits.min_separation - 1e-6
    name = schedule.route.names[stopped]
    assert any(event.kind == "retime" and name in event.detail for event in executor.events)
    # at most its bound; less where the others, not held by it, drive on meanwhile
    late = executor.time - schedule.duration
    assert late <= stop_bound(schedule, 4.0), late


def _fleet_scenario(case, verified) -> GraphScenario:
    """The fleet's scenario: its track, the plan's limits, its vehicles' names, starts and goals."""
    route = case.route()
    return GraphScenario(route.track, verified.schedule.limits, route.names, route.start, route.goal)


@pytest.mark.parametrize(
    "case",
    [pytest.param(case, marks=() if case.name == "ring-of-3" else pytest.mark.slow) for case in FLEETS],
    ids=lambda case: case.name,
)  # the ring in the fast set
def test_a_fleet_is_simulated_with_every_vehicle_stopped_in_its_first_move_and_its_books_cover_every_vehicle(
    case,
):
    """``simulate`` with the fleet's plan at hand: each vehicle stops 3 s halfway through its first move."""
    verified = _fleet_plan(case)
    schedule = verified.schedule
    scenario = _fleet_scenario(case, verified)
    specs = []
    for vehicle, name in enumerate(scenario.names):
        move = next(k for k, m in enumerate(schedule.route.moves) if m.vehicle == vehicle)
        section = schedule.sections[move]
        specs.append(f"stop:{name}@{section.start_time + 0.5 * section.duration:.3f}+3")
    result, _ = simulate(scenario, parse_faults(scenario, specs, verified=verified), verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    assert result.emergency_brakes == 0
    assert result.certified_separation_m >= scenario.limits.min_separation - 1e-6
    assert result.position_margin == pytest.approx(0.05)  # the plan keeps 0.2 m beyond the separation
    assert result.time_lost_s <= case.count * stop_bound(schedule, 3.0)
    for key in ("speed", "travel", "frontier"):
        assert result.plot[key].shape == (case.count, result.plot["t"].size)
    assert result.plot["travel"][:, -1] == pytest.approx([path.length for path in schedule.paths], abs=1e-3)
    json.dumps(result.summary())


@pytest.mark.slow
def test_a_fleets_simulation_writes_a_trace_per_vehicle_and_a_picture_of_every_vehicle(tmp_path):
    case = FLEETS[0]
    verified = _fleet_plan(case)
    scenario = _fleet_scenario(case, verified)
    run = run_simulation(scenario, trace_dir=tmp_path / "trace", plot_dir=tmp_path, verified=verified)
    assert run.result.reached_goal
    assert run.result.method == "exact"
    assert sorted(path.name for path in run.files) == sorted(
        [*(f"{n}.csv" for n in scenario.names), "simulation.png"]
    )
    figure = plot_simulation(run.result, names=scenario.names, min_separation=scenario.limits.min_separation)
    speed_axis = figure.axes[0]
    assert len(speed_axis.lines) == 2 * case.count  # planned and executed, each vehicle


def test_a_plan_of_other_vehicles_than_the_scenarios_is_refused_by_simulate():
    case = FLEETS[0]
    verified = _fleet_plan(case)
    with pytest.raises(InputError, match=r"the plan handed to simulate moves 3 vehicles, the scenario 2"):
        simulate(builtin_scenario("crossing"), (), verified=verified)


def test_a_new_goal_for_a_fleet_is_refused_naming_the_planner_and_the_run_keeps_its_goals():
    case = FLEETS[0]  # the convoy on one line
    verified = _fleet_plan(case)
    scenario = _fleet_scenario(case, verified)
    faults = parse_faults(scenario, [f"goal:{scenario.names[0]}@3=main:39"], verified=verified)
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal
    assert result.rejected_goals == 1
    refusal = next(event.detail for event in result.events if event.kind == "goal-refused")
    assert "the track-graph planner plans exactly 2 vehicles, got 3" in refusal
