"""Tables of at most a controller's number of points, placed where they keep the error smallest.

A schedule sampled every 10 ms has thousands of rows; a ``TO_Cam`` takes
1,000 points and ``MC_VelocityProfile`` 100. :func:`resample` picks the
points: the start, the goal and every place where a vehicle starts, stops or
reverses are always points (so the table rests and turns where the schedule
does); the others are added greedily, each round where the interpolated
table is furthest from the schedule, until the limit is reached or the table
is exact. The table is then slowed down uniformly (both vehicles by the same
factor, so their coordination is kept) just enough for its interpolation to
respect the limits, if it does not already.
"""

from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass

import numpy as np

from trajgen.errors import InputError, OutputLimitError
from trajgen.export.plc.tables import Interpolation, ProfileTable, divided_differences, limit_ratios, slowdown
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import kinematics_polynomials, schedule_pieces, split_at_values
from trajgen.model.schedule import Schedule
from trajgen.model.values import sorted_unique
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["POSITION_SCALE", "VELOCITY_SCALE", "Resampled", "resample"]

logger = logging.getLogger(__name__)

#: Samples of the schedule per polynomial piece against which a table's error is measured.
SAMPLES_PER_PIECE = 16
#: Errors are weighed as position / POSITION_SCALE and velocity / VELOCITY_SCALE (m, m/s).
POSITION_SCALE = 1e-3
VELOCITY_SCALE = 1e-2
#: Shortest step between two points of a table, seconds (a spline over a shorter one has no use).
MIN_STEP = 1e-6
#: Points are also placed this long before and after each closest approach, seconds.
APPROACH_SPAN = 0.1
#: Below this speed (m/s) a vehicle counts as at rest.
REST_SPEED = 1e-9


@dataclass(frozen=True, slots=True)
class Resampled:
    """Both vehicles' tables and how far they are from the schedule.

    Attributes
    ----------
    tables : tuple of 2 ProfileTable
    time_scale : float
        The tables run this many times as long as the schedule (1.0: not slowed).
    position_error : tuple of float
        Worst distance of each interpolated table from the schedule, metres
        (in the table's own time: the schedule's time multiplied by ``time_scale``).
    velocity_error : tuple of float
        Worst velocity difference, m/s, likewise.
    """

    tables: tuple[ProfileTable, ...]
    time_scale: float
    position_error: tuple[float, ...]
    velocity_error: tuple[float, ...]

    def summary(self) -> dict:
        """JSON-ready figures."""
        return {
            "points": [int(table.times.size) for table in self.tables],
            "interpolation": self.tables[0].interpolation.value,
            "time_scale": self.time_scale,
            "duration_s": max(table.duration for table in self.tables),
            "position_error_m": list(self.position_error),
            "velocity_error_mps": list(self.velocity_error),
        }


def _spread(times: np.ndarray) -> np.ndarray:
    """Sorted unique times without any closer than MIN_STEP to the one before (the last kept)."""
    keep = [0]
    for k in range(1, times.size):
        if times[k] - times[keep[-1]] >= MIN_STEP:
            keep.append(k)
    if times.size > 1 and keep[-1] != times.size - 1:
        keep[-1] = times.size - 1
    return times[keep]


def _pieces(schedule: Schedule | GraphSchedule) -> tuple[np.ndarray, np.ndarray]:
    """Start time and length (seconds) of every polynomial piece of ``schedule``, shape (n,) each."""
    if isinstance(schedule, Schedule):
        pieces = schedule_pieces(schedule)
        return pieces.start, pieces.length
    # a junction's legs are numbered in its rows: a vehicle changing legs starts a piece, as on the junction
    changes = tuple(_leg_changes(path) for path in schedule.paths) if schedule.track.numbered_legs else None
    starts, lengths = [], []
    for section in schedule.sections:
        times, travel, intervals = kinematics_polynomials(section.kinematics)
        if changes is not None:
            start, length, _, _ = split_at_values(times, travel, intervals, changes)
        else:
            start, length = times[:-1], np.diff(times)
        starts.append(section.start_time + start)
        lengths.append(length)
    return np.concatenate(starts), np.concatenate(lengths)


def _leg_changes(path) -> np.ndarray:
    """The travel (m) at which a vehicle's path goes on from one edge to another."""
    edges = np.asarray(path.edges)
    return (
        np.asarray(path.starts, dtype=float)[1:-1][edges[1:] != edges[:-1]] if edges.size > 1 else np.zeros(0)
    )


