"""Straight moves: closed form vs Ruckig vs the exact schedule."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from ruckig import InputParameter, Result, Ruckig, Trajectory

from limits import Limits, VehicleLimits
from tests.support.helpers import route_of
from trajgen import Exact
from trajgen.model.profiles import PiecewiseCubic, rest_to_rest_time, scurve_phases, trapezoid_phases


def ruckig_move(distance: float, v: float, a: float, j: float) -> Trajectory:
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [distance], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    trajectory = Trajectory(1)
    assert otg.calculate(inp, trajectory) == Result.Working
    return trajectory


_PEAK = 0.25 * (-0.5 + np.sqrt(0.25 + 8.0))  # D=1, a=0.5, j=1: v^2/a + v a/j = D


@pytest.mark.parametrize(
    ("distance", "v", "a", "j", "expected"),
    [
        # cruise reached: 2 (a/j + v/a) + (D - v (a/j + v/a)) / v
        pytest.param(20.0, 1.0, 0.5, 1.0, 2 * (0.5 + 2.0) + (20.0 - 2.5) / 1.0, id="cruise"),
        # a reached, v not: T = 2 (a/j + v_peak/a)
        pytest.param(1.0, 1.0, 0.5, 1.0, 2 * (0.5 + _PEAK / 0.5), id="no-cruise"),
        # neither a nor v reached: T = 4 (D / 2j)^(1/3)
        pytest.param(0.1, 1.0, 0.5, 1.0, 4 * 0.05 ** (1 / 3), id="jerk-only"),
        # a never reachable (v j < a^2): ramps of 2 sqrt(v/j), then cruise
        pytest.param(
            10.0, 0.2, 1.0, 1.0, 4 * np.sqrt(0.2) + (10.0 - 0.2 * 2 * np.sqrt(0.2)) / 0.2, id="low-v"
        ),
    ],
)
def test_scurve_closed_form(distance, v, a, j, expected):
    assert rest_to_rest_time(distance, v, a, j) == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(ruckig_move(distance, v, a, j).duration, rel=1e-9)


def test_scurve_reference_values():
    assert rest_to_rest_time(20.0, 1.0, 0.5, 1.0) == pytest.approx(22.5)
    assert rest_to_rest_time(0.1, 1.0, 0.5, 1.0) == pytest.approx(4 * 0.05 ** (1 / 3))
    assert rest_to_rest_time(20.0, 1.0, 0.5) == pytest.approx(22.0)  # trapezoid: 2 s ramps, 18 s cruise
    assert rest_to_rest_time(1.0, 1.0, 0.5) == pytest.approx(2 * np.sqrt(2.0))  # triangle


@given(
    distance=st.floats(1e-3, 60.0),
    v=st.floats(0.05, 3.0),
    a=st.floats(0.05, 3.0),
    j=st.floats(0.05, 5.0),
)
def test_closed_form_agrees_with_ruckig(distance, v, a, j):
    reference = ruckig_move(distance, v, a, j)
    phases = scurve_phases(distance, v, a, j)
    assert sum(d for d, _ in phases) == pytest.approx(reference.duration, rel=1e-7, abs=1e-9)
    profile = PiecewiseCubic.from_phases(0.0, [(d, np.nan, jerk) for d, jerk in phases], end=distance)
    times = np.linspace(0.0, reference.duration, 41)
    ours = profile.evaluate(times)
    theirs = np.array([reference.at_time(t) for t in times])  # rows: (position, velocity, acceleration)
    scale = max(distance, 1.0)
    assert np.allclose(ours[0], theirs[:, 0, 0], atol=1e-7 * scale)
    assert np.allclose(ours[1], theirs[:, 1, 0], atol=1e-7 * scale)
    assert np.allclose(ours[2], theirs[:, 2, 0], atol=1e-6 * scale)
    assert np.all(np.abs(ours[1]) <= v * (1 + 1e-9))
    assert np.all(np.abs(ours[2]) <= a * (1 + 1e-9))
    assert np.all(np.abs(ours[3]) <= j * (1 + 1e-9))


@pytest.mark.parametrize(
    ("v", "a", "distance"),
    [pytest.param(1.0, 0.5, 20.0, id="trapezoid"), pytest.param(1.0, 0.5, 1.0, id="triangle")],
)
def test_trapezoid_reaches_the_distance_within_limits(v, a, distance):
    phases = trapezoid_phases(distance, v, a)
    profile = PiecewiseCubic.from_phases(0.0, [(d, acc, 0.0) for d, acc in phases], end=distance)
    values = profile.evaluate(np.linspace(0.0, profile.duration, 2001))
    assert values[0, -1] == pytest.approx(distance, abs=1e-12)
    assert np.max(np.abs(values[1])) <= v * (1 + 1e-12)
    assert values[1, -1] == pytest.approx(0.0, abs=1e-12)


def test_exact_schedule_of_a_single_move_is_the_slower_vehicles_scurve():
    # vehicle 2 parked at the junction, vehicle 1 drives A:2 -> A:9 directly (a ray, one straight piece)
    slow = VehicleLimits(max_velocity=0.7, max_acceleration=0.35, max_jerk=0.6)
    limits = Limits(vehicles=(slow, VehicleLimits(1.0, 0.5, 1.0)), min_separation=1.5)
    route = route_of((10.0, 8.0, 15.0), ("A:2", "O"), ("A:10", "O"))
    schedule = Exact().schedule(route, limits)
    assert schedule.duration == pytest.approx(ruckig_move(8.0, 0.7, 0.35, 0.6).duration, rel=1e-9)


def test_exact_schedule_scales_limits_on_a_diagonal_piece():
    # quadrangle retraction moves both vehicles at once with speed ratio s1 : s2 = 3 : 2
    route = route_of((12.0, 8.0, 15.0), ("A:3", "B:2"), ("A:12", "B:8"), 0.0)
    limits = Limits(vehicles=(VehicleLimits(1.0, 0.5, 1.0), VehicleLimits(1.0, 0.5, 1.0)), min_separation=0.0)
    schedule = Exact().schedule(route, limits)
    # one piece: vehicle 1 moves 9 m, vehicle 2 moves 6 m; vehicle 1's limits bind
    assert len(schedule.sections) == 1
    assert schedule.duration == pytest.approx(ruckig_move(9.0, 1.0, 0.5, 1.0).duration, rel=1e-9)
    state = schedule.sample(0.01)
    assert np.max(np.abs(state.velocity[0])) == pytest.approx(1.0)
    ratio = state.velocity[1, 1:-1] / state.velocity[0, 1:-1]
    assert np.allclose(ratio, 6.0 / 9.0)
