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
from trajgen.pieces import schedule_pieces
from trajgen.schedule import Schedule
from trajgen.tables import Interpolation, ProfileTable, limit_ratios
from trajgen.verify import VerifiedSchedule, require_verified

__all__ = ["POSITION_SCALE", "VELOCITY_SCALE", "Resampled", "resample"]

logger = logging.getLogger(__name__)

#: Samples of the schedule per polynomial piece against which a table's error is measured.
SAMPLES_PER_PIECE = 32
#: Errors are weighed as position / POSITION_SCALE and velocity / VELOCITY_SCALE (m, m/s).
POSITION_SCALE = 1e-3
VELOCITY_SCALE = 1e-2
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
    position_error : tuple of 2 float
        Worst distance of each interpolated table from the schedule, metres
        (in the table's own time: the schedule's time multiplied by ``time_scale``).
    velocity_error : tuple of 2 float
        Worst velocity difference, m/s, likewise.
    """

    tables: tuple[ProfileTable, ProfileTable]
    time_scale: float
    position_error: tuple[float, float]
    velocity_error: tuple[float, float]

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


def _reference_times(schedule: Schedule, decimals: int) -> tuple[np.ndarray, np.ndarray]:
    """A grid of SAMPLES_PER_PIECE samples per piece, and the pieces' boundaries (both rounded)."""
    pieces = schedule_pieces(schedule)
    duration = schedule.duration
    boundaries = np.concatenate([[0.0, duration], pieces.start, pieces.start + pieces.length])
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_PIECE + 1)
    grid = (pieces.start[:, None] + pieces.length[:, None] * fractions[None, :]).ravel()
    boundaries = np.unique(np.clip(np.round(boundaries, decimals), 0.0, duration))
    grid = np.unique(np.concatenate([np.clip(np.round(grid, decimals), 0.0, duration), boundaries]))
    return grid, boundaries


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


def _matched_velocities(times: np.ndarray, velocity: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Velocities scaled per stretch between rests so the table's integral lands where the schedule does."""
    velocity = velocity.copy()
    rests = np.nonzero(np.abs(velocity) <= REST_SPEED)[0]
    rests = np.unique(np.concatenate([[0], rests, [times.size - 1]]))
    velocity[rests] = 0.0
    for a, b in itertools.pairwise(rests):
        if b - a < 2:
            continue
        span = slice(a, b + 1)
        travelled = float(np.sum(0.5 * (velocity[span][:-1] + velocity[span][1:]) * np.diff(times[span])))
        wanted = float(axis[b] - axis[a])
        if travelled != 0.0:
            velocity[a + 1 : b] *= wanted / travelled
    return velocity


def _table(
    schedule: Schedule,
    vehicle: int,
    times: np.ndarray,
    interpolation: Interpolation,
    scale: float,
    *,
    matched: bool = True,
) -> ProfileTable:
    """The table with points at ``times`` (its own time) of a schedule slowed by ``scale``.

    A velocity table's velocities are scaled per stretch between rests so it arrives where the
    schedule does (``matched``), else they are the schedule's.
    """
    state = schedule.state(times / scale)
    if interpolation is Interpolation.VELOCITY:
        values = state.velocity[vehicle] / scale
        if matched:
            values = _matched_velocities(times, values, state.axis[vehicle])
        return ProfileTable(times, values, interpolation, start=float(state.axis[vehicle, 0]))
    return ProfileTable(times, state.axis[vehicle], interpolation)


def _errors(table: ProfileTable, grid: np.ndarray, axis: np.ndarray, velocity: np.ndarray, scale: float):
    """Position and velocity error of ``table`` at the schedule's ``grid`` times (shape (n,) each)."""
    values = table.motion().evaluate(grid * scale)
    return np.abs(values[0] - axis), np.abs(values[1] * scale - velocity)


def _points(
    schedule: Schedule,
    vehicle: int,
    interpolation: Interpolation,
    max_points: int,
    grid: np.ndarray,
    boundaries: np.ndarray,
    state,
) -> np.ndarray:
    """The times (of the schedule) of one vehicle's table points, at most ``max_points``."""
    at_bounds = schedule.state(boundaries)
    middles = schedule.state(0.5 * (boundaries[:-1] + boundaries[1:]))
    required = _required(boundaries, at_bounds.velocity[vehicle], middles.velocity[vehicle])
    if boundaries.size <= 1:
        return boundaries
    if required.size > max_points:
        raise OutputLimitError(
            f"vehicle {vehicle + 1}'s table needs at least {required.size} points (start, goal and every "
            f"start, stop and reversal): expected at most max_points {max_points} (raise --max-points)"
        )
    if interpolation is Interpolation.CUBIC and boundaries.size <= max_points:
        required = boundaries  # a spline with knots at every jerk switch is the schedule itself
    chosen = np.searchsorted(grid, required)
    axis, velocity = state.axis[vehicle], state.velocity[vehicle]
    while chosen.size < max_points:
        table = _table(schedule, vehicle, grid[chosen], interpolation, 1.0, matched=False)
        position_error, velocity_error = _errors(table, grid, axis, velocity, 1.0)
        if interpolation is Interpolation.VELOCITY:  # its position error is the integral: not local
            position_error = 0.0
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
        chosen = np.unique(np.concatenate([chosen, where[take]]))
    return grid[chosen]


def resample(
    verified: VerifiedSchedule, *, interpolation: Interpolation, max_points: int, decimals: int = 9
) -> Resampled:
    """Tables of both vehicles with at most ``max_points`` points each, for ``interpolation``.

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
    grid, boundaries = _reference_times(schedule, decimals)
    state = schedule.state(grid)
    times = [
        _points(schedule, vehicle, interpolation, max_points, grid, boundaries, state) for vehicle in range(2)
    ]
    tables = tuple(_table(schedule, v, times[v], interpolation, 1.0) for v in range(2))
    ratios = limit_ratios(tables, schedule.limits, jerk=schedule.jerk_limited)
    scale = 1.0
    for order, name in enumerate(("velocity", "acceleration", "jerk"), start=1):
        if ratios[name] is not None:
            scale = max(scale, max(ratios[name]) ** (1.0 / order))
    if scale > 1.0 + 1e-9:
        scale *= 1.0 + 1e-6  # clear of the limit, not on it
        logger.info("tables slowed down by %.6g to respect the limits as interpolated", scale)
        tables = tuple(
            _table(schedule, v, np.round(times[v] * scale, decimals), interpolation, scale) for v in range(2)
        )
    else:
        scale = 1.0
    fine = np.sort(np.concatenate([grid, 0.5 * (grid[:-1] + grid[1:])]))  # between the candidates too
    fine_state = schedule.state(fine)
    errors = [_errors(tables[v], fine, fine_state.axis[v], fine_state.velocity[v], scale) for v in range(2)]
    return Resampled(
        tables,
        scale,
        (float(errors[0][0].max()), float(errors[1][0].max())),
        (float(errors[0][1].max()), float(errors[1][1].max())),
    )
