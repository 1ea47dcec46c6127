"""The online executor: paths, the braking check, Ruckig recovery, anti-chatter, and a short fault campaign.

The full 200-scenario campaign is ``benchmarks/bench_online.py``; the CLI is in ``test_simulate_cli.py``.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from ruckig import ControlInterface, InputParameter, Ruckig, Trajectory

from limits import Limits, VehicleLimits
from topology import Configuration, Position, YGraph, plan
from topology.indexed import separation as indexed_separation
from trajgen import certify, default_scenario, make_schedule
from trajgen.errors import InputError, UnverifiedScheduleError
from trajgen.online import BrakingCheck, Coordination, Executor, Mode, PathState, VehiclePath, VehicleState
from trajgen.online.braking import emergency_position
from trajgen.online.executor import execution_margin, plan_for_execution, ruckig_jerk
from trajgen.online.simulation import parse_faults, simulate
from trajgen.sampling import campaign_faults, online_campaign
from trajgen.scenario import Scenario

AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)


@pytest.fixture(autouse=True)
def _quiet():
    logging.disable(logging.WARNING)
    yield
    logging.disable(logging.NOTSET)


@pytest.fixture(scope="module")
def swap():
    scenario = default_scenario()
    return scenario, plan_for_execution(scenario)


# -- paths and coordination --------------------------------------------------------------------


def test_the_swap_paths_follow_the_route():
    scenario = default_scenario()
    route = scenario.plan()
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
    route = default_scenario().plan()
    path = VehiclePath.from_route(route, vehicle)
    p = fraction * path.length
    leg, s = path.locate(p)
    assert path.project(leg, s, p) == pytest.approx(p, abs=1e-9)


def test_hold_points_follow_the_route_order():
    route = default_scenario().plan()
    coordination = Coordination.from_route(route)
    for v in (0, 1):
        own, other = (
            (coordination.first, coordination.second) if v == 0 else (coordination.second, coordination.first)
        )
        grid = np.linspace(-1.0, other[-1] + 1.0, 500)
        holds = [coordination.hold(v, x) for x in grid]
        assert np.all(np.diff(holds) >= -1e-12)  # more progress of the other never holds a vehicle back
        for mine, theirs in zip(own, other, strict=True):
            assert coordination.hold(v, theirs) >= mine - 1e-12  # the route itself is always allowed
        assert holds[-1] == pytest.approx(own[-1])


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


def track_distance(paths, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    out = []
    for p, q in zip(first, second, strict=True):
        leg1, s1 = paths[0].locate(p)
        leg2, s2 = paths[1].locate(q)
        out.append(indexed_separation((leg1, s1, leg2, s2)))
    return np.array(out)


@settings(max_examples=150, derandomize=True, deadline=None)
@given(
    data=st.data(),
    fraction=st.floats(0.0, 1.0),
    speeds=st.tuples(st.floats(-0.2, 1.0), st.floats(-0.2, 1.0)),
    accelerations=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),
)
def test_what_the_check_certifies_holds_under_every_braking_of_both(data, fraction, speeds, accelerations):
    """The braking invariant, against an independent dense simulation (1 ms) of the braking motions.

    Both vehicles of the swap somewhere along their paths; if the check certifies the pair, then with
    each vehicle braking at service (from its command) or stopping at its emergency deceleration
    (from its measurement), in all four combinations, the track distance stays above the requirement.
    """
    scenario = default_scenario()
    route = scenario.plan()
    paths = tuple(VehiclePath.from_route(route, v) for v in (0, 1))
    coordination = Coordination.from_route(route)
    first = fraction * paths[0].length
    second = coordination.hold(1, first) + data.draw(st.floats(-2.0, 2.0))
    second = min(max(second, 0.0), paths[1].length)
    commanded = tuple(
        PathState(p, v, a) for p, v, a in zip((first, second), speeds, accelerations, strict=True)
    )
    measured = tuple(PathState(c.p - 0.001 * c.v, c.v, c.a) for c in commanded)
    required = 1.5
    check = BrakingCheck((AGV, AGV), (1.0, 1.0), scenario.track.lengths)
    if not check.clearance(paths, commanded, measured, required):
        return
    times = np.arange(0.0, 6.0, 0.001)
    service = [braking_positions(c, AGV, times) for c in commanded]
    emergency = [np.array([emergency_position(m, 1.0, t) for t in times]) for m in measured]
    for one in (service[0], emergency[0]):
        for two in (service[1], emergency[1]):
            # 1 ms samples: at 1 m/s each, at most 1 mm between samples
            assert track_distance(paths, one, two).min() >= required - 2e-3


# -- the executor --------------------------------------------------------------------------------


def test_an_undisturbed_run_follows_the_plan(swap):
    scenario, verified = swap
    result, _ = simulate(scenario, (), verified=verified)
    assert result.reached_goal
    assert result.violations == 0
    # the braking check takes over where the plan follows closest (a leader may stop short): < 10 %
    assert 0.0 <= result.time_lost_s <= 0.1 * result.planned_s
    assert result.min_separation_m >= scenario.limits.min_separation


@pytest.mark.parametrize(("method", "lost"), [("exact", 0.01), ("toppra", 0.01)], ids=["exact", "toppra"])
def test_a_plan_without_close_approaches_is_played_as_it_is(method, lost):
    """Stored reference: the swap's exact and TOPPRA plans keep far apart; played to within one cycle."""
    scenario = default_scenario()
    result, _ = simulate(scenario, (), method=method)
    assert result.reached_goal
    assert result.violations == 0
    assert result.replans == 0
    assert 0.0 <= result.time_lost_s <= lost + 1e-9


