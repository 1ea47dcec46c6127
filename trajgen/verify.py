"""Independent verifier: nothing leaves the library unless it passes.

The verifier takes a schedule apart into polynomial pieces
(:mod:`trajgen.pieces`: on each piece both vehicles' signed axes are single
polynomials and each vehicle is on one leg) and checks every piece in closed
form (:mod:`trajgen.polynomials`: extrema at the ends and at the roots of the
derivative), so nothing can hide between samples, and its cost grows with the
number of pieces, not with the duration. It checks:

- the track distance between the vehicles never drops below the minimum
  separation (and they never pass each other on a leg);
- ``|v|``, ``|a|`` (and ``|j|`` where the method limits it) stay within each
  vehicle's limits, to a relative tolerance of 1e-6;
- every position is on its leg (at most 1e-6 m past its end) and within the
  range its section's position map covers;
- position, the axis, velocity (and, where jerk is limited, acceleration)
  are continuous from piece to piece (as many derivatives as the schedule's
  ``smoothness`` says) to round-off (:data:`CONTINUITY_TOLERANCE`), and the
  pieces tile ``[0, duration]``;
- the start and the goal are the route's, to 1e-9 m, at rest (1e-6 m/s);
- the sequence of regions visited (the homotopy class) is the route's;
- the braking rule (:mod:`trajgen.braking_rule`): each vehicle that follows at a
  conflict can always stop short of its frontier, so what is planned is what
  the online executor plays;
- every number is finite, every knot sequence increases, and every array
  derived from others agrees with them (:mod:`trajgen.integrity`).

A failure names the arrays where it occurs, by their paths from the schedule
(``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4``).

Each schedule object is verified once: the report is kept (for the last
:data:`_REMEMBERED` schedules) and returned again, also to concurrent callers.
:func:`certify` turns a passing schedule into a :class:`VerifiedSchedule`, the
only kind of schedule that exporters and plots accept.
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
from topology.indexed import JUNCTION_INDEX, track_distance
from trajgen import polynomials
from trajgen.braking_rule import BRAKING_RULE_TOLERANCE, braking_rule_failures
from trajgen.errors import InputError, UnverifiedScheduleError, VerificationError
from trajgen.integrity import array_failures
from trajgen.pieces import Pieces, UncheckableKinematicsError, motion_arrays, schedule_pieces
from trajgen.schedule import Schedule

__all__ = [
    "CONTINUITY_TOLERANCE",
    "POSITION_TOLERANCE",
    "RELATIVE_TOLERANCE",
    "REST_TOLERANCE",
    "TRACK_END_TOLERANCE",
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
#: How far past the end of its leg a position may be (solver round-off), metres; also the largest jump.
TRACK_END_TOLERANCE = 1e-6
#: Continuity from piece to piece, relative to the quantity's scale (round-off: every method integrates its
#: knots from the ones before, so a jump above this is a number that disagrees with the others).
CONTINUITY_TOLERANCE = 1e-12
#: Reports kept for schedules already verified (by identity).
_REMEMBERED = 64
_reports: collections.OrderedDict[int, tuple[weakref.ref, VerificationReport]] = collections.OrderedDict()
_reports_lock = threading.Lock()
#: One lock per schedule being verified, so that concurrent callers wait for one verification.
_in_progress: dict[int, threading.Lock] = {}


@dataclass(frozen=True, slots=True)
class VerificationReport:
    """Outcome of :func:`verify`.

    Attributes
    ----------
    passed : bool
        Whether every check passed.
    failures : tuple of str
        One message per failed check, naming the quantity, value and limit.
    pieces : int
        Number of polynomial pieces checked.
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
    pieces: int
    min_separation: float
    separation_margin: float
    velocity_ratio: tuple[float, float]
    acceleration_ratio: tuple[float, float]
    jerk_ratio: tuple[float, float] | None
    start_error: float
    goal_error: float
    regions_match: bool

    @classmethod
    def failed(cls, failures: tuple[str, ...], *, pieces: int = 0) -> VerificationReport:
        """The report of a motion that could not be checked further (its figures are NaN)."""
        nan = float("nan")
        return cls(
            passed=False,
            failures=tuple(failures),
            pieces=pieces,
            min_separation=nan,
            separation_margin=nan,
            velocity_ratio=(nan, nan),
            acceleration_ratio=(nan, nan),
            jerk_ratio=None,
            start_error=nan,
            goal_error=nan,
            regions_match=False,
        )

    def raise_if_failed(self) -> None:
        """Raise VerificationError listing the failures, if any."""
        if not self.passed:
            raise VerificationError("schedule failed verification: " + "; ".join(self.failures))

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
        if verify(self.schedule) != self.report:
            raise UnverifiedScheduleError("the report given is not this schedule's verification report")


