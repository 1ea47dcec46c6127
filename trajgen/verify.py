"""Independent verifier: nothing leaves the library unless it passes.

Each schedule object is verified once: the report is kept (for the last
:data:`_REMEMBERED` schedules) and returned again for the same schedule and
period. :func:`certify` turns a passing schedule into a :class:`VerifiedSchedule`,
the only kind of schedule that exporters and plots accept.

The verifier re-samples a schedule on a fine time grid (1 ms or finer, plus
every section boundary) and checks, from the sampled track positions and
kinematics alone:

- the track distance between the vehicles never drops below the minimum
  separation;
- ``|v|``, ``|a|`` (and ``|j|`` where the method limits it) stay within each
  vehicle's limits, to a relative tolerance;
- the start and the goal are the route's, to 1e-9 m, at rest (1e-6 m/s);
- every position is on the track (at most 1e-6 m past a leg's end);
- the positions move no faster than the sampled velocities allow (the track
  positions and the kinematics tell one story);
- the sequence of regions visited (the homotopy class) is the route's.

Tolerance: 1e-6 relative for every method. The ``toppra`` method enforces its
limits at grid points only and therefore plans with a small headroom
(:data:`trajgen.methods.toppra.HEADROOM`), so the true limits hold between
grid points too; the verifier checks them at the same 1e-6.
"""

from __future__ import annotations

import collections
import logging
import math
import threading
import time
import weakref
from dataclasses import dataclass

import numpy as np

from topology import Region, RegionKey, reduce_regions
from topology.indexed import JUNCTION_INDEX, region_keys, track_distance
from topology.validation import finite_real
from trajgen import polynomials
from trajgen.errors import InputError, UnverifiedScheduleError, VerificationError
from trajgen.pieces import Pieces, UncheckableKinematicsError, schedule_pieces
from trajgen.schedule import Schedule, ScheduleState

__all__ = [
    "MAX_PERIOD",
    "POSITION_TOLERANCE",
    "RELATIVE_TOLERANCE",
    "VerificationReport",
    "VerifiedSchedule",
    "certify",
    "require_verified",
    "verify",
]

logger = logging.getLogger(__name__)

#: Relative tolerance on velocity, acceleration and jerk limits.
RELATIVE_TOLERANCE = 1e-6
#: Absolute tolerance on start, goal and separation, metres.
POSITION_TOLERANCE = 1e-9
#: At rest at the start and goal: |v| in m/s (plus |a| in m/s² for jerk-limited methods) at most this.
REST_TOLERANCE = 1e-6
#: How far past the end of its leg a sampled position may be (solver round-off), metres.
TRACK_END_TOLERANCE = 1e-6
#: Coarsest sampling the verifier accepts, seconds.
MAX_PERIOD = 1e-3


@dataclass(frozen=True, slots=True)
class VerificationReport:
    """Outcome of :func:`verify`.

    Attributes
    ----------
    passed : bool
        Whether every check passed.
    failures : tuple of str
        One message per failed check, naming the quantity, value and limit.
    samples : int
        Number of time samples checked.
    pieces : int
        Number of polynomial pieces checked in closed form (between the samples too).
    period : float
        Sample period, seconds.
    min_separation : float
        Smallest track distance between the vehicles, metres.
    separation_margin : float
        ``min_separation - required``, metres (negative: violated).
    velocity_ratio, acceleration_ratio : tuple of 2 float
        Per vehicle, largest ``|value| / limit`` (1.0 is at the limit).
    jerk_ratio : tuple of 2 float or None
        The same for jerk; ``None`` when the schedule does not limit jerk.
    start_error, goal_error : float
        Track distance of the schedule's first and last positions from the route's, metres.
    regions_match : bool
        Whether the sampled region sequence equals the route's.
    """

    passed: bool
    failures: tuple[str, ...]
    samples: int
    pieces: int
    period: float
    min_separation: float
    separation_margin: float
    velocity_ratio: tuple[float, float]
    acceleration_ratio: tuple[float, float]
    jerk_ratio: tuple[float, float] | None
    start_error: float
    goal_error: float
    regions_match: bool

    def raise_if_failed(self) -> None:
        """Raise VerificationError listing the failures, if any."""
        if not self.passed:
            raise VerificationError("schedule failed verification: " + "; ".join(self.failures))

    def summary(self) -> dict:
        """JSON-ready worst margins."""
        return {
            "verified": self.passed,
            "failures": list(self.failures),
            "samples": self.samples,
            "pieces": self.pieces,
            "sample_period_s": self.period,
            "min_separation_m": self.min_separation,
            "separation_margin_m": self.separation_margin,
            "velocity_ratio": list(self.velocity_ratio),
            "acceleration_ratio": list(self.acceleration_ratio),
            "jerk_ratio": None if self.jerk_ratio is None else list(self.jerk_ratio),
            "start_error_m": self.start_error,
            "goal_error_m": self.goal_error,
            "regions_match": self.regions_match,
        }