def test_recovery_follows_ruckigs_own_trajectory(swap):
    """In recovery, the setpoints are Ruckig's trajectory, recomputed here from the same input."""
    scenario, verified = swap
    compared, agreed = [0], [0]

    def observe(executor, measured, command):
        if command.mode is not Mode.RECOVERING:
            return
        for v in (0, 1):
            if command.braking[v]:
                continue
            inp, _trajectory, elapsed = executor.motion(v)
            if elapsed <= 0.0 or abs(command.setpoints[v].velocity) < 1e-6:
                continue
            fresh_input = InputParameter(1)
            for name in (
                "current_position",
                "current_velocity",
                "current_acceleration",
                "target_position",
                "target_velocity",
                "target_acceleration",
                "max_velocity",
                "max_acceleration",
                "max_jerk",
            ):
                setattr(fresh_input, name, list(getattr(inp, name)))
            fresh = Trajectory(1)
            Ruckig(1).calculate(fresh_input, fresh)
            (p,), (velocity,), _ = fresh.at_time(min(elapsed, fresh.duration))
            path = executor.paths[v]
            setpoint = command.setpoints[v]
            compared[0] += 1
            if (
                abs(path.axis(p) - setpoint.axis) <= 1e-9
                and abs(path.heading(p) * velocity - setpoint.velocity) <= 1e-9
            ):
                agreed[0] += 1
                assert abs(ruckig_jerk(fresh, min(elapsed, fresh.duration) - 1e-12)) <= AGV.max_jerk * (
                    1 + 1e-9
                )

    result, _ = simulate(
        scenario, parse_faults(scenario, ["stop:agv1@8+3"]), verified=verified, observer=observe
    )
    assert result.reached_goal
    assert result.violations == 0
    assert compared[0] >= 300
    assert agreed[0] >= 0.95 * compared[0]


def test_every_command_is_certified_or_both_brake(swap):
    scenario, verified = swap
    seen = []

    def observe(executor, measured, command):
        seen.append(command.certified or command.braking == (True, True))

    specs = ["stop:agv2@9+2", "jump:agv1@14=0.04", "lag:agv2@3=150"]
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified, observer=observe)
    assert result.reached_goal
    assert result.violations == 0
    assert len(seen) == result.cycles
    assert all(seen)


@pytest.mark.parametrize(("hysteresis", "chatters"), [(None, False), (0.0, True)], ids=["default", "none"])
def test_replanning_along_the_antipodal_set_does_not_chatter(swap, hysteresis, chatters):
    """Replans every cycle with the configuration on the antipodal set of the goal, either side of it.

    The vehicles stand at the swap's start while the goal is requested alternately a little either
    side of the start's antipode on the boundary circle: the planner's instruction flips between the
    two ways round every cycle; the executor keeps its class (hysteresis) and so never switches.
    """
    scenario, verified = swap
    track = scenario.track
    executor = Executor(
        verified, min_separation=scenario.limits.min_separation, position_margin=0.05, hysteresis=hysteresis
    )
    either_side = (
        (1, Position("A", 9.8)),  # goal (B:10, A:9.8)
        (0, Position("B", 9.8)),  # goal (B:9.8, A:10)
    )
    goals = (
        Configuration(Position("B", 10.0), Position("A", 9.8)),
        Configuration(Position("B", 9.8), Position("A", 10.0)),
    )
    ways = {plan(track, scenario.start, goal, min_separation=1.55).way_round for goal in goals}
    assert len(ways) == 2  # the planner alone would flip every cycle
    at_start = [VehicleState(track.index(p.leg), p.s, 0.0, 0.0) for p in scenario.start]
    executor.step(*at_start)
    first_way = executor.route.way_round
    seen = set()
    for _ in range(3000):  # a new goal is taken once both commands are at rest: alternate per replan
        executor.request_goal(0, Position("B", 10.0))
        executor.request_goal(1, Position("A", 10.0))
        vehicle, position = either_side[executor.replans % 2]
        assert executor.request_goal(vehicle, position).accepted
        executor.step(*at_start)
        seen.add(executor.route.way_round)
        if executor.replans >= 60:
            break
    assert executor.replans >= 60
    switches = [e for e in executor.events if e.kind == "switch-class"]
    if chatters:  # without hysteresis the executor flips with the planner: the test can tell
        assert len(seen) == 2
        assert len(switches) >= 25
    else:
        assert seen == {first_way}
        assert not switches


