"""Independent verifier: nothing leaves the library unless it passes.

The verifier takes a schedule apart into polynomial pieces
(:mod:`trajgen.model.pieces`: on each piece both vehicles' signed axes are single
polynomials and each vehicle is on one leg) and checks every piece in closed
form (:mod:`trajgen.model.polynomials`: extrema at the ends and at the roots of the
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
- the sequence of regions visited (the route's class: which way the vehicles go round each other) is
  the route's;
- the braking rule (:mod:`trajgen.verification.braking_rule`): each vehicle that follows at a
  conflict can always stop short of its frontier, so what is planned is what
  the online executor plays;
- every number is finite, every knot sequence increases, and every array
  derived from others agrees with them (:mod:`trajgen.verification.integrity`).

A failure says in plain words what is wrong: the quantity, its value and limit, the vehicle,
when (seconds) and where on the track. Where it lies in the schedule's arrays, by their paths
(``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4``), is in the report's
``details`` (and :class:`~trajgen.errors.VerificationError`'s), for debugging.

:func:`verify` is a pure function of the (immutable) schedule: it keeps nothing.
:func:`certify` turns a passing schedule into a :class:`VerifiedSchedule`, the
only kind of schedule that exporters and plots accept, and the only way to make one.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from topology import Region, reduce_regions
from topology.indexed import JUNCTION_INDEX, track_distance
from trajgen.errors import InputError, UnverifiedScheduleError
from trajgen.model import polynomials
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import Pieces, UncheckableKinematicsError, schedule_pieces
from trajgen.model.schedule import Schedule
from trajgen.verification.braking_rule import braking_rule_failures, for_execution
from trajgen.verification.graph_schedule import verify_graph_schedule
from trajgen.verification.integrity import array_failures
from trajgen.verification.piecewise import (
    allowance,
    check_maps,
    check_parked,
    check_piece_continuity,
    check_piece_limits,
    check_piece_separation,
    check_piece_track,
    piece_arrays,
    place,
    places,
)
from trajgen.verification.report import (
    POSITION_TOLERANCE,
    REST_TOLERANCE,
    TRACK_END_TOLERANCE,
    Finding,
    VerificationReport,
)

__all__ = ["VerifiedSchedule", "certify", "require_verified", "verify"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class VerifiedSchedule:
    """A schedule that passed the verifier, with its report: what exporters and plots accept.

    Made by :func:`certify` alone: calling the class (or :func:`dataclasses.replace` on an
    instance) raises, so that no schedule is ever paired with a report that is not its own.

    Attributes
    ----------
    schedule : Schedule
    report : VerificationReport
        The passed report.
    """

    schedule: Schedule
    report: VerificationReport

    def __repr__(self) -> str:
        """One line: the schedule and the verifier's verdict."""
        schedule = repr(self.schedule).removeprefix("<Schedule: ").removesuffix(">")
        report = repr(self.report).removeprefix("<VerificationReport: ").removesuffix(">")
        return f"<VerifiedSchedule: {schedule}; {report}>"

    def __post_init__(self) -> None:
        raise UnverifiedScheduleError(
            "a VerifiedSchedule is made by trajgen.certify(schedule) alone: expected certify, not the class"
        )


def verify(schedule: Schedule) -> VerificationReport:
    """Check a schedule independently of how it was computed, between any two instants too.

    Parameters
    ----------
    schedule : Schedule

    Returns
    -------
    VerificationReport
        Computed afresh at each call (about 10–20 ms for the examples' schedules).

    Raises
    ------
    InputError
        ``schedule`` is not a Schedule.
    """
    if not isinstance(schedule, Schedule | GraphSchedule):
        raise InputError(f"verify expects a Schedule or a GraphSchedule, got {type(schedule).__name__}")
    began = time.perf_counter()
    moved = len(tuple(schedule.route.start))
    if schedule.limits.count != moved:  # the motion's vehicles are the route's: limits for each
        return VerificationReport.failed(
            (
                f"the limits are of {schedule.limits.count} vehicle(s), the route moves {moved}: "
                "expected one per vehicle",
            )
        )
    report = verify_graph_schedule(schedule) if isinstance(schedule, GraphSchedule) else _verify(schedule)
    logger.debug(
        "verified a %s schedule (%d pieces) in %.1f ms: %s",
        schedule.method,
        report.pieces,
        1e3 * (time.perf_counter() - began),
        "passed" if report.passed else "FAILED",
    )
    if not report.passed:  # with where in the schedule's arrays: what ``trajgen --verbose`` shows
        logger.info("schedule (%s) failed verification: %s", schedule.method, "; ".join(report.details))
    return report


def _failed(failures: list[str], pieces: int = 0) -> VerificationReport:
    """A failed report for a schedule that cannot even be taken apart."""
    return VerificationReport.failed(tuple(failures), pieces=pieces)


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
                    Finding(
                        f"vehicle {vehicle + 1} is not at rest at the {label} "
                        f"(t={float(state.t[index]):.6f} s, |v| + |a| = {residue:.3g}): "
                        f"expected at most {REST_TOLERANCE:g}",
                        piece_arrays(schedule, pieces, piece, (vehicle,)),
                    )
                )
        tolerance = POSITION_TOLERANCE if schedule.end_tolerance is None else schedule.end_tolerance
        if not error <= tolerance:
            at = float(state.t[index])
            failures.append(
                Finding(
                    f"{label} is off the route's {label} by {error:.3g} m at t={at:.6f} s (expected "
                    f"<= {tolerance:g} m): {_where(state, index, graph)} (the route's: "
                    + ", ".join(str(p) for p in expected)
                    + ")",
                    piece_arrays(schedule, pieces, piece),
                )
            )
        errors.append(error)
    start_gap = float(track_distance(state.leg[0, 0], state.s[0, 0], state.leg[1, 0], state.s[1, 0]))
    return errors[0], errors[1], start_gap