def _remembered(schedule: Schedule) -> VerificationReport | None:
    with _reports_lock:
        remembered = _reports.get(id(schedule))
        if remembered is not None and remembered[0]() is schedule:
            _reports.move_to_end(id(schedule))
            return remembered[1]
    return None


def verify(schedule: Schedule) -> VerificationReport:
    """Check a schedule independently of how it was computed, between any two instants too.

    Parameters
    ----------
    schedule : Schedule

    Returns
    -------
    VerificationReport
        The same report object for the same schedule, computed once.

    Raises
    ------
    InputError
        ``schedule`` is not a Schedule.
    """
    if not isinstance(schedule, Schedule):
        raise InputError(f"verify expects a Schedule, got {type(schedule).__name__}")
    report = _remembered(schedule)
    if report is not None:
        return report
    key = id(schedule)
    with _reports_lock:
        working = _in_progress.setdefault(key, threading.Lock())
    with working:  # one thread verifies a schedule; the others wait for its report
        report = _remembered(schedule)
        if report is not None:
            return report
        began = time.perf_counter()
        try:
            report = _verify(schedule)
        finally:
            with _reports_lock:
                _in_progress.pop(key, None)
        logger.debug(
            "verified a %s schedule (%d pieces) in %.1f ms: %s",
            schedule.method,
            report.pieces,
            1e3 * (time.perf_counter() - began),
            "passed" if report.passed else "FAILED",
        )
        with _reports_lock:
            _reports[key] = (weakref.ref(schedule), report)
            while len(_reports) > _REMEMBERED:
                _reports.popitem(last=False)
    return report


def _failed(schedule: Schedule, failures: list[str], pieces: int = 0) -> VerificationReport:
    """A failed report for a schedule that cannot even be taken apart."""
    logger.info("schedule (%s) failed verification: %s", schedule.method, "; ".join(failures))
    return VerificationReport.failed(tuple(failures), pieces=pieces)


def _where(schedule: Schedule, pieces: Pieces, k: int, vehicles: tuple[int, ...] = (0, 1)) -> str:
    """The arrays that define piece ``k`` of the given vehicles, by their paths (for failure messages)."""
    if not pieces.count:
        return "sections[0]"
    section = int(pieces.section[k])
    return "; ".join(
        motion_arrays(schedule, section, vehicle, int(pieces.interval[vehicle, k])) for vehicle in vehicles
    )


def _check_ends(schedule: Schedule, pieces: Pieces, state, failures: list[str]) -> tuple[float, float, float]:
    """Start and goal errors (metres), at rest; and the separation at the start, metres.

    ``state`` is the schedule's state at 0 and at its end (what is exported there).
    """
    route, graph = schedule.route, schedule.route.graph
    errors = []
    for label, index, expected in (("start", 0, route.start), ("goal", -1, route.goal)):
        error = 0.0
        piece = 0 if index == 0 else pieces.count - 1
        for vehicle, position in enumerate(expected):
            leg = JUNCTION_INDEX if position.leg is None else graph.index(position.leg)
            error += float(
                track_distance(state.leg[vehicle, index], state.s[vehicle, index], leg, position.s)
            )
            # at rest: v = 0; a jerk-limited method also starts and ends with a = 0 (a linearly
            # interpolated table has no velocity at its ends: the drive's own ramps are checked there)
            residue = abs(state.velocity[vehicle, index]) if schedule.smoothness >= 1 else 0.0
            if schedule.smoothness >= 2 and schedule.jerk_limited:
                residue += abs(state.acceleration[vehicle, index])
            if not residue <= REST_TOLERANCE:
                failures.append(
                    f"vehicle {vehicle + 1} is not at rest at the {label} (|v| + |a| = {residue:.3g}): "
                    f"{_where(schedule, pieces, piece, (vehicle,))}"
                )
        tolerance = POSITION_TOLERANCE if schedule.end_tolerance is None else schedule.end_tolerance
        if not error <= tolerance:
            failures.append(
                f"{label} is off the route's {label} by {error:.3g} m (expected <= {tolerance:g} m): "
                f"{_where(schedule, pieces, piece)}"
            )
        errors.append(error)
    start_gap = float(track_distance(state.leg[0, 0], state.s[0, 0], state.leg[1, 0], state.s[1, 0]))
    return errors[0], errors[1], start_gap