def test_the_other_class_is_taken_when_it_is_much_shorter(swap):
    """A new goal just round the other way: the hysteresis does not stop a clearly shorter class."""
    scenario, verified = swap
    executor = Executor(verified, min_separation=scenario.limits.min_separation, position_margin=0.05)
    states = [VehicleState(0, 10.0), VehicleState(1, 10.0)]
    executor.step(*states)
    decision = executor.request_goal(1, Position("C", 10.0))
    assert decision.accepted
    executor.step(*states)
    new_goal = Configuration(Position("B", 10.0), Position("C", 10.0))
    classes = {
        r.way_round: r.length
        for r in (
            plan(scenario.track, scenario.start, new_goal, min_separation=1.55),
            plan(scenario.track, scenario.start, new_goal, min_separation=1.55, homotopy="other"),
        )
    }
    shorter = min(classes, key=classes.get)
    assert executor.route.way_round is shorter


# -- requests and bad input ---------------------------------------------------------------------


def test_a_goal_too_close_to_the_other_goal_is_refused_with_the_reason(swap):
    scenario, verified = swap
    executor = Executor(verified, min_separation=1.5)
    decision = executor.request_goal(0, Position("A", 9.0))  # 1 m from vehicle 2's goal A:10
    assert not decision.accepted
    assert "expected at least 1.550 m" in decision.reason
    assert "A:10" in decision.reason
    assert executor.rejected_goals == 1
    assert executor.goal == scenario.goal  # the run continues to the previous goals


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda e: e.step(VehicleState(0, math.nan), VehicleState(1, 10.0)), "measured s must be a finite"),
        (lambda e: e.step(VehicleState(5, 1.0), VehicleState(1, 10.0)), "measured leg must be"),
        (lambda e: e.step(VehicleState(0, 11.0), VehicleState(1, 10.0)), r"measured s 11.0 m is off leg 0"),
        (lambda e: e.step((0, 1.0), VehicleState(1, 10.0)), "must be a VehicleState"),
        (lambda e: e.request_speed_limit(0, 2.0), r"speed limit of vehicle 1 must be > 0 and <= 1.0"),
        (lambda e: e.request_goal(2, Position("A", 1.0)), "vehicle must be 0 or 1"),
    ],
    ids=["nan-s", "bad-leg", "off-leg", "not-a-state", "speed-above-limit", "bad-vehicle"],
)
def test_bad_input_to_the_executor(swap, call, match):
    executor = Executor(swap[1], min_separation=1.5)
    with pytest.raises(InputError, match=match):
        call(executor)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"period": 0.5}, r"control period must be 0.002 to 0.1 s, got 0.5"),
        ({"min_separation": 3.0}, r"min_separation must be between 0 m and the schedule's"),
        ({"hysteresis": -1.0}, r"hysteresis \(m\) must be a finite number >= 0"),
        ({"position_tolerance": 0.0}, r"position_tolerance \(m\) must be a finite number > 0"),
    ],
    ids=["period", "separation", "hysteresis", "tolerance"],
)
def test_bad_executor_options(swap, options, match):
    with pytest.raises(InputError, match=match):
        Executor(swap[1], **options)


def test_the_executor_takes_only_verified_schedules():
    scenario = default_scenario()
    schedule = make_schedule(scenario.plan(), scenario.limits, method="exact")
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


# -- a short campaign (the full one: benchmarks/bench_online.py) --------------------------------

CAMPAIGN_SEED = 11
SHORT = 14


@pytest.mark.parametrize("k", range(SHORT), ids=lambda k: f"scenario-{k}")
def test_short_fault_campaign(k):
    """Random scenarios with 1-3 random faults: no violation, no deadlock, every goal reached."""
    scenario = online_campaign(SHORT, seed=CAMPAIGN_SEED)[k]
    verified = plan_for_execution(scenario)
    margin = execution_margin(scenario, 0.05)
    specs = campaign_faults(scenario, verified.schedule.duration, seed=1000 + k, margin=margin)
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, (specs, result.summary())
    assert result.separation_violations == 0, specs
    assert result.limit_violations == 0, specs
    assert result.certified_separation_m >= scenario.limits.min_separation - 1e-6
    assert result.jerk_ratio <= 1.0 + 1e-6
    assert result.acceleration_ratio <= 1.0 + 1e-6
    assert result.velocity_ratio <= 1.0 + 1e-6