@dataclass(frozen=True, slots=True)
class VerifiedSchedule:
    """A schedule that passed the verifier, with its report: what exporters and plots accept.

    Made by :func:`certify`; constructing one from a failing report raises.

    Attributes
    ----------
    schedule : Schedule
    report : VerificationReport
        The passed report.
    """

    schedule: Schedule
    report: VerificationReport

    def __post_init__(self) -> None:
        if not isinstance(self.schedule, Schedule) or not isinstance(self.report, VerificationReport):
            raise UnverifiedScheduleError("a VerifiedSchedule holds a Schedule and its VerificationReport")
        if not self.report.passed:
            raise VerificationError("schedule failed verification: " + "; ".join(self.report.failures))
        if verify(self.schedule, period=self.report.period) != self.report:
            raise UnverifiedScheduleError("the report given is not this schedule's verification report")


def _sample_times(schedule: Schedule, period: float) -> np.ndarray:
    duration = schedule.duration
    count = max(int(np.ceil(duration / period)), 1)
    grid = np.linspace(0.0, duration, count + 1)
    boundaries = np.array([section.start_time for section in schedule.sections] + [duration])
    return np.unique(np.concatenate([grid, boundaries]))


#: Reports kept for schedules already verified (by identity and period).
_REMEMBERED = 64
_reports: collections.OrderedDict[tuple[int, float], tuple[weakref.ref, VerificationReport]] = (
    collections.OrderedDict()
)
_reports_lock = threading.Lock()
#: One lock per schedule being verified, so that concurrent callers wait for one verification.
_in_progress: dict[tuple[int, float], threading.Lock] = {}
#: Finest sampling the verifier accepts, seconds.
MIN_PERIOD = 1e-6
#: Most samples one verification takes (memory grows with them: about 200 bytes each).
MAX_SAMPLES = 20_000_000


def _check_period(period: object) -> float:
    value = finite_real(period, "verifier sample period (seconds)", InputError)
    if not MIN_PERIOD <= value <= MAX_PERIOD:
        raise InputError(
            f"verifier sample period must be between {MIN_PERIOD:g} s and {MAX_PERIOD:g} s, got {value!r}"
        )
    return value


def _remembered(key: tuple[int, float], schedule: Schedule) -> VerificationReport | None:
    with _reports_lock:
        remembered = _reports.get(key)
        if remembered is not None and remembered[0]() is schedule:
            _reports.move_to_end(key)
            return remembered[1]
    return None


