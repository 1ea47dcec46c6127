"""The verifier's own arguments, its once-per-schedule promise, and the certificate type."""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np
import pytest

from tests.helpers import LIMITS, route_of, too_close
from tests.mutants import with_coefficient
from trajgen import Exact, VerifiedSchedule, certify, verify
from trajgen.errors import InputError, UnverifiedScheduleError, VerificationError
from trajgen.profiles import PiecewiseCubic
from trajgen.schedule import CubicKinematics

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


def test_each_schedule_is_verified_once(caplog):
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    with caplog.at_level(logging.DEBUG, logger="trajgen.verify"):
        first = verify(schedule)
        second = verify(schedule)
        certified = certify(schedule)
    assert first is second is certified.report
    assert len([r for r in caplog.records if r.message.startswith("verified a")]) == 1
    assert first.pieces == 24  # 3 straight pieces of 7 phases, split where a vehicle passes the junction
    # an equal but distinct schedule object is verified on its own
    copy = dataclasses.replace(schedule)
    assert verify(copy) is not first
    assert verify(copy) == first


def test_a_failing_report_cannot_make_a_certificate():
    broken = too_close(Exact().schedule(route_of(*SWAP), LIMITS))
    report = verify(broken)
    assert not report.passed
    with pytest.raises(VerificationError, match=r"below the minimum 10\.5 m"):
        VerifiedSchedule(broken, report)
    with pytest.raises(UnverifiedScheduleError, match="holds a Schedule and its VerificationReport"):
        VerifiedSchedule(broken, "passed")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="verify expects a Schedule, got str"):
        verify("schedule")  # type: ignore[arg-type]


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize(("column", "name"), [(0, "axis"), (1, "velocity"), (2, "acceleration")])
def test_non_finite_values_fail_and_are_never_certified(value, column, name):
    schedule = with_coefficient(Exact().schedule(route_of(*SWAP), LIMITS), 1, column, value)
    report = verify(schedule)
    assert not report.passed
    assert any("is not finite" in f for f in report.failures), report.failures
    with pytest.raises(VerificationError, match="is not finite"):
        certify(schedule)


def test_a_non_finite_duration_fails_without_sampling():
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    section = schedule.sections[-1]
    profiles = list(section.kinematics.vehicles)
    times = np.array(profiles[0].times)
    times[-1] = math.nan
    profiles[0] = PiecewiseCubic(times, profiles[0].initial, profiles[0].jerk)
    broken = dataclasses.replace(
        schedule,
        sections=(
            *schedule.sections[:-1],
            dataclasses.replace(section, kinematics=CubicKinematics(tuple(profiles))),
        ),
    )
    report = verify(broken)
    assert report.failures == ("schedule duration is nan s: expected finite, >= 0",)


def test_a_certificate_is_bound_to_its_own_schedule():
    good = Exact().schedule(route_of(*SWAP), LIMITS)
    other = Exact(jerk=False).schedule(route_of(*SWAP), LIMITS)
    with pytest.raises(UnverifiedScheduleError, match="not this schedule's verification report"):
        VerifiedSchedule(other, verify(good))
    assert VerifiedSchedule(good, verify(good)).report.passed


def test_concurrent_callers_get_one_report():
    import threading

    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    reports = []
    threads = [threading.Thread(target=lambda: reports.append(verify(schedule))) for _ in range(6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len({id(report) for report in reports}) == 1


def test_a_schedule_that_does_not_limit_jerk_reports_no_jerk_ratio():
    from trajgen import Toppra

    report = verify(Toppra().schedule(route_of(*SWAP), LIMITS))
    assert report.jerk_ratio is None
    assert report.summary()["jerk_ratio"] is None
    assert report == verify(Toppra().schedule(route_of(*SWAP), LIMITS))