def _check_exported_ends(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, state, failures: list[str]
) -> None:
    """What the schedule reports at 0 and at the end (what is exported) is where its pieces start and end."""
    if not pieces.count:
        return
    for vehicle in range(2):
        ends = (
            ("start", 0, int(pieces.leg[vehicle, 0]), float(track[vehicle, 0, 0])),
            (
                "goal",
                -1,
                int(pieces.leg[vehicle, -1]),
                float(polynomials.evaluate(track[vehicle, -1:], pieces.length[-1:])[0]),
            ),
        )
        for label, index, leg, s in ends:
            gap = float(track_distance(state.leg[vehicle, index], state.s[vehicle, index], leg, s))
            if not gap <= _allowance(schedule, vehicle, "position"):
                failures.append(
                    f"vehicle {vehicle + 1} is {gap:.3g} m from where its motion puts it at the {label}: "
                    "the schedule reports a position its motion does not reach: "
                    f"{_where(schedule, pieces, 0 if index == 0 else pieces.count - 1, (vehicle,))}"
                )


def _check_tiling(schedule: Schedule, pieces: Pieces, failures: list[str]) -> None:
    """The pieces follow one another without gaps from 0 to the duration."""
    if not pieces.count:
        return
    duration = schedule.duration
    ends = pieces.start + pieces.length
    gaps = np.abs(np.concatenate([[pieces.start[0]], pieces.start[1:] - ends[:-1], [duration - ends[-1]]]))
    k = int(np.argmax(gaps))
    if not gaps[k] <= 1e-9 * max(1.0, duration):
        section = int(pieces.section[min(k, pieces.count - 1)])
        failures.append(
            f"the motion has a gap of {gaps[k]:.3g} s in time (piece {k}): expected none: "
            f"sections[{section}].start_time; {_where(schedule, pieces, min(k, pieces.count - 1))}"
        )


def _for_execution(schedule: Schedule) -> bool:
    """Whether the schedule's method plans for execution (its plans then obey the braking rule)."""
    method = schedule.method
    return method is None or bool(getattr(method, "plans_for_execution", True))


