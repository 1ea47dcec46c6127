"""The verifier's own arguments, its once-per-schedule promise, and the certificate type."""

from __future__ import annotations

import dataclasses
import logging
import math
import re

import numpy as np
import pytest

from tests.support.corruption import corrupted
from tests.support.helpers import LIMITS, route_of, too_close
from tests.support.mutants import with_coefficient
from trajgen import Exact, VerifiedSchedule, certify, verify
from trajgen.errors import InputError, UnverifiedScheduleError, VerificationError
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import AxisMap

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


def test_verification_cost_grows_with_pieces_not_with_duration():
    import time

    from limits import VehicleLimits
    from trajgen import Limits

    # the same route at a thousandth of the speed: a thousand times longer, the same pieces
    slow = VehicleLimits(max_velocity=1e-3, max_acceleration=5e-4, max_jerk=1e-3)
    fast_schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    slow_schedule = Exact().schedule(route_of(*SWAP), Limits((slow, slow), min_separation=1.5))
    assert slow_schedule.duration > 500 * fast_schedule.duration
    began = time.perf_counter()
    report = verify(slow_schedule)
    assert time.perf_counter() - began < 1.0
    assert report.passed, report.failures
    assert report.pieces == verify(fast_schedule).pieces


def test_verify_is_a_pure_function_of_the_schedule(caplog):
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    with caplog.at_level(logging.DEBUG, logger="trajgen.verification"):
        first = verify(schedule)
        second = verify(schedule)
        certified = certify(schedule)
    assert first == second == certified.report  # equal reports, each computed afresh: nothing is kept
    assert len([r for r in caplog.records if r.message.startswith("verified a")]) == 3
    assert first.pieces == 24  # 3 straight pieces of 7 phases, split where a vehicle passes the junction
    assert verify(dataclasses.replace(schedule)) == first


def test_a_failing_report_cannot_make_a_certificate():
    broken = too_close(Exact().schedule(route_of(*SWAP), LIMITS))
    report = verify(broken)
    assert not report.passed
    with pytest.raises(VerificationError, match=r"below the minimum 10\.5 m"):
        certify(broken)
    with pytest.raises(UnverifiedScheduleError, match=r"made by trajgen\.certify\(schedule\) alone"):
        VerifiedSchedule(broken, report)
    with pytest.raises(InputError, match="verify expects a Schedule or a GraphSchedule, got str"):
        verify("schedule")  # type: ignore[arg-type]


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize(("column", "name"), [(0, "axis"), (1, "velocity"), (2, "acceleration")])
def test_non_finite_values_fail_and_are_never_certified(value, column, name):
    schedule, entry = with_coefficient(Exact().schedule(route_of(*SWAP), LIMITS), 1, column, value)
    report = verify(schedule)
    assert not report.passed
    expected = f"{entry} is {value!r}: expected a finite number"
    assert len(report.details) == 1, report.details
    assert report.details[0].endswith(f": {expected}"), report.details
    with pytest.raises(
        VerificationError, match=re.escape(f"hold {value!r}: expected finite numbers")
    ) as caught:
        certify(schedule)
    assert caught.value.details == report.details


def test_a_non_finite_duration_fails_naming_the_knot():
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    path = f"sections[{len(schedule.sections) - 1}].kinematics.vehicles[0].times"
    times = np.array(schedule.sections[-1].kinematics.vehicles[0].times)
    times[-1] = math.nan
    report = verify(corrupted(schedule, path, times))
    assert len(report.details) == 1
    assert report.details[0].endswith(f": {path}[{times.size - 1}] is nan: expected a finite number")


@pytest.mark.parametrize(
    ("arrays", "message"),
    [
        (([0.0, 1.0, math.nan], [[0, 0, 0], [0, 0, 0]], [1.0, -1.0]), "times holds a non-finite value"),
        (([0.0, 1.0, 2.0], [[0, 0, 0], [0, math.inf, 0]], [1.0, -1.0]), "initial holds a non-finite value"),
        (([0.0, 1.0, 2.0], [[0, 0, 0], [0, 0, 0]], [1.0, -math.inf]), "jerk holds a non-finite value"),
        (([0.0, 2.0, 1.0], [[0, 0, 0], [0, 0, 0]], [1.0, -1.0]), r"times do not increase at \[2\]"),
        (([0.0, 1.0, 1.0], [[0, 0, 0], [0, 0, 0]], [1.0, -1.0]), r"times do not increase at \[2\]"),
        (([0.0, 1.0], [[0, 0, 0], [0, 0, 0]], [1.0]), r"initial of shape \(2, 3\)"),
    ],
    ids=["nan-knot", "inf-velocity", "inf-jerk", "unsorted", "repeated", "shapes"],
)
def test_a_piecewise_cubic_refuses_numbers_no_motion_has(arrays, message):
    times, initial, jerk = (np.array(a, dtype=float) for a in arrays)
    with pytest.raises(InputError, match=message):
        PiecewiseCubic(times, initial, jerk)


def test_a_profile_of_no_time_at_rest_is_allowed():
    profile = PiecewiseCubic(np.array([0.0, 0.0]), np.array([[2.0, 0.0, 0.0]]), np.zeros(1))
    assert profile.duration == 0.0


def test_an_axis_map_refuses_a_non_finite_number():
    with pytest.raises(InputError, match="axis map: s_start holds a non-finite value"):
        AxisMap(np.array([0.0]), np.array([1.0]), np.array([0]), np.array([math.nan]), np.array([1]))


def test_certify_alone_makes_a_certificate_bound_to_its_own_schedule():
    import copy

    good = Exact().schedule(route_of(*SWAP), LIMITS)
    other = Exact(jerk=False).schedule(route_of(*SWAP), LIMITS)
    verified = certify(good)
    with pytest.raises(UnverifiedScheduleError, match="expected certify, not the class"):
        VerifiedSchedule(good, verify(good))  # even with its own passing report
    with pytest.raises(UnverifiedScheduleError, match="expected certify, not the class"):
        dataclasses.replace(verified, schedule=other)  # no certificate moves to another schedule
    assert verified.schedule is good
    assert verified.report.passed
    twin = copy.copy(verified)  # a copy is the same certificate
    assert isinstance(twin, VerifiedSchedule)
    assert twin.report is verified.report
    with pytest.raises(dataclasses.FrozenInstanceError):
        verified.schedule = other  # type: ignore[misc]


def test_a_schedule_that_does_not_limit_jerk_reports_no_jerk_ratio():
    from trajgen import Toppra

    report = verify(Toppra().schedule(route_of(*SWAP), LIMITS))
    assert report.jerk_ratio is None
    assert report.summary()["jerk_ratio"] is None
    assert report == verify(Toppra().schedule(route_of(*SWAP), LIMITS))


def test_a_verified_schedule_and_its_report_print_as_one_short_line():
    from trajgen import Exact, VerificationReport, certify, default_scenario, make_schedule

    scenario = default_scenario()
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact()))
    for value in (verified, verified.schedule, verified.report):
        text = repr(value)
        assert "\n" not in text
        assert len(text) <= 240, text
        assert "array" not in text
    assert repr(verified) == (
        "<VerifiedSchedule: exact, 67.500 s in 3 section(s), jerk-limited, counterclockwise; "
        "passed, 24 pieces, closest approach 10.0000 m, worst ratio to the limits 1.000000>"
    )
    failed = VerificationReport.failed(tuple(f"failure {k}: " + "x" * 300 for k in range(5)))
    assert repr(failed).startswith("<VerificationReport: FAILED, failure 0: xxx")
    assert repr(failed).endswith("... and 4 more>")
    assert len(repr(failed)) <= 200