def _reference_times(
    schedule: Schedule | GraphSchedule, decimals: int, points: int
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate times, and the pieces' boundaries (both rounded to ``decimals``).

    The candidates: SAMPLES_PER_PIECE per piece, and ``4 * points`` evenly (finer than any table
    of ``points`` points needs), so their number grows with the pieces and the points, not the duration.
    """
    start, length = _pieces(schedule)
    duration = schedule.duration
    boundaries = np.concatenate([[0.0, duration], start, start + length])
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_PIECE + 1)
    grid = (start[:, None] + length[:, None] * fractions[None, :]).ravel()
    boundaries = sorted_unique(np.clip(np.round(boundaries, decimals), 0.0, duration))
    boundaries = _spread(boundaries)
    even = np.linspace(0.0, duration, 4 * points + 1)
    grid = sorted_unique(
        np.concatenate([np.clip(np.round(np.r_[grid, even], decimals), 0.0, duration), boundaries])
    )
    return _spread(grid), boundaries


def _required(boundaries: np.ndarray, velocity: np.ndarray, middle: np.ndarray) -> np.ndarray:
    """Boundaries where the vehicle starts, stops or reverses, with the first and last.

    ``velocity``: at the boundaries; ``middle``: at the middles between them.
    """
    moving = np.abs(middle) > REST_SPEED
    direction = np.sign(middle)
    keep = np.zeros(boundaries.size, dtype=bool)
    keep[[0, -1]] = True
    inner = slice(1, -1)
    keep[inner] = (moving[:-1] != moving[1:]) | (moving[:-1] & moving[1:] & (direction[:-1] != direction[1:]))
    return boundaries[keep]


def _matched_velocities(
    times: np.ndarray, velocity: np.ndarray, axis: np.ndarray, anchors: np.ndarray
) -> np.ndarray:
    """Velocities scaled between anchors so the table's integral lands where the schedule is at each.

    ``anchors``: indices of the points where the position must be the schedule's (start, goal,
    starts, stops, reversals, closest approaches). Every rest is one; an anchor with no point
    between it and the previous one is passed over (nothing there to scale).
    """
    velocity = velocity.copy()
    rests = np.nonzero(np.abs(velocity) <= REST_SPEED)[0]
    velocity[rests] = 0.0
    wanted = set(anchors.tolist()) | {0, times.size - 1}
    resting = set(rests.tolist()) | {0, times.size - 1}
    kept = [0]
    for k in range(1, times.size):
        if k not in wanted:
            continue
        if k - kept[-1] < 2:
            if k not in resting:
                continue
            if kept[-1] not in resting:
                kept.pop()  # a rest is kept before a closer anchor: nothing lies between them
        kept.append(k)
    for a, b in itertools.pairwise(kept):
        if b - a < 2:
            continue
        steps = np.diff(times[a : b + 1])
        ends = 0.5 * (velocity[a] * steps[0] + velocity[b] * steps[-1])  # the anchors' own share
        inner = float(np.sum(velocity[a + 1 : b] * 0.5 * (steps[:-1] + steps[1:])))
        target = float(axis[b] - axis[a]) - ends
        if inner * target > 0.0 and 0.5 < target / inner < 2.0:
            velocity[a + 1 : b] *= target / inner
    return velocity


def _table(
    schedule: Schedule | GraphSchedule,
    vehicle: int,
    times: np.ndarray,
    interpolation: Interpolation,
    scale: float,
    *,
    anchors: np.ndarray | None = None,
) -> ProfileTable:
    """The table with points at ``times`` (its own time) of a schedule slowed by ``scale``.

    A velocity table's velocities are scaled between the points at ``anchors`` (indices) so it
    is where the schedule is at each of them; without anchors they are the schedule's.
    """
    state = schedule.state(times / scale)
    if interpolation is Interpolation.VELOCITY:
        values = state.velocity[vehicle] / scale
        if anchors is not None:
            values = _matched_velocities(times, values, state.axis[vehicle], anchors)
        return ProfileTable(times, values, interpolation, start=float(state.axis[vehicle, 0]))
    return ProfileTable(times, state.axis[vehicle], interpolation)


def _errors(table: ProfileTable, grid: np.ndarray, axis: np.ndarray, velocity: np.ndarray, scale: float):
    """Position and velocity error of ``table`` at the schedule's ``grid`` times (shape (n,) each)."""
    values = table.motion().evaluate(grid * scale)
    return np.abs(values[0] - axis), np.abs(values[1] * scale - velocity)