def verify(schedule: Schedule, *, period: float = MAX_PERIOD) -> VerificationReport:
    """Check a schedule independently of how it was computed.

    Parameters
    ----------
    schedule : Schedule
    period : float, optional
        Sample period in seconds, ``0 < period <= 1e-3``.

    Returns
    -------
    VerificationReport
        The same report object for the same schedule and period, computed once.

    Raises
    ------
    InputError
        ``period`` not finite or outside [1e-6, 1e-3] s, more than :data:`MAX_SAMPLES`
        samples, or ``schedule`` not a Schedule.
    """
    period = _check_period(period)
    if not isinstance(schedule, Schedule):
        raise InputError(f"verify expects a Schedule, got {type(schedule).__name__}")
    if not math.isfinite(schedule.duration) or schedule.duration < 0.0:
        return _unusable(
            schedule, period, f"schedule duration is {schedule.duration!r} s: expected finite, >= 0"
        )
    samples = schedule.duration / period
    if samples > MAX_SAMPLES:
        raise InputError(
            f"verifying a {schedule.duration:.6g} s schedule every {period:g} s takes {samples:.3g} samples: "
            f"expected at most {MAX_SAMPLES:,} (use a coarser period)"
        )
    key = (id(schedule), period)
    report = _remembered(key, schedule)
    if report is not None:
        return report
    with _reports_lock:
        working = _in_progress.setdefault(key, threading.Lock())
    with working:  # one thread verifies a schedule; the others wait for its report
        report = _remembered(key, schedule)
        if report is not None:
            return report
        began = time.perf_counter()
        try:
            report = _verify(schedule, period)
        finally:
            with _reports_lock:
                _in_progress.pop(key, None)
        logger.debug(
            "verified a %s schedule (%d samples) in %.1f ms: %s",
            schedule.method,
            report.samples,
            1e3 * (time.perf_counter() - began),
            "passed" if report.passed else "FAILED",
        )
        with _reports_lock:
            _reports[key] = (weakref.ref(schedule), report)
            while len(_reports) > _REMEMBERED:
                _reports.popitem(last=False)
    return report


def _check_separation(state: ScheduleState, required: float, failures: list[str]) -> float:
    """Smallest track distance between the vehicles, metres; records a violation of ``required``."""
    separation = track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])
    worst = int(np.argmin(separation))
    if separation[worst] < required - POSITION_TOLERANCE:
        failures.append(
            f"separation {separation[worst]:.9g} m at t={state.t[worst]:.4f} s "
            f"is below the minimum {required:g} m"
        )
    if separation[worst] <= 0.0:
        failures.append(f"vehicles collide at t={state.t[worst]:.4f} s")
    return float(separation[worst])


def _check_on_track(state: ScheduleState, graph, failures: list[str]) -> None:
    """Every sampled position within its leg (to :data:`TRACK_END_TOLERANCE`)."""
    lengths = np.array(graph.lengths)
    on_leg = state.leg != JUNCTION_INDEX
    overrun = np.where(on_leg, state.s - lengths[np.where(on_leg, state.leg, 0)], 0.0)
    worst_overrun = float(overrun.max())
    if worst_overrun > TRACK_END_TOLERANCE:
        vehicle, k = np.unravel_index(int(np.argmax(overrun)), overrun.shape)
        failures.append(
            f"vehicle {vehicle + 1} is {worst_overrun:.3g} m past the end of leg "
            f"{graph.names[state.leg[vehicle, k]]!r} at t={state.t[k]:.4f} s "
            f"(tolerance {TRACK_END_TOLERANCE:g} m)"
        )


def _check_limits(
    state: ScheduleState, schedule: Schedule, failures: list[str]
) -> dict[str, tuple[float, float]]:
    """Largest ``|value| / limit`` per vehicle of velocity, acceleration and (if limited) jerk."""
    checks = [
        ("velocity", state.velocity, "max_velocity", "m/s"),
        ("acceleration", state.acceleration, "max_acceleration", "m/s^2"),
    ]
    if schedule.jerk_limited:
        checks.append(("jerk", state.jerk, "max_jerk", "m/s^3"))
    ratios: dict[str, tuple[float, float] | None] = {"jerk": None}
    for name, values, limit_name, unit in checks:
        per_vehicle = []
        for vehicle in range(2):
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(np.abs(values[vehicle])))
            ratio = float(abs(values[vehicle, k]) / limit)
            per_vehicle.append(ratio)
            if ratio > 1.0 + RELATIVE_TOLERANCE:
                failures.append(
                    f"vehicle {vehicle + 1} {name} {values[vehicle, k]:.9g} {unit} at t={state.t[k]:.4f} s "
                    f"exceeds its {limit_name} {limit:g} {unit}"
                )
        ratios[name] = (per_vehicle[0], per_vehicle[1])
    return ratios


