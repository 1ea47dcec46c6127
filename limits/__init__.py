"""Vehicle limits (velocity, acceleration, jerk) and the minimum separation.

Examples
--------
>>> from limits import VehicleLimits, Limits
>>> agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
>>> Limits(vehicles=(agv, agv), min_separation=1.5).min_separation
1.5
"""

from limits.errors import LimitsError
from limits.vehicle import (
    EMERGENCY_FACTOR,
    ILLUSTRATIVE_LIMITS,
    ILLUSTRATIVE_MIN_SEPARATION,
    ILLUSTRATIVE_VEHICLE,
    Limits,
    VehicleLimits,
)

__all__ = [
    "EMERGENCY_FACTOR",
    "ILLUSTRATIVE_LIMITS",
    "ILLUSTRATIVE_MIN_SEPARATION",
    "ILLUSTRATIVE_VEHICLE",
    "Limits",
    "LimitsError",
    "VehicleLimits",
]
