"""Mutation tests of the verifier: defects between its samples are caught in closed form; tolerances hold."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import LIMITS, route_of
from tests.mutants import between_samples, free_window, with_bump
from tests.sampled_verifier import sampled_verify
from topology.indexed import track_distance
from trajgen import Exact, Optimal, verify
from trajgen.analysis import travelled

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


def _closest_approach(schedule):
    state = schedule.sample(1e-3)
    gap = track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])
    k = int(np.argmin(gap))
    return float(state.t[k])


def _moving_vehicle(schedule, t):
    state = schedule.state([t])
    return int(np.argmax(np.abs(state.velocity[:, 0])))


def _farther_vehicle(schedule, t):
    """The vehicle farther from the junction at ``t`` and the axis sign that brings it closer to the other."""
    state = schedule.state([t])
    vehicle = int(np.argmax(state.s[:, 0]))
    section = next(s for s in schedule.sections if s.start_time <= t < s.start_time + s.duration)
    return vehicle, -int(section.maps[vehicle].outward[0])  # vehicles on different legs: toward the junction


@pytest.fixture(scope="module")
def exact():
    return Exact().schedule(route_of(*SWAP), LIMITS)


@pytest.fixture(scope="module")
def optimal():
    return Optimal().schedule(route_of(*SWAP), LIMITS)


def test_a_one_percent_velocity_spike_between_samples_is_caught(exact):
    t = between_samples(exact, 0.5 * exact.sections[0].duration)
    vehicle = _moving_vehicle(exact, t)
    h = 0.2e-3  # a 0.8 ms window
    mutant = with_bump(exact, vehicle, t, 4 * h, 0.01 * 1.0 * h)  # peak |dv| = height / h
    report = verify(mutant)
    assert not report.passed
    assert any("velocity reaches 1.01" in f for f in report.failures), report.failures
    assert sampled_verify(mutant).passed  # the second opinion, sampling every 1 ms, does not see it
    assert report.velocity_ratio[vehicle] == pytest.approx(1.01, rel=1e-6)


@pytest.mark.parametrize(("dip", "below"), [(1e-3, 1.5 - 1e-5), (2.0, 0.0)], ids=["1mm-dip", "collision"])
def test_a_dip_or_a_collision_between_samples_is_caught(optimal, dip, below):
    near = _closest_approach(optimal)
    vehicle, sign = _farther_vehicle(optimal, near)
    assert optimal.state([near]).leg[0, 0] != optimal.state([near]).leg[1, 0]  # different legs there
    t = free_window(optimal, vehicle, near)
    mutant = with_bump(optimal, vehicle, t, 0.8e-3, sign * dip)
    report = verify(mutant)
    assert not report.passed
    assert any("below the minimum 1.5 m" in f for f in report.failures), report.failures
    if dip < 1.0:
        assert sampled_verify(mutant).passed  # between the samples: only the closed form sees it
    assert report.min_separation < below


def test_the_closed_form_sees_what_a_sampled_check_misses(exact):
    t = between_samples(exact, 0.5 * exact.sections[0].duration)
    vehicle = _moving_vehicle(exact, t)
    mutant = with_bump(exact, vehicle, t, 0.8e-3, 2e-6)
    # the 1 ms samples of the mutant and of the original agree: the defect lies between them
    times = np.linspace(0.0, exact.duration, int(np.ceil(exact.duration / 1e-3)) + 1)
    assert np.array_equal(mutant.state(times).velocity, exact.state(times).velocity)
    assert not verify(mutant).passed


def test_defects_inside_the_tolerances_pass(exact):
    t = 0.5 * exact.sections[0].duration  # cruise: a 40 ms window holds no breakpoint
    vehicle = _moving_vehicle(exact, t)
    mutant = with_bump(exact, vehicle, t, 40e-3, 1e-10)  # 0.1 nm, |dv| 1e-8 m/s
    report = verify(mutant)
    assert report.passed, report.failures
    assert travelled(mutant)[1][vehicle, -1] == pytest.approx(travelled(exact)[1][vehicle, -1], abs=1e-9)