def _check_ends(state: ScheduleState, schedule: Schedule, failures: list[str]) -> tuple[float, float]:
    """Distance of the first and last sample from the route's start and goal, metres; both at rest."""
    route, graph = schedule.route, schedule.route.graph
    errors = []
    for label, index, expected in (("start", 0, route.start), ("goal", -1, route.goal)):
        error = 0.0
        for vehicle, position in enumerate(expected):
            leg = JUNCTION_INDEX if position.leg is None else graph.index(position.leg)
            error += float(
                track_distance(state.leg[vehicle, index], state.s[vehicle, index], leg, position.s)
            )
            # at rest: v = 0; a jerk-limited method also starts and ends with a = 0
            residue = abs(state.velocity[vehicle, index])
            if schedule.jerk_limited:
                residue += abs(state.acceleration[vehicle, index])
            if residue > REST_TOLERANCE:
                failures.append(
                    f"vehicle {vehicle + 1} is not at rest at the {label} (|v| + |a| = {residue:.3g})"
                )
        if error > POSITION_TOLERANCE:
            failures.append(f"{label} is off the route's {label} by {error:.3g} m (expected <= 1e-9 m)")
        errors.append(error)
    return errors[0], errors[1]


def _check_consistency(state: ScheduleState, schedule: Schedule, failures: list[str]) -> None:
    """Positions move no faster than the vehicles' velocity limits allow (track and kinematics agree)."""
    dt = np.diff(state.t)
    for vehicle in range(2):
        moved = track_distance(
            state.leg[vehicle, :-1], state.s[vehicle, :-1], state.leg[vehicle, 1:], state.s[vehicle, 1:]
        )
        limit = schedule.limits.vehicles[vehicle].max_velocity
        jumps = np.nonzero(moved > limit * dt * (1.0 + RELATIVE_TOLERANCE) + POSITION_TOLERANCE)[0]
        if jumps.size:
            k = int(jumps[0])
            failures.append(
                f"vehicle {vehicle + 1} jumps {moved[k]:.6g} m in {dt[k]:.3g} s at t={state.t[k]:.4f} s "
                f"(faster than its max_velocity)"
            )


def _check_class(state: ScheduleState, route, failures: list[str]) -> bool:
    """Whether the sampled region sequence (homotopy class) is the route's."""
    expected = route.region_keys
    sampled = reduce_regions(region_keys(state.leg[0], state.s[0], state.leg[1], state.s[1]))
    if sampled == expected:
        return True

    def show(keys):
        return " ".join(str(Region.from_key(route.graph, key)) for key in keys)

    failures.append(f"homotopy class differs: schedule visits [{show(sampled)}], route [{show(expected)}]")
    return False


def _unusable(schedule: Schedule, period: float, failure: str) -> VerificationReport:
    """A failed report for a schedule that cannot even be sampled."""
    logger.warning("schedule (%s) failed verification: %s", schedule.method, failure)
    nan = float("nan")
    return VerificationReport(
        passed=False,
        failures=(failure,),
        samples=0,
        pieces=0,
        period=period,
        min_separation=nan,
        separation_margin=nan,
        velocity_ratio=(nan, nan),
        acceleration_ratio=(nan, nan),
        jerk_ratio=None,
        start_error=nan,
        goal_error=nan,
        regions_match=False,
    )