def _verify(schedule: Schedule) -> VerificationReport:
    own = array_failures(schedule)
    if own:  # the motion is read from these numbers: broken ones make every other check meaningless
        return _failed(schedule, own)
    duration = schedule.duration
    if not math.isfinite(duration) or duration < 0.0:
        return _failed(schedule, [f"schedule duration is {duration!r} s: expected finite, >= 0"])
    route = schedule.route
    required = max(schedule.limits.min_separation, route.min_separation)
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # non-finite numbers are reported below
            pieces = schedule_pieces(schedule)
    except UncheckableKinematicsError as error:
        return _failed(schedule, [f"cannot be checked: {error}"])
    if not (np.all(np.isfinite(pieces.axis)) and np.all(np.isfinite(pieces.start))):
        bad = int(np.argmax(~np.all(np.isfinite(pieces.axis), axis=(0, 2)) | ~np.isfinite(pieces.start)))
        return _failed(
            schedule,
            [
                f"the motion is not finite in piece {bad} (from t={pieces.start[bad]!r} s): expected finite: "
                f"{_where(schedule, pieces, bad)}"
            ],
            pieces.count,
        )
    failures: list[str] = []
    _check_maps(schedule, failures)
    if failures:  # the pieces are read through the maps: a broken map makes them meaningless
        return _failed(schedule, failures, pieces.count)
    ends = schedule.state([0.0, duration])
    track = pieces.track()
    start_error, goal_error, start_gap = _check_ends(schedule, pieces, ends, failures)
    _check_exported_ends(pieces, track, schedule, ends, failures)
    _check_tiling(schedule, pieces, failures)
    _check_parked(pieces, schedule, failures)
    ratios = _check_piece_limits(pieces, schedule, failures)
    past_end = max(TRACK_END_TOLERANCE, schedule.end_tolerance or 0.0)
    _check_piece_track(pieces, track, schedule, failures, past_end)
    closest, regions = _check_piece_separation(pieces, track, schedule, required, failures)
    closest = min(closest, start_gap)
    if not pieces.count and start_gap < required - POSITION_TOLERANCE:
        failures.append(f"separation {start_gap:.9g} m at rest is below the minimum {required:g} m")
    _check_piece_continuity(pieces, track, schedule, failures)
    if not failures and schedule.end_tolerance is None and _for_execution(schedule):
        # a plan for execution: each follower can always stop short of its frontier (a table read
        # back follows a plan that was checked; its own round-off is not an execution)
        for failure in braking_rule_failures(schedule, pieces=pieces):
            k = int(
                np.clip(np.searchsorted(pieces.start, failure.time, side="right") - 1, 0, pieces.count - 1)
            )
            what = (
                f"its service stop point passes it by {failure.excess:.3g} m"
                if math.isfinite(failure.excess)
                else "its margin stays too thin to certify"
            )
            failures.append(
                f"vehicle {failure.vehicle + 1} cannot stop short of its frontier at t={failure.time:.6f} s: "
                f"{what} (the braking rule; expected at most {BRAKING_RULE_TOLERANCE:g} m past it): "
                f"{_where(schedule, pieces, k)}"
            )
    expected = route.region_keys
    sequence = reduce_regions(regions)
    if sequence != expected:
        show = lambda keys: " ".join(str(Region.from_key(route.graph, key)) for key in keys)  # noqa: E731
        failures.append(
            f"homotopy class differs: schedule visits [{show(sequence)}], route [{show(expected)}]: "
            f"{_where(schedule, pieces, _first_departure(regions, expected))}"
        )
    if failures:
        logger.info("schedule (%s) failed verification: %s", schedule.method, "; ".join(failures))
    return VerificationReport(
        passed=not failures,
        failures=tuple(failures),
        pieces=pieces.count,
        min_separation=closest,
        separation_margin=closest - required,
        velocity_ratio=ratios["velocity"],
        acceleration_ratio=ratios["acceleration"],
        jerk_ratio=ratios["jerk"],
        start_error=start_error,
        goal_error=goal_error,
        regions_match=sequence == expected,
    )


def _first_departure(regions: list, expected: tuple) -> int:
    """The first piece at which the region sequence leaves the route's (the last piece if none does)."""
    position = 0
    for k, region in enumerate(regions):
        if region is None:
            continue
        if position < len(expected) and region == expected[position]:
            continue
        if position + 1 < len(expected) and region == expected[position + 1]:
            position += 1
            continue
        return k
    return max(len(regions) - 1, 0)


def _time_resolution(schedule: Schedule) -> float:
    """The time round-off of the schedule, seconds: breakpoints are floats of its duration's size."""
    return 8.0 * float(np.spacing(max(schedule.duration, 1.0)))


def _allowance(schedule: Schedule, vehicle: int, name: str) -> float:
    """What a quantity may exceed its limit or jump by, in its units.

    1e-6 of the limit, plus what the next derivative's limit allows within the
    time round-off (a jerk of 1e6 m/s^3 moves the acceleration 1e-8 m/s^2 in 1e-14 s).
    """
    limits = schedule.limits.vehicles[vehicle]
    eps = _time_resolution(schedule)
    if name == "position":
        return TRACK_END_TOLERANCE + limits.max_velocity * eps
    if name == "velocity":
        return RELATIVE_TOLERANCE * limits.max_velocity + limits.max_acceleration * eps
    if name == "acceleration":
        return RELATIVE_TOLERANCE * limits.max_acceleration + limits.max_jerk * eps
    return RELATIVE_TOLERANCE * limits.max_jerk