def _closest_approaches(schedule: Schedule | GraphSchedule, grid: np.ndarray, state) -> np.ndarray:
    """Times of the grid where the least distance of two vehicles has a local minimum near the separation."""
    separation = schedule.limits.min_separation
    distance = schedule.distances(state)
    if distance.size < 3:
        return np.zeros(0)
    inner = (distance[1:-1] < distance[:-2]) & (distance[1:-1] <= distance[2:])
    near = distance[1:-1] < 1.05 * separation + 0.01
    minima = grid[1:-1][inner & near]
    # and a little before and after: where the vehicles run close together, a table is held to
    # the schedule on both sides of the closest instant, not only at it
    around = (minima[:, None] + np.array([-APPROACH_SPAN, 0.0, APPROACH_SPAN])[None, :]).ravel()
    return sorted_unique(grid[np.clip(np.searchsorted(grid, around), 0, grid.size - 1)])


def _equidistributed(grid: np.ndarray, density: np.ndarray, required: np.ndarray, count: int) -> np.ndarray:
    """Indices of ``count`` grid points, the ``required`` ones among them, equal ``density`` between.

    Linear interpolation's error on a step ``h`` grows as ``h**2`` times the second derivative,
    so equal shares of ``sqrt(|second derivative|)`` per step make the steps' errors equal.
    """
    mass = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(grid))])
    shares = np.diff(mass[required])
    budget = count - required.size
    if budget <= 0 or mass[-1] <= 0.0:
        return required
    quota = budget * shares / shares.sum()
    extra = np.floor(quota).astype(int)
    leftover = budget - int(extra.sum())
    extra[np.argsort(-(quota - extra))[:leftover]] += 1
    chosen = [required]
    for k, n in enumerate(extra):
        if n <= 0:
            continue
        targets = mass[required[k]] + shares[k] * np.arange(1, n + 1) / (n + 1)
        inside = np.clip(np.searchsorted(mass, targets), required[k] + 1, required[k + 1] - 1)
        chosen.append(inside[inside < required[k + 1]])
    return sorted_unique(np.concatenate(chosen))