def _check_finite(state: ScheduleState, failures: list[str]) -> None:
    """Every sampled time, position and derivative is a finite number."""
    for name in ("t", "axis", "velocity", "acceleration", "jerk", "s"):
        values = getattr(state, name)
        bad = ~np.isfinite(values)
        if bad.any():
            where = np.argwhere(bad)[0]
            k = int(where[-1])
            failures.append(
                f"{name} is not finite ({values[tuple(where)]!r}) at t={state.t[k]!r} s "
                f"({int(bad.sum())} samples in all): expected finite numbers"
            )


@dataclass(frozen=True, slots=True)
class _PieceFigures:
    """What the closed-form check of the pieces found."""

    count: int
    closest: float
    ratios: dict
    regions_match: bool


def _piece_extrema(c: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    return polynomials.extrema(c, h)


def _check_piece_limits(pieces: Pieces, schedule: Schedule, failures: list[str]) -> dict:
    """Largest ``|v|``, ``|a|`` (and ``|j|``) / limit per vehicle over every piece, in closed form."""
    names = [("velocity", "max_velocity", "m/s"), ("acceleration", "max_acceleration", "m/s^2")]
    if schedule.jerk_limited:
        names.append(("jerk", "max_jerk", "m/s^3"))
    ratios: dict[str, tuple[float, float] | None] = {"jerk": None}
    for vehicle in range(2):
        c = pieces.axis[vehicle]
        for order, (name, limit_name, unit) in enumerate(names, start=1):
            for _ in range(order):
                c = polynomials.derivative(c)
            low, t_low, high, t_high = _piece_extrema(c, pieces.length)
            peak = np.maximum(np.abs(low), np.abs(high))
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(peak)) if peak.size else 0
            ratio = float(peak[k] / limit) if peak.size else 0.0
            previous = ratios.get(name) or (0.0, 0.0)
            ratios[name] = (ratio, previous[1]) if vehicle == 0 else (previous[0], ratio)
            if ratio > 1.0 + RELATIVE_TOLERANCE:
                when = pieces.start[k] + (t_high[k] if abs(high[k]) >= abs(low[k]) else t_low[k])
                failures.append(
                    f"vehicle {vehicle + 1} {name} reaches {peak[k]:.9g} {unit} at t={when:.6f} s "
                    f"(closed form, between samples too): exceeds its {limit_name} {limit:g} {unit}"
                )
            c = pieces.axis[vehicle]
    return ratios


def _check_piece_track(pieces: Pieces, graph, failures: list[str]) -> np.ndarray:
    """Each vehicle stays within its leg and its map's range; returns s polynomials, shape (2, n, d + 1)."""
    track = pieces.track()
    lengths = np.array(graph.lengths)
    for vehicle in range(2):
        low, t_low, high, t_high = _piece_extrema(track[vehicle], pieces.length)
        on_leg = pieces.leg[vehicle] != JUNCTION_INDEX
        length = np.where(on_leg, lengths[np.where(on_leg, pieces.leg[vehicle], 0)], 0.0)
        over = np.nonzero(on_leg & (high > length + TRACK_END_TOLERANCE))[0]
        if over.size:
            k = int(over[0])
            failures.append(
                f"vehicle {vehicle + 1} is {high[k] - length[k]:.3g} m past the end of leg "
                f"{graph.names[pieces.leg[vehicle, k]]!r} at t={pieces.start[k] + t_high[k]:.6f} s "
                "(closed form)"
            )
        under = np.nonzero(low < -TRACK_END_TOLERANCE)[0]
        if under.size:
            k = int(under[0])
            failures.append(
                f"vehicle {vehicle + 1} passes the junction inside a piece (s = {low[k]:.3g} m) "
                f"at t={pieces.start[k] + t_low[k]:.6f} s: its position map does not cover it"
            )
        axis_low, _, axis_high, _ = _piece_extrema(pieces.axis[vehicle], pieces.length)
        outside = np.nonzero(
            (axis_low < pieces.axis_low[vehicle] - TRACK_END_TOLERANCE)
            | (axis_high > pieces.axis_high[vehicle] + TRACK_END_TOLERANCE)
        )[0]
        if outside.size:
            k = int(outside[0])
            failures.append(
                f"vehicle {vehicle + 1} leaves the range of its position map at t={pieces.start[k]:.6f} s "
                f"(axis {axis_low[k]:.6g} to {axis_high[k]:.6g} m, map {pieces.axis_low[vehicle, k]:.6g} to "
                f"{pieces.axis_high[vehicle, k]:.6g} m)"
            )
    return track