def _continuity_allowance(schedule: Schedule, vehicle: int, name: str, length_scale: float) -> float:
    """What a quantity may jump by from piece to piece, in its units: round-off of its scale.

    ``length_scale``: metres, the largest position of the schedule (at least 1 m). A table
    read back (``end_tolerance`` set) is held to its interpolation's allowances instead.
    """
    if schedule.end_tolerance is not None:
        return _allowance(schedule, vehicle, name)
    limits = schedule.limits.vehicles[vehicle]
    eps = _time_resolution(schedule)
    if name == "position":
        return CONTINUITY_TOLERANCE * length_scale + limits.max_velocity * eps
    if name == "velocity":
        return CONTINUITY_TOLERANCE * limits.max_velocity + limits.max_acceleration * eps
    return CONTINUITY_TOLERANCE * limits.max_acceleration + limits.max_jerk * eps


def _check_piece_limits(pieces: Pieces, schedule: Schedule, failures: list[str]) -> dict:
    """Largest ``|v|``, ``|a|`` (and ``|j|``) / limit per vehicle over every piece, in closed form."""
    names = [("velocity", "max_velocity", "m/s"), ("acceleration", "max_acceleration", "m/s^2")]
    if schedule.jerk_limited:
        names.append(("jerk", "max_jerk", "m/s^3"))
    if schedule.checked_limits is not None:  # a table read back: the rest is checked from its points
        names = names[: schedule.checked_limits]
    ratios: dict[str, tuple[float, float] | None] = {
        "velocity": (0.0, 0.0),
        "acceleration": (0.0, 0.0),
        "jerk": None,
    }
    for vehicle in range(2):
        c = pieces.axis[vehicle]
        for order, (name, limit_name, unit) in enumerate(names, start=1):
            for _ in range(order):
                c = polynomials.derivative(c)
            low, t_low, high, t_high = polynomials.extrema(c, pieces.length)
            peak = np.maximum(np.abs(low), np.abs(high))
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(peak)) if peak.size else 0
            ratio = float(peak[k] / limit) if peak.size else 0.0
            previous = ratios.get(name) or (0.0, 0.0)
            ratios[name] = (ratio, previous[1]) if vehicle == 0 else (previous[0], ratio)
            if peak.size and not peak[k] <= limit + _allowance(schedule, vehicle, name):
                when = pieces.start[k] + (t_high[k] if abs(high[k]) >= abs(low[k]) else t_low[k])
                failures.append(
                    f"vehicle {vehicle + 1} {name} reaches {peak[k]:.9g} {unit} at t={when:.6f} s "
                    f"exceeds its {limit_name} {limit:g} {unit}: {_where(schedule, pieces, k, (vehicle,))}"
                )
            c = pieces.axis[vehicle]
    return ratios


