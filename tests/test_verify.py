"""The verifier's own arguments, its once-per-schedule promise, and the certificate type."""

from __future__ import annotations

import dataclasses
import logging
import math

import pytest

from tests.helpers import LIMITS, route_of, too_close
from trajgen import Exact, VerifiedSchedule, certify, verify
from trajgen.errors import InputError, UnverifiedScheduleError, VerificationError

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


@pytest.mark.parametrize(
    ("period", "match"),
    [
        pytest.param(-1.0, r"must be > 0 s and at most 0\.001 s, got -1\.0", id="negative"),
        pytest.param(0.0, r"must be > 0 s and at most 0\.001 s, got 0\.0", id="zero"),
        pytest.param(math.inf, r"verifier sample period \(seconds\) must be finite, got inf", id="inf"),
        pytest.param(math.nan, "must be finite, got nan", id="nan"),
        pytest.param(0.002, r"at most 0\.001 s, got 0\.002", id="coarse"),
        pytest.param("1e-3", "must be a real number, got '1e-3'", id="string"),
    ],
)
def test_bad_periods_are_input_errors(period, match):
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    with pytest.raises(InputError, match=match):
        verify(schedule, period=period)


def test_a_finer_period_is_accepted_and_sees_more_samples():
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    assert verify(schedule, period=5e-4).samples > 1.9 * verify(schedule).samples


def test_each_schedule_is_verified_once(caplog):
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    with caplog.at_level(logging.DEBUG, logger="trajgen.verify"):
        first = verify(schedule)
        second = verify(schedule)
        certified = certify(schedule)
    assert first is second is certified.report
    assert len([r for r in caplog.records if r.message.startswith("verified a")]) == 1
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