def _check_piece_separation(
    pieces: Pieces, track: np.ndarray, required: float, failures: list[str]
) -> tuple[float, list]:
    """Smallest track distance over every piece (closed form) and each piece's region."""
    same = (pieces.leg[0] == pieces.leg[1]) & (pieces.leg[0] != JUNCTION_INDEX)
    gap = np.where(same[:, None], track[0] - track[1], track[0] + track[1])
    low, t_low, high, t_high = _piece_extrema(gap, pieces.length)
    crossing = same & (low < 0.0) & (high > 0.0)
    closest = np.where(same, np.where(high <= 0.0, -high, low), low)
    closest = np.where(crossing, 0.0, closest)
    when = np.where(same & (high <= 0.0), t_high, t_low)
    regions: list = []
    middle = polynomials.evaluate(gap, 0.5 * pieces.length)
    for k in range(pieces.count):
        first, second = int(pieces.leg[0, k]), int(pieces.leg[1, k])
        if first == JUNCTION_INDEX or second == JUNCTION_INDEX:
            regions.append(None)
        else:
            regions.append(RegionKey(first, second, 0 if first != second else (1 if middle[k] < 0.0 else 2)))
    if not pieces.count:
        return float("inf"), regions
    k = int(np.argmin(closest))
    if crossing[k]:
        failures.append(
            f"vehicles pass each other on one leg between t={pieces.start[k]:.6f} s and the next piece"
        )
    elif closest[k] < required - POSITION_TOLERANCE:
        failures.append(
            f"separation {closest[k]:.9g} m at t={pieces.start[k] + when[k]:.6f} s is below the minimum "
            f"{required:g} m (closed form, between samples too)"
        )
    return float(closest[k]), regions


def _check_piece_continuity(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, failures: list[str]
) -> None:
    """Position, velocity (and for jerk-limited schedules acceleration) continuous from piece to piece."""
    if pieces.count < 2:
        return
    h = pieces.length[:-1]
    for vehicle in range(2):
        end_s = polynomials.evaluate(track[vehicle, :-1], h)
        start_s = track[vehicle, 1:, 0]
        jump = track_distance(pieces.leg[vehicle, :-1], end_s, pieces.leg[vehicle, 1:], start_s)
        limits = schedule.limits.vehicles[vehicle]
        checks = [("position", jump, TRACK_END_TOLERANCE, "m")]
        velocity = polynomials.derivative(pieces.axis[vehicle])
        dv = np.abs(polynomials.evaluate(velocity[:-1], h) - velocity[1:, 0])
        checks.append(("velocity", dv, RELATIVE_TOLERANCE * limits.max_velocity, "m/s"))
        if schedule.jerk_limited:
            acceleration = polynomials.derivative(velocity)
            da = np.abs(polynomials.evaluate(acceleration[:-1], h) - acceleration[1:, 0])
            checks.append(("acceleration", da, RELATIVE_TOLERANCE * limits.max_acceleration, "m/s^2"))
        for name, values, tolerance, unit in checks:
            jumps = np.nonzero(~(values <= tolerance))[0]
            if jumps.size:
                k = int(jumps[0])
                failures.append(
                    f"vehicle {vehicle + 1} {name} jumps by {values[k]:.3g} {unit} "
                    f"at t={pieces.start[k + 1]:.6f} s "
                    f"(tolerance {tolerance:.3g} {unit})"
                )