def _points(
    schedule: Schedule | GraphSchedule,
    vehicle: int,
    interpolation: Interpolation,
    max_points: int,
    grid: np.ndarray,
    boundaries: np.ndarray,
    state,
    critical: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The times (of the schedule) of one vehicle's table points, at most ``max_points``.

    Returns the times and the indices among them where the table must be where the schedule is.
    """
    at_bounds = schedule.state(boundaries)
    middles = schedule.state(0.5 * (boundaries[:-1] + boundaries[1:]))
    required = _required(boundaries, at_bounds.velocity[vehicle], middles.velocity[vehicle])
    if boundaries.size <= 1:
        return boundaries, np.arange(boundaries.size)
    if required.size > max_points:
        raise OutputLimitError(
            f"vehicle {vehicle + 1}'s table needs at least {required.size} points (start, goal and every "
            f"start, stop and reversal): expected at most max_points {max_points} "
            "(raise max_points=... or --max-points)"
        )
    if required.size + critical.size <= max_points // 2:  # where the vehicles come closest
        required = np.union1d(required, critical)
    if interpolation is Interpolation.CUBIC and boundaries.size <= max_points:
        # a spline with knots at every jerk switch is the schedule itself; more knots would only
        # let the values' round-off through (it grows as the cube of a short step)
        return boundaries, np.searchsorted(boundaries, required)
    chosen = sorted_unique(np.searchsorted(grid, required))
    anchors = chosen.copy()
    axis, velocity = state.axis[vehicle], state.velocity[vehicle]
    if interpolation is not Interpolation.CUBIC:
        # second differences on the grid: also where the schedule's own derivative jumps (toppra)
        quantity = axis if interpolation is Interpolation.LINEAR else velocity
        second, _ = divided_differences(grid, quantity, 2)
        curvature = np.abs(np.concatenate([[second[0]], second, [second[-1]]]))
        curvature = np.maximum(curvature, np.maximum(np.roll(curvature, 1), np.roll(curvature, -1)))
        chosen = _equidistributed(grid, np.sqrt(curvature), chosen, max_points)
    while chosen.size < max_points:
        table = _table(schedule, vehicle, grid[chosen], interpolation, 1.0)
        position_error, velocity_error = _errors(table, grid, axis, velocity, 1.0)
        if interpolation is Interpolation.VELOCITY:  # its position error is the integral: not local
            error = velocity_error
        elif interpolation is Interpolation.LINEAR:  # its velocity steps at every point whatever we do
            error = position_error
        else:
            error = np.maximum(position_error / POSITION_SCALE, velocity_error / VELOCITY_SCALE)
        error[chosen] = 0.0  # already points
        interval = np.searchsorted(chosen, np.arange(grid.size), side="right") - 1
        worst = np.full(chosen.size, -1.0)
        where = np.full(chosen.size, -1)
        order = np.lexsort((error, interval))  # by interval, the largest error last
        last = np.r_[np.nonzero(np.diff(interval[order]))[0], order.size - 1]
        worst[interval[order[last]]] = error[order[last]]
        where[interval[order[last]]] = order[last]
        candidates = np.nonzero(worst > 1e-9)[0]
        if not candidates.size:
            break
        room = max_points - chosen.size
        take = candidates[np.argsort(-worst[candidates])][: max(1, min(room, chosen.size // 2 + 1))]
        chosen = sorted_unique(np.concatenate([chosen, where[take]]))
    return grid[chosen], np.searchsorted(chosen, anchors)


def resample(
    verified: VerifiedSchedule,
    *,
    interpolation: Interpolation,
    max_points: int,
    decimals: int = 9,
    min_scale: float = 1.0,
) -> Resampled:
    """Tables of every vehicle with at most ``max_points`` points each, for ``interpolation``.

    Parameters
    ----------
    verified : VerifiedSchedule
    interpolation : Interpolation
        How the controller interpolates the table.
    max_points : int
        Most points per table (at least 2).
    decimals : int, optional
        Decimal places of the times written (default 9: nanoseconds); the points' times are
        rounded to them before the values are taken, so what is written is what was verified.
    min_scale : float, optional
        Slow the tables down at least this much (default 1.0), e.g. when their written values'
        round-off needs it.

    Returns
    -------
    Resampled

    Raises
    ------
    OutputLimitError
        A vehicle starts, stops and reverses more often than ``max_points`` allows.
    """
    schedule = require_verified(verified, "resample").schedule
    interpolation = Interpolation.lookup(interpolation)
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
        raise InputError(f"max_points must be an integer >= 2, got {max_points!r}")
    grid, boundaries = _reference_times(schedule, decimals, max_points)
    state = schedule.state(grid)
    critical = _closest_approaches(schedule, grid, state)
    count = schedule.limits.count
    points = [
        _points(schedule, vehicle, interpolation, max_points, grid, boundaries, state, critical)
        for vehicle in range(count)
    ]
    times = [p[0] for p in points]
    tables = tuple(
        _table(schedule, v, times[v], interpolation, 1.0, anchors=points[v][1]) for v in range(count)
    )
    ratios = limit_ratios(tables, schedule.limits, jerk=schedule.jerk_limited)
    scale = slowdown(ratios)
    if scale > 1.0 + 1e-9:
        scale *= 1.0 + 1e-6  # clear of the limit, not on it
    scale = max(scale, min_scale)
    if scale > 1.0 + 1e-9:
        logger.info("tables slowed down by %.6g to respect the limits as interpolated", scale)
        tables = tuple(
            _table(
                schedule, v, np.round(times[v] * scale, decimals), interpolation, scale, anchors=points[v][1]
            )
            for v in range(count)
        )
    else:
        scale = 1.0
    fine = np.sort(np.concatenate([grid, 0.5 * (grid[:-1] + grid[1:])]))  # between the candidates too
    fine_state = schedule.state(fine)
    errors = [
        _errors(tables[v], fine, fine_state.axis[v], fine_state.velocity[v], scale) for v in range(count)
    ]
    return Resampled(
        tables,
        scale,
        tuple(float(position.max()) for position, _ in errors),
        tuple(float(velocity.max()) for _, velocity in errors),
    )