def _check_piece_track(
    pieces: Pieces,
    track: np.ndarray,
    schedule: Schedule,
    failures: list[str],
    past_end: float = TRACK_END_TOLERANCE,
) -> None:
    """Each vehicle stays on its leg and in its map's range; ``track``: s polynomials, shape (2, n, 5)."""
    graph = schedule.route.graph
    lengths = np.array(graph.lengths)
    for vehicle in range(2):
        low, t_low, high, t_high = polynomials.extrema(track[vehicle], pieces.length)
        on_leg = pieces.leg[vehicle] != JUNCTION_INDEX
        length = np.where(on_leg, lengths[np.where(on_leg, pieces.leg[vehicle], 0)], 0.0)
        over = np.nonzero(on_leg & (high > length + past_end))[0]
        if over.size:
            k = int(over[0])
            failures.append(
                f"vehicle {vehicle + 1} is {high[k] - length[k]:.3g} m past the end of leg "
                f"{graph.names[pieces.leg[vehicle, k]]!r} at t={pieces.start[k] + t_high[k]:.6f} s: "
                f"{_where(schedule, pieces, k, (vehicle,))}"
            )
        under = np.nonzero(low < -TRACK_END_TOLERANCE)[0]
        if under.size:
            k = int(under[0])
            failures.append(
                f"vehicle {vehicle + 1} passes the junction inside a piece (s = {low[k]:.3g} m) "
                f"at t={pieces.start[k] + t_low[k]:.6f} s: its position map does not cover it: "
                f"{_where(schedule, pieces, k, (vehicle,))}"
            )
        axis_low, _, axis_high, _ = polynomials.extrema(pieces.axis[vehicle], pieces.length)
        outside = np.nonzero(
            (axis_low < pieces.axis_low[vehicle] - TRACK_END_TOLERANCE)
            | (axis_high > pieces.axis_high[vehicle] + TRACK_END_TOLERANCE)
        )[0]
        if outside.size:
            k = int(outside[0])
            failures.append(
                f"vehicle {vehicle + 1} leaves the range of its position map at t={pieces.start[k]:.6f} s "
                f"(axis {axis_low[k]:.6g} to {axis_high[k]:.6g} m, map {pieces.axis_low[vehicle, k]:.6g} to "
                f"{pieces.axis_high[vehicle, k]:.6g} m): {_where(schedule, pieces, k, (vehicle,))}"
            )


def _check_piece_separation(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, required: float, failures: list[str]
) -> tuple[float, list]:
    """Smallest track distance over every piece and each piece's region."""
    same = (pieces.leg[0] == pieces.leg[1]) & (pieces.leg[0] != JUNCTION_INDEX)
    gap = np.where(same[:, None], track[0] - track[1], track[0] + track[1])
    low, t_low, high, t_high = polynomials.extrema(gap, pieces.length)
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
            f"vehicles pass each other on one leg between t={pieces.start[k]:.6f} s and the next piece: "
            f"{_where(schedule, pieces, k)}"
        )
    elif closest[k] < required - POSITION_TOLERANCE:
        failures.append(
            f"separation {closest[k]:.9g} m at t={pieces.start[k] + when[k]:.6f} s is below the minimum "
            f"{required:g} m: {_where(schedule, pieces, k)}"
        )
    return float(closest[k]), regions


def _check_piece_continuity(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, failures: list[str]
) -> None:
    """Position, velocity (and for jerk-limited schedules acceleration) continuous from piece to piece.

    Velocity and acceleration are compared along the track (``ds/dt``) where a
    vehicle stays on one leg, so a reversal hidden in a map change is a jump;
    through the junction (where ``s`` changes leg) along its own axis. The
    axis itself (each vehicle's odometer, exported beside ``s``) is continuous too.
    """
    if pieces.count < 2:
        return
    h = pieces.length[:-1]
    length_scale = max(1.0, float(np.max(np.abs(pieces.axis[:, :, 0]))), *schedule.route.graph.lengths)
    for vehicle in range(2):
        end_s = polynomials.evaluate(track[vehicle, :-1], h)
        start_s = track[vehicle, 1:, 0]
        jump = track_distance(pieces.leg[vehicle, :-1], end_s, pieces.leg[vehicle, 1:], start_s)
        same_leg = (pieces.leg[vehicle, :-1] == pieces.leg[vehicle, 1:]) & (
            pieces.leg[vehicle, 1:] != JUNCTION_INDEX
        )
        sign_before = np.where(same_leg, pieces.s_sign[vehicle, :-1], 1.0)
        sign_after = np.where(same_leg, pieces.s_sign[vehicle, 1:], 1.0)
        axis_end = polynomials.evaluate(pieces.axis[vehicle, :-1], h)
        checks = [("position", jump), ("axis", np.abs(axis_end - pieces.axis[vehicle, 1:, 0]))]
        derivative = pieces.axis[vehicle]
        names = ["velocity", "acceleration"][: schedule.smoothness]
        for name in names:
            derivative = polynomials.derivative(derivative)
            before = sign_before * polynomials.evaluate(derivative[:-1], h)
            after = sign_after * derivative[1:, 0]
            checks.append((name, np.abs(before - after)))
        for name, values in checks:
            quantity = "position" if name == "axis" else name
            tolerance = _continuity_allowance(schedule, vehicle, quantity, length_scale)
            unit = {"position": "m", "axis": "m", "velocity": "m/s", "acceleration": "m/s^2"}[name]
            jumps = np.nonzero(~(values <= tolerance))[0]
            if jumps.size:
                k = int(jumps[0])
                failures.append(
                    f"vehicle {vehicle + 1} {name} jumps by {values[k]:.3g} {unit} "
                    f"at t={pieces.start[k + 1]:.6f} s (tolerance {tolerance:.3g} {unit}): between "
                    f"{_where(schedule, pieces, k, (vehicle,))} and "
                    f"{_where(schedule, pieces, k + 1, (vehicle,))}"
                )