def _where(state, index: int, graph) -> str:
    """Both vehicles' places in ``state`` at ``index``, as positions are written (``A:9.8``, ``O``)."""
    names = []
    for vehicle in range(2):
        leg = int(state.leg[vehicle, index])
        at = "O" if leg == JUNCTION_INDEX else f"{graph.names[leg]}:{float(state.s[vehicle, index]):.4g}"
        names.append(f"vehicle {vehicle + 1} at {at}")
    return ", ".join(names)


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
            if not gap <= allowance(schedule, vehicle, "position"):
                failures.append(
                    Finding(
                        f"vehicle {vehicle + 1} is {gap:.3g} m from where its motion puts it at the "
                        f"{label}: the schedule reports a position its motion does not reach",
                        piece_arrays(schedule, pieces, 0 if index == 0 else pieces.count - 1, (vehicle,)),
                    )
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
        at = float(ends[k - 1]) if k else 0.0
        failures.append(
            Finding(
                f"the motion has a gap of {gaps[k]:.3g} s in time at t={at:.6f} s: expected none",
                f"sections[{section}].start_time; {piece_arrays(schedule, pieces, min(k, pieces.count - 1))}",
            )
        )


def _verify(schedule: Schedule) -> VerificationReport:
    own = array_failures(schedule)
    if own:  # the motion is read from these numbers: broken ones make every other check meaningless
        return _failed(own)
    duration = schedule.duration
    if not math.isfinite(duration) or duration < 0.0:
        return _failed([f"schedule duration is {duration!r} s: expected finite, >= 0"])
    route = schedule.route
    required = max(schedule.limits.min_separation, route.min_separation)
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # non-finite numbers are reported below
            pieces = schedule_pieces(schedule)
    except UncheckableKinematicsError as error:
        return _failed([f"cannot be checked: {error}"])
    if not (np.all(np.isfinite(pieces.axis)) and np.all(np.isfinite(pieces.start))):
        bad = int(np.argmax(~np.all(np.isfinite(pieces.axis), axis=(0, 2)) | ~np.isfinite(pieces.start)))
        return _failed(
            [
                Finding(
                    f"the motion is not finite from t={pieces.start[bad]!r} s: expected finite numbers",
                    piece_arrays(schedule, pieces, bad),
                )
            ],
            pieces.count,
        )
    failures: list[str] = []
    check_maps(schedule, failures)
    if failures:  # the pieces are read through the maps: a broken map makes them meaningless
        return _failed(failures, pieces.count)
    ends = schedule.state([0.0, duration])
    track = pieces.track()
    start_error, goal_error, start_gap = _check_ends(schedule, pieces, ends, failures)
    _check_exported_ends(pieces, track, schedule, ends, failures)
    _check_tiling(schedule, pieces, failures)
    check_parked(pieces, schedule, failures)
    ratios = check_piece_limits(pieces, schedule, failures)
    past_end = max(TRACK_END_TOLERANCE, schedule.end_tolerance or 0.0)
    check_piece_track(pieces, track, schedule, failures, past_end)
    closest, regions = check_piece_separation(pieces, track, schedule, required, failures)
    closest = min(closest, start_gap)
    if not pieces.count and start_gap < required - POSITION_TOLERANCE:
        failures.append(f"separation {start_gap:.9g} m at rest is below the minimum {required:g} m")
    check_piece_continuity(pieces, track, schedule, failures)
    if not failures and for_execution(schedule):
        # a plan for execution: each follower can always stop short of its frontier
        for failure in braking_rule_failures(schedule, pieces=pieces):
            k = int(
                np.clip(np.searchsorted(pieces.start, failure.time, side="right") - 1, 0, pieces.count - 1)
            )
            where = place(schedule, pieces, failure.vehicle, k, failure.time)
            failures.append(Finding(failure.message(where), piece_arrays(schedule, pieces, k)))
    expected = route.region_keys
    sequence = reduce_regions(regions)
    if sequence != expected:
        show = lambda keys: " ".join(str(Region.from_key(route.graph, key)) for key in keys)  # noqa: E731
        k = _first_departure(regions, expected)
        at = float(pieces.start[k]) if pieces.count else 0.0
        failures.append(
            Finding(
                f"the vehicles go round each other in another class than their route's, from t={at:.6f} s "
                f"({places(schedule, pieces, k, at)}): schedule visits [{show(sequence)}], "
                f"route [{show(expected)}]",
                piece_arrays(schedule, pieces, k),
            )
        )
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


def certify(schedule: Schedule) -> VerifiedSchedule:
    """Verify ``schedule`` and return it certified, or raise.

    Raises
    ------
    VerificationError
        The schedule failed; the message lists every failure.
    """
    report = verify(schedule)
    report.raise_if_failed()
    verified = object.__new__(VerifiedSchedule)  # the class refuses to be called: certify alone makes one
    object.__setattr__(verified, "schedule", schedule)
    object.__setattr__(verified, "report", report)
    return verified


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