def _check_pieces(schedule: Schedule, required: float, failures: list[str]) -> _PieceFigures | None:
    """The closed-form checks: limits, track, separation, continuity and class over every piece."""
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # non-finite values are reported by the samples
            pieces = schedule_pieces(schedule)
    except UncheckableKinematicsError as error:
        failures.append(f"cannot be checked between samples: {error}")
        return None
    if not np.all(np.isfinite(pieces.axis)) or not np.all(np.isfinite(pieces.length)):
        return None  # reported by the finiteness check of the samples
    ratios = _check_piece_limits(pieces, schedule, failures)
    track = _check_piece_track(pieces, schedule.route.graph, failures)
    closest, regions = _check_piece_separation(pieces, track, required, failures)
    _check_piece_continuity(pieces, track, schedule, failures)
    expected = schedule.route.region_keys
    sequence = reduce_regions(regions)
    if sequence != expected:
        failures.append(
            "homotopy class differs (closed form): schedule visits ["
            + " ".join(str(Region.from_key(schedule.route.graph, key)) for key in sequence)
            + "], route ["
            + " ".join(str(Region.from_key(schedule.route.graph, key)) for key in expected)
            + "]"
        )
    return _PieceFigures(pieces.count, closest, ratios, sequence == expected)


def _worse(sampled, certified):
    if sampled is None or certified is None:
        return sampled if certified is None else certified
    return (max(sampled[0], certified[0]), max(sampled[1], certified[1]))


def _verify(schedule: Schedule, period: float) -> VerificationReport:
    route = schedule.route
    required = max(schedule.limits.min_separation, route.min_separation)
    with np.errstate(invalid="ignore", over="ignore"):  # non-finite values are reported below
        state = schedule.state(_sample_times(schedule, period))
    failures: list[str] = []
    _check_finite(state, failures)
    closest = _check_separation(state, required, failures)
    _check_on_track(state, route.graph, failures)
    ratios = _check_limits(state, schedule, failures)
    start_error, goal_error = _check_ends(state, schedule, failures)
    _check_consistency(state, schedule, failures)
    regions_match = _check_class(state, route, failures)
    figures = _check_pieces(schedule, required, failures)
    if figures is not None:
        closest = min(closest, figures.closest)
        ratios = {name: _worse(ratios.get(name), figures.ratios.get(name)) for name in ratios}
        regions_match = regions_match and figures.regions_match
    if failures:
        logger.warning("schedule (%s) failed verification: %s", schedule.method, "; ".join(failures))
    return VerificationReport(
        passed=not failures,
        failures=tuple(failures),
        samples=int(state.t.size),
        pieces=0 if figures is None else figures.count,
        period=period,
        min_separation=closest,
        separation_margin=closest - required,
        velocity_ratio=ratios["velocity"],
        acceleration_ratio=ratios["acceleration"],
        jerk_ratio=ratios["jerk"],
        start_error=start_error,
        goal_error=goal_error,
        regions_match=regions_match,
    )


def certify(schedule: Schedule, *, period: float = MAX_PERIOD) -> VerifiedSchedule:
    """Verify ``schedule`` and return it certified, or raise.

    Raises
    ------
    VerificationError
        The schedule failed; the message lists every failure.
    """
    report = verify(schedule, period=period)
    report.raise_if_failed()
    return VerifiedSchedule(schedule, report)


def require_verified(value: object, what: str) -> VerifiedSchedule:
    """Return ``value`` if it is a :class:`VerifiedSchedule`, else raise naming ``what`` needs one.

    Raises
    ------
    UnverifiedScheduleError
        ``value`` is not a VerifiedSchedule (e.g. a bare Schedule).
    """
    if not isinstance(value, VerifiedSchedule):
        raise UnverifiedScheduleError(
            f"{what} takes a VerifiedSchedule (from trajgen.certify), got {type(value).__name__}"
        )
    return value
