"""What the verifier reports: its tolerances and the :class:`VerificationReport`."""

from __future__ import annotations

from dataclasses import dataclass

from trajgen.errors import VerificationError
from trajgen.model.summary import closest_text

__all__ = [
    "CONTINUITY_TOLERANCE",
    "POSITION_TOLERANCE",
    "RELATIVE_TOLERANCE",
    "REST_TOLERANCE",
    "TRACK_END_TOLERANCE",
    "Finding",
    "VerificationReport",
]

#: Relative tolerance on velocity, acceleration and jerk limits.
RELATIVE_TOLERANCE = 1e-6
#: Absolute tolerance on start, goal and separation, metres.
POSITION_TOLERANCE = 1e-9
#: At rest at the start and goal: |v| in m/s (plus |a| in m/s² for jerk-limited methods) at most this.
REST_TOLERANCE = 1e-6
#: How far past the end of its leg a position may be (solver round-off), metres; also the largest jump.
TRACK_END_TOLERANCE = 1e-6
#: Continuity from piece to piece, relative to the quantity's scale (round-off: every method integrates its
#: knots from the ones before, so a jump above this is a number that disagrees with the others).
CONTINUITY_TOLERANCE = 1e-12


class Finding(str):
    """One failed check: the plain message (the string itself) and where it lies in the schedule's arrays.

    The checks append findings to their lists of failures; :class:`VerificationReport` keeps the
    plain messages as ``failures`` and each with its arrays as ``details``.

    Parameters
    ----------
    message : str
        What is wrong in an engineer's words: the quantity, its value and limit, the vehicle, when
        (seconds) and where on the track.
    arrays : str
        The arrays of the schedule it lies in, by their paths
        (``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4, ...``).

    Examples
    --------
    >>> finding = Finding("vehicle 1 velocity reaches 1.2 m/s", "sections[0].maps[0]")
    >>> str(finding), finding.detail
    ('vehicle 1 velocity reaches 1.2 m/s', 'vehicle 1 velocity reaches 1.2 m/s: sections[0].maps[0]')
    """

    def __new__(cls, message: str, arrays: str = "") -> Finding:
        """The finding ``message``, lying in ``arrays``."""
        finding = super().__new__(cls, message)
        finding.arrays = arrays
        return finding

    @property
    def detail(self) -> str:
        """The message followed by the arrays it lies in (the message alone if none are named)."""
        return f"{self}: {self.arrays}" if self.arrays else str(self)


def _detail(failure: str) -> str:
    return failure.detail if isinstance(failure, Finding) else str(failure)


@dataclass(frozen=True, slots=True)
class VerificationReport:
    """Outcome of :func:`verify`.

    Attributes
    ----------
    passed : bool
        Whether every check passed.
    failures : tuple of str
        One message per failed check in plain words: the quantity, its value and limit, the
        vehicle, when (seconds) and where on the track.
    pieces : int
        Number of polynomial pieces checked.
    min_separation : float
        Smallest track distance between any two vehicles, metres.
    separation_margin : float
        ``min_separation - required``, metres (negative: violated).
    velocity_ratio, acceleration_ratio : tuple of float
        Per vehicle, largest ``|value| / limit`` (1.0 is at the limit).
    jerk_ratio : tuple of float or None
        The same for jerk; ``None`` when the schedule does not limit jerk.
    start_error, goal_error : float
        Track distance of the schedule's first and last positions from the route's, metres.
    regions_match : bool
        Whether the sampled region sequence equals the route's.
    details : tuple of str
        Per failure, its message followed by where it lies in the schedule's arrays
        (``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4, ...``), for debugging;
        by default (or for a failure that names none) the message alone. Given ``failures`` that
        are :class:`Finding` objects, taken from them.
    """

    passed: bool
    failures: tuple[str, ...]
    pieces: int
    min_separation: float
    separation_margin: float
    velocity_ratio: tuple[float, ...]
    acceleration_ratio: tuple[float, ...]
    jerk_ratio: tuple[float, ...] | None
    start_error: float
    goal_error: float
    regions_match: bool
    details: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        failures = tuple(self.failures)
        if not self.details or len(self.details) != len(failures):
            object.__setattr__(self, "details", tuple(_detail(failure) for failure in failures))
        else:
            object.__setattr__(self, "details", tuple(str(detail) for detail in self.details))
        object.__setattr__(self, "failures", tuple(str(failure) for failure in failures))

    def __repr__(self) -> str:
        """One line: the verdict, the closest approach and the worst ratios, or the first failure."""
        if not self.passed:
            first = self.failures[0] if self.failures else "no reason given"
            first = first if len(first) <= 120 else first[:117] + "..."
            more = f" and {len(self.failures) - 1} more" if len(self.failures) > 1 else ""
            return f"<VerificationReport: FAILED, {first}{more}>"
        ratios = [max(self.velocity_ratio), max(self.acceleration_ratio)]
        ratios += [] if self.jerk_ratio is None else [max(self.jerk_ratio)]
        return (
            f"<VerificationReport: passed, {self.pieces} pieces, "
            f"closest approach {closest_text(self.min_separation)}, "
            f"worst ratio to the limits {max(ratios):.6f}>"
        )

    @classmethod
    def failed(cls, failures: tuple[str, ...], *, pieces: int = 0, count: int = 0) -> VerificationReport:
        """The report of a motion that could not be checked further (its figures are NaN).

        ``count``: the motion's vehicles, each given a NaN ratio (none where it is not known).
        """
        nan = float("nan")
        return cls(
            passed=False,
            failures=tuple(failures),
            pieces=pieces,
            min_separation=nan,
            separation_margin=nan,
            velocity_ratio=(nan,) * count,
            acceleration_ratio=(nan,) * count,
            jerk_ratio=None,
            start_error=nan,
            goal_error=nan,
            regions_match=False,
        )

    def raise_if_failed(self) -> None:
        """Raise VerificationError listing the failures in plain words (with ``details``), if any."""
        if not self.passed:
            raise VerificationError(
                "schedule failed verification: " + "; ".join(self.failures), details=self.details
            )

    def summary(self) -> dict:
        """JSON-ready worst margins."""
        return {
            "verified": self.passed,
            "failures": list(self.failures),
            "pieces": self.pieces,
            "min_separation_m": self.min_separation,
            "separation_margin_m": self.separation_margin,
            "velocity_ratio": list(self.velocity_ratio),
            "acceleration_ratio": list(self.acceleration_ratio),
            "jerk_ratio": None if self.jerk_ratio is None else list(self.jerk_ratio),
            "start_error_m": self.start_error,
            "goal_error_m": self.goal_error,
            "regions_match": self.regions_match,
        }
