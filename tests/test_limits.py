"""Vehicle limits and their validation."""

from __future__ import annotations

import math

import pytest

from limits import ILLUSTRATIVE_LIMITS, ILLUSTRATIVE_VEHICLE, Limits, LimitsError, VehicleLimits
from topology.errors import SeparationError


def test_illustrative_defaults():
    assert VehicleLimits(1.0, 0.5, 1.0) == ILLUSTRATIVE_VEHICLE
    assert ILLUSTRATIVE_LIMITS.min_separation == 1.5
    assert ILLUSTRATIVE_LIMITS.first == ILLUSTRATIVE_LIMITS.second == ILLUSTRATIVE_VEHICLE


def test_vehicles_may_differ_and_values_are_immutable():
    slow = VehicleLimits(max_velocity=0.7, max_acceleration=0.35, max_jerk=0.6)
    limits = Limits(vehicles=(ILLUSTRATIVE_VEHICLE, slow), min_separation=2)
    assert limits.second.max_jerk == 0.6
    assert isinstance(limits.min_separation, float)
    with pytest.raises(AttributeError):
        limits.min_separation = 1.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        pytest.param({"max_velocity": 0.0}, r"max_velocity must be > 0 m/s, got 0\.0", id="zero-velocity"),
        pytest.param(
            {"max_acceleration": -1.0}, r"max_acceleration must be > 0 m/s\^2, got -1\.0", id="negative"
        ),
        pytest.param({"max_jerk": math.nan}, r"max_jerk \(m/s\^3\) must be finite, got nan", id="nan-jerk"),
        pytest.param({"max_velocity": math.inf}, "must be finite, got inf", id="inf-velocity"),
        pytest.param({"max_jerk": "1"}, "must be a real number, got '1'", id="string"),
        pytest.param({"max_jerk": True}, "must be a real number, got True", id="bool"),
    ],
)
def test_bad_vehicle_limits(kwargs, match):
    values = {"max_velocity": 1.0, "max_acceleration": 0.5, "max_jerk": 1.0, **kwargs}
    with pytest.raises(LimitsError, match=match):
        VehicleLimits(**values)


def test_bad_limits():
    with pytest.raises(LimitsError, match="a sequence of VehicleLimits, one per vehicle, got \\(\\)"):
        Limits(vehicles=(), min_separation=1.0)
    assert Limits(vehicles=(ILLUSTRATIVE_VEHICLE,) * 3, min_separation=1.0).count == 3  # the count is data
    with pytest.raises(LimitsError, match="limits of vehicle 2 must be VehicleLimits"):
        Limits(vehicles=(ILLUSTRATIVE_VEHICLE, 1.0), min_separation=1.0)
    with pytest.raises(SeparationError, match=r"min_separation must be >= 0 m, got -1\.0"):
        Limits(vehicles=(ILLUSTRATIVE_VEHICLE, ILLUSTRATIVE_VEHICLE), min_separation=-1.0)
    with pytest.raises(SeparationError, match="must be finite"):
        Limits(vehicles=(ILLUSTRATIVE_VEHICLE, ILLUSTRATIVE_VEHICLE), min_separation=math.nan)
