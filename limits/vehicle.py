"""Value objects for the drive limits of each vehicle and the separation."""

from __future__ import annotations

from dataclasses import dataclass

from limits.errors import LimitsError
from topology.errors import SeparationError
from topology.validation import finite_real

__all__ = [
    "EMERGENCY_FACTOR",
    "ILLUSTRATIVE_LIMITS",
    "ILLUSTRATIVE_MIN_SEPARATION",
    "ILLUSTRATIVE_VEHICLE",
    "Limits",
    "VehicleLimits",
]


#: Default emergency deceleration as a multiple of ``max_acceleration``.
EMERGENCY_FACTOR = 2.0


@dataclass(frozen=True, slots=True)
class VehicleLimits:
    """Kinematic limits of one vehicle along its own path (names as in Ruckig).

    Parameters
    ----------
    max_velocity : float
        Largest speed ``|v|``, m/s, finite and > 0.
    max_acceleration : float
        Largest ``|a|``, m/s², finite and > 0.
    max_jerk : float
        Largest ``|j|``, m/s³, finite and > 0.
    emergency_deceleration : float or None, optional
        Deceleration of an emergency stop, m/s², at least ``max_acceleration``;
        ``None`` (default) means ``EMERGENCY_FACTOR * max_acceleration``. The
        online executor assumes the other vehicle may stop this hard at any time.

    Raises
    ------
    LimitsError
        A limit that is not a finite positive number, or an emergency deceleration below ``max_acceleration``.
    """

    max_velocity: float
    max_acceleration: float
    max_jerk: float
    emergency_deceleration: float | None = None

    def __post_init__(self) -> None:
        for name, unit in (("max_velocity", "m/s"), ("max_acceleration", "m/s^2"), ("max_jerk", "m/s^3")):
            value = finite_real(getattr(self, name), f"{name} ({unit})", LimitsError)
            if value <= 0.0:
                raise LimitsError(f"{name} must be > 0 {unit}, got {value!r}")
            object.__setattr__(self, name, value)
        if self.emergency_deceleration is not None:
            value = finite_real(self.emergency_deceleration, "emergency_deceleration (m/s^2)", LimitsError)
            if value < self.max_acceleration:
                raise LimitsError(
                    f"emergency_deceleration must be >= max_acceleration {self.max_acceleration!r} m/s^2 "
                    f"(an emergency stop is no gentler than service braking), got {value!r}"
                )
            object.__setattr__(self, "emergency_deceleration", value)

    @property
    def emergency_braking(self) -> float:
        """Deceleration of an emergency stop, m/s² (the default when none was given)."""
        if self.emergency_deceleration is not None:
            return self.emergency_deceleration
        return EMERGENCY_FACTOR * self.max_acceleration


@dataclass(frozen=True, slots=True)
class Limits:
    """Limits of each vehicle and the minimum separation between every two of them.

    The number of vehicles is data: the planners say how many they take (two, today).

    Parameters
    ----------
    vehicles : sequence of VehicleLimits
        Vehicle 1's limits, then vehicle 2's, and so on (at least one); they may differ.
    min_separation : float
        Minimum track distance between any two vehicles, metres, finite and >= 0.
        Whether it fits the track (at most the shortest leg) is checked when
        planning.
    """

    vehicles: tuple[VehicleLimits, ...]
    min_separation: float

    def __post_init__(self) -> None:
        vehicles = tuple(self.vehicles) if isinstance(self.vehicles, (tuple, list)) else None
        if not vehicles:
            raise LimitsError(
                f"vehicles must be a sequence of VehicleLimits, one per vehicle, got {self.vehicles!r}"
            )
        for k, vehicle in enumerate(vehicles, start=1):
            if not isinstance(vehicle, VehicleLimits):
                raise LimitsError(
                    f"limits of vehicle {k} must be VehicleLimits, got {vehicle!r} ({type(vehicle).__name__})"
                )
        separation = finite_real(self.min_separation, "min_separation (metres)", SeparationError)
        if separation < 0.0:
            raise SeparationError(f"min_separation must be >= 0 m, got {separation!r}")
        object.__setattr__(self, "vehicles", vehicles)
        object.__setattr__(self, "min_separation", separation)

    @property
    def count(self) -> int:
        """How many vehicles."""
        return len(self.vehicles)

    @property
    def first(self) -> VehicleLimits:
        """Limits of vehicle 1."""
        return self.vehicles[0]

    @property
    def second(self) -> VehicleLimits:
        """Limits of vehicle 2."""
        return self.vehicles[1]


#: Illustrative limits of one AGV (1.0 m/s, 0.5 m/s², 1.0 m/s³). Not a real vehicle's data.
ILLUSTRATIVE_VEHICLE = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
#: Illustrative minimum separation, metres. Not a safety figure for any real vehicle.
ILLUSTRATIVE_MIN_SEPARATION = 1.5
#: Both vehicles with the illustrative limits and separation.
ILLUSTRATIVE_LIMITS = Limits(vehicles=(ILLUSTRATIVE_VEHICLE, ILLUSTRATIVE_VEHICLE), min_separation=1.5)