def _check_maps(schedule: Schedule, failures: list[str]) -> None:
    """Each section's position maps are well formed: known legs, unit slopes, contiguous sub-ranges."""
    legs = len(schedule.route.graph.lengths)
    for index, section in enumerate(schedule.sections):
        for vehicle, axis_map in enumerate(section.maps):
            where = f"sections[{index}].maps[{vehicle}]"
            if not np.all(np.isin(axis_map.outward, (-1, 0, 1))):
                failures.append(
                    f"{where}.outward: map slopes {axis_map.outward.tolist()} are not -1, 0 or +1"
                )
            if not np.all((axis_map.legs >= JUNCTION_INDEX) & (axis_map.legs < legs)):
                failures.append(
                    f"{where}.legs: map legs {axis_map.legs.tolist()} are not track legs: expected "
                    f"{JUNCTION_INDEX} (the junction) or a leg index 0 to {legs - 1} ({legs} legs)"
                )
                continue
            at_junction = axis_map.legs == JUNCTION_INDEX
            if np.any(at_junction & ((axis_map.outward != 0) | (axis_map.s_start != 0.0))):
                failures.append(
                    f"{where}.{{legs,outward,s_start}}: a map sub-range at the junction moves or lies off it"
                )
            if np.any(~at_junction & (axis_map.s_start < -TRACK_END_TOLERANCE)):
                failures.append(f"{where}.s_start: a map sub-range starts before the junction (s < 0)")
            if axis_map.legs.size > 1:
                s_end = axis_map.s_start + axis_map.outward * (axis_map.axis_end - axis_map.axis_start)
                scale = max(1.0, float(np.max(np.abs(axis_map.axis_end))))
                gaps = np.abs(axis_map.axis_end[:-1] - axis_map.axis_start[1:])
                same = axis_map.legs[:-1] == axis_map.legs[1:]
                broken = np.where(
                    same, np.abs(s_end[:-1] - axis_map.s_start[1:]), s_end[:-1] + axis_map.s_start[1:]
                )
                if np.any(gaps > 1e-12 * scale) or np.any(broken > TRACK_END_TOLERANCE):
                    failures.append(
                        f"{where}.{{axis_start,axis_end,s_start}}: map sub-ranges do not join "
                        "(axis or track gap)"
                    )


def _check_parked(pieces: Pieces, schedule: Schedule, failures: list[str]) -> None:
    """A vehicle whose map says it stands still (slope 0) does not move its axis."""
    for vehicle in range(2):
        parked = pieces.s_sign[vehicle] == 0.0
        if not parked.any():
            continue
        low, _, high, _ = polynomials.extrema(
            polynomials.derivative(pieces.axis[vehicle][parked]), pieces.length[parked]
        )
        moving = np.maximum(np.abs(low), np.abs(high)) > _allowance(schedule, vehicle, "velocity")
        if moving.any():
            k = int(np.nonzero(parked)[0][np.argmax(moving)])
            failures.append(
                f"vehicle {vehicle + 1} moves at t={pieces.start[k]:.6f} s where its map says it stands: "
                f"{_where(schedule, pieces, k, (vehicle,))}"
            )


def certify(schedule: Schedule) -> VerifiedSchedule:
    """Verify ``schedule`` and return it certified, or raise.

    Raises
    ------
    VerificationError
        The schedule failed; the message lists every failure.
    """
    report = verify(schedule)
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
