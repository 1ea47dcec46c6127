"""Mutation tests of the verifier: defects between its samples are caught in closed form; tolerances hold."""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.helpers import LIMITS, route_of
from tests.support.mutants import between_samples, free_window, with_bump
from tests.support.sampled_verifier import sampled_verify
from topology.indexed import track_distance
from trajgen import Exact, Optimal, verify
from trajgen.model.analysis import travelled

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


# -- mutants of the position maps and of the sections (found by a hostile review) ---------------------


def _replace_section(schedule, index, **changes):
    import dataclasses

    sections = list(schedule.sections)
    sections[index] = dataclasses.replace(sections[index], **changes)
    return dataclasses.replace(schedule, sections=tuple(sections))


def _replace_map(schedule, index, vehicle, **changes):
    import dataclasses

    maps = list(schedule.sections[index].maps)
    maps[vehicle] = dataclasses.replace(maps[vehicle], **changes)
    return _replace_section(schedule, index, maps=tuple(maps))


def test_a_zero_length_last_section_cannot_teleport_a_vehicle_to_the_goal(exact):
    import dataclasses

    from trajgen.model.axes import piece_profiles
    from trajgen.model.profiles import PiecewiseCubic
    from trajgen.model.schedule import AxisMap, CubicKinematics, Section

    # the last piece stops vehicle 2 at axis 9 (11 m short of its goal); a section of zero length at
    # the end reports the goal anyway
    short = CubicKinematics(piece_profiles(np.array([20.0, 20.0]), np.array([20.0, 9.0]), exact.limits))
    cut = _replace_section(exact, 2, kinematics=short)
    end = cut.sections[2].start_time + short.duration
    rest = CubicKinematics((PiecewiseCubic.from_phases(20.0, []), PiecewiseCubic.from_phases(0.0, [])))
    parked = Section(end, rest, (AxisMap.parked(20.0, 1, 10.0), AxisMap.parked(0.0, 0, 10.0)))
    mutant = dataclasses.replace(cut, sections=(*cut.sections, parked))
    report = verify(mutant)
    assert any("from where its motion puts it at the goal" in f for f in report.failures), report.failures


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        pytest.param({"outward": np.array([-2, 2])}, "map slopes [-2, 2] are not -1, 0 or +1", id="slope-2"),
        pytest.param({"legs": np.array([1, 3])}, "map legs [1, 3] are not track legs", id="leg-3"),
        pytest.param({"legs": np.array([1, -2])}, "map legs [1, -2] are not track legs", id="leg-minus-2"),
        pytest.param({"axis_end": np.array([8.0, 20.0])}, "map sub-ranges do not join", id="gap"),
        pytest.param(
            {"legs": np.array([1, -1])}, "at the junction moves or lies off it", id="moving-junction"
        ),
    ],
)
def test_malformed_position_maps_fail(exact, changes, message):
    # section 0, vehicle 2: B (end) -> junction -> C (end), two sub-ranges
    assert exact.sections[0].maps[1].legs.tolist() == [1, 2]
    report = verify(_replace_map(exact, 0, 1, **changes))
    assert not report.passed
    assert any(message in f for f in report.failures), report.failures


def test_a_reversal_hidden_in_a_map_change_on_one_leg_is_a_jump(exact):
    from trajgen.model.schedule import AxisMap

    # vehicle 2 on leg B only, but the second half of its axis range maps backwards: a U-turn at 5 m
    first = exact.sections[0].maps[1]
    bounce = AxisMap(
        first.axis_start, first.axis_end, np.array([1, 1]), np.array([10.0, 0.0]), np.array([-1, 1])
    )
    report = verify(
        _replace_map(exact, 0, 1, **{f: getattr(bounce, f) for f in ("legs", "s_start", "outward")})
    )
    assert not report.passed
    assert any("velocity jumps" in f or "do not join" in f for f in report.failures), report.failures


def test_kinematics_the_verifier_does_not_know_cannot_be_certified(exact):
    from trajgen.model.schedule import CubicKinematics

    class Liar(CubicKinematics):  # evaluates (and so would export) something else than its cubics
        __slots__ = ()

        def evaluate(self, t):
            return super().evaluate(t) * 1.5

    section = exact.sections[0]
    report = verify(_replace_section(exact, 0, kinematics=Liar(section.kinematics.vehicles)))
    assert any("no polynomial form the verifier knows" in f for f in report.failures)


def test_extreme_but_plausible_limits_verify_through_the_time_round_off():
    from limits import Limits, VehicleLimits

    # acceleration 0.001 m/s^2 with jerk 1e6 m/s^3: jerk phases of 1e-9 s at t ~ 30 s, near float resolution
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.001, max_jerk=1e6)
    limits = Limits((agv, agv), min_separation=1.5)
    report = verify(Exact().schedule(route_of(*SWAP), limits))
    assert report.passed, report.failures
