"""A schedule as polynomial pieces: on each, both axes are single polynomials and each vehicle on one leg.

The verifier checks these pieces in closed form (:mod:`trajgen.model.polynomials`), so
nothing can hide between samples, and its cost grows with the number of
pieces, not with the duration.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from math import comb

import numpy as np

from topology import JUNCTION_INDEX
from trajgen.model.blended import ToppraKinematics
from trajgen.model.polynomials import evaluate, root_in
from trajgen.model.schedule import AxisMap, CubicKinematics, Schedule
from trajgen.model.values import ArrayValue, readonly, sorted_unique

__all__ = [
    "DEGREE",
    "Pieces",
    "UncheckableKinematicsError",
    "cubic_pieces",
    "kinematics_polynomials",
    "motion_arrays",
    "schedule_pieces",
    "shift",
    "split_at_values",
    "toppra_pieces",
]

#: Highest power of the axis polynomials (TOPPRA sections: a quadratic path of a quadratic s(t)).
DEGREE = 4


class UncheckableKinematicsError(TypeError):
    """A section's kinematics have no polynomial form the verifier knows."""


@dataclass(frozen=True, slots=True, eq=False)
class Pieces(ArrayValue):
    """The polynomial pieces of a schedule, in time order.

    Attributes
    ----------
    start : ndarray, shape (n,)
        Start of each piece, seconds from the start of the schedule.
    length : ndarray, shape (n,)
        Duration of each piece, seconds (> 0).
    axis : ndarray, shape (2, n, DEGREE + 1)
        Per vehicle, the signed axis on the piece as a polynomial of the time
        since the piece's start (increasing powers; metres, seconds).
    leg : ndarray of int, shape (2, n)
        Leg of each vehicle on the piece (``JUNCTION_INDEX``: parked at the junction).
    s_offset, s_sign : ndarray, shape (2, n)
        Distance from the junction ``s = s_offset + s_sign * axis`` (metres; ``s_sign`` is +1, -1 or 0).
    axis_low, axis_high : ndarray, shape (2, n)
        The axis range the section's map covers, metres (outside it the map would clip).
    section : ndarray of int, shape (n,)
        Index of the section each piece belongs to.
    interval : ndarray of int, shape (2, n)
        Per vehicle, the interval of its section's kinematics the piece lies in (a knot
        interval of its piecewise cubic, or of a TOPPRA section's grid): where its numbers are.
    """

    start: np.ndarray
    length: np.ndarray
    axis: np.ndarray
    leg: np.ndarray
    s_offset: np.ndarray
    s_sign: np.ndarray
    axis_low: np.ndarray
    axis_high: np.ndarray
    section: np.ndarray
    interval: np.ndarray

    def __post_init__(self) -> None:
        for name in ("start", "length", "axis", "s_offset", "s_sign", "axis_low", "axis_high"):
            object.__setattr__(self, name, readonly(getattr(self, name), float))
        for name in ("leg", "section", "interval"):
            object.__setattr__(self, name, readonly(getattr(self, name), int))

    @property
    def count(self) -> int:
        """Number of pieces."""
        return int(self.length.size)

    def track(self) -> np.ndarray:
        """Distance from the junction of each vehicle as polynomials, shape (2, n, DEGREE + 1)."""
        s = self.axis * self.s_sign[:, :, None]
        s[:, :, 0] += self.s_offset
        return s


def shift(c: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """The same polynomials re-expanded about ``t = delta`` (Taylor shift), shape of ``c``.

    Examples
    --------
    >>> shift(np.array([[0.0, 0.0, 1.0]]), np.array([2.0]))  # t^2 about t = 2: 4 + 4 u + u^2
    array([[4., 4., 1.]])
    """
    out = np.zeros_like(c)
    degree = c.shape[-1] - 1
    for j in range(degree + 1):
        for i in range(j, degree + 1):
            out[..., j] += c[..., i] * comb(i, j) * delta ** (i - j)
    return out


def cubic_pieces(kinematics: CubicKinematics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Breakpoints (m + 1,), axis polynomials (V, m, DEGREE + 1), knot intervals (V, m): a cubic section.

    V is the number of vehicles.
    """
    duration = kinematics.duration
    times = sorted_unique(
        np.concatenate([np.clip(p.times, 0.0, duration) for p in kinematics.vehicles] + [[0.0]])
    )
    times = np.append(times[times < duration], duration) if duration > 0 else np.array([0.0, 0.0])
    begin = times[:-1]
    count = len(kinematics.vehicles)
    coefficients = np.zeros((count, begin.size, DEGREE + 1))
    intervals = np.zeros((count, begin.size), dtype=int)
    for vehicle, profile in enumerate(kinematics.vehicles):
        k = np.clip(np.searchsorted(profile.times, begin, side="right") - 1, 0, len(profile.jerk) - 1)
        intervals[vehicle] = k
        delta = begin - profile.times[k]
        p0, v0, a0 = profile.initial[k, 0], profile.initial[k, 1], profile.initial[k, 2]
        j = profile.jerk[k]
        ended = begin >= profile.times[-1]
        end_p = profile.initial[-1, 0] + (h := profile.times[-1] - profile.times[-2]) * (
            profile.initial[-1, 1] + h * (profile.initial[-1, 2] / 2.0 + h * profile.jerk[-1] / 6.0)
        )
        coefficients[vehicle, :, 0] = np.where(
            ended, end_p, p0 + delta * (v0 + delta * (a0 / 2.0 + delta * j / 6.0))
        )
        coefficients[vehicle, :, 1] = np.where(ended, 0.0, v0 + delta * (a0 + delta * j / 2.0))
        coefficients[vehicle, :, 2] = np.where(ended, 0.0, (a0 + delta * j) / 2.0)
        coefficients[vehicle, :, 3] = np.where(ended, 0.0, j / 6.0)
    return times, coefficients, intervals


def toppra_pieces(kinematics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Breakpoints, axis polynomials and grid intervals of a TOPPRA section: q(s(t)), quadratic in time."""
    grid, speed, times, path = kinematics.grid, kinematics.speed, kinematics.times, kinematics.path
    width = np.diff(grid)
    with np.errstate(divide="ignore", invalid="ignore"):
        accel = np.where(width > 0.0, (speed[1:] ** 2 - speed[:-1] ** 2) / (2.0 * width), 0.0)
    piece = path.piece(grid[:-1])
    piece_start = path.breakpoints[piece]
    alpha = grid[:-1] - piece_start  # s - s_piece at the interval start
    beta, gamma = speed[:-1], 0.5 * accel
    p0 = path.on_piece(piece, piece_start, 0)  # (m, 2): the piece's polynomial at its own start
    d1 = path.on_piece(piece, piece_start, 1)
    d2 = path.on_piece(piece, piece_start, 2)
    count = p0.shape[1]
    coefficients = np.zeros((count, grid.size - 1, DEGREE + 1))
    for vehicle in range(count):
        a, b, c = p0[:, vehicle], d1[:, vehicle], 0.5 * d2[:, vehicle]  # q = a + b u + c u^2
        coefficients[vehicle, :, 0] = a + b * alpha + c * alpha**2
        coefficients[vehicle, :, 1] = b * beta + 2.0 * c * alpha * beta
        coefficients[vehicle, :, 2] = b * gamma + c * (beta**2 + 2.0 * alpha * gamma)
        coefficients[vehicle, :, 3] = 2.0 * c * beta * gamma
        coefficients[vehicle, :, 4] = c * gamma**2
    intervals = np.tile(np.arange(grid.size - 1), (count, 1))
    return np.asarray(times, dtype=float), coefficients, intervals


def kinematics_polynomials(kinematics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Breakpoints (m + 1,), every vehicle's polynomials (V, m, DEGREE + 1) and intervals (V, m) of a section.

    Raises
    ------
    UncheckableKinematicsError
        The kinematics are neither piecewise cubic nor TOPPRA's.
    """
    # exact types only: a subclass could evaluate (and so export) something else than this form
    if type(kinematics) is CubicKinematics:
        return cubic_pieces(kinematics)
    if type(kinematics) is ToppraKinematics:
        return toppra_pieces(kinematics)
    raise UncheckableKinematicsError(
        f"section kinematics {type(kinematics).__name__} have no polynomial form the verifier knows"
    )


def motion_arrays(schedule: Schedule, section: int, vehicle: int, interval: int | None = None) -> str:
    """The arrays that define one vehicle's motion in a section, by their paths from the schedule.

    Parameters
    ----------
    schedule : Schedule
    section, vehicle : int
        Section index; 0 for vehicle 1, 1 for vehicle 2.
    interval : int, optional
        The knot (or grid) interval of the section's kinematics, when one is meant.

    Returns
    -------
    str
        For example ``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4,
        sections[2].maps[0].{axis_start,axis_end,s_start}``.
    """
    kinematics = schedule.sections[section].kinematics
    if type(kinematics) is ToppraKinematics:
        arrays = f"sections[{section}].kinematics.{{grid,speed,times}}"
    else:
        arrays = f"sections[{section}].kinematics.vehicles[{vehicle}].{{times,initial,jerk}}"
    at = "" if interval is None else f" interval {interval}"
    return f"{arrays}{at}, sections[{section}].maps[{vehicle}].{{axis_start,axis_end,s_start}}"


def split_at_values(
    times: np.ndarray, axis: np.ndarray, intervals: np.ndarray, values: tuple, *, margin: float = 0.0
):
    """Split pieces where a vehicle's axis polynomial passes one of its ``values``.

    Parameters
    ----------
    times : ndarray, shape (m + 1,)
        Breakpoints, seconds.
    axis : ndarray, shape (2, m, DEGREE + 1)
        Both vehicles' polynomials on each piece (time since the piece's start).
    intervals : ndarray of int, shape (2, m)
    values : tuple of 2 sequences of float
        Per vehicle, the axis values to split at.
    margin : float, optional
        A piece that reaches a value within ``margin`` at one of its ends is not split (it passes the
        value at its knot; a root near a knot where the motion comes to rest is round-off).

    Returns
    -------
    (starts, lengths, axis, intervals)
        The pieces after splitting, shapes (n,), (n,), (2, n, DEGREE + 1), (2, n).
    """
    splits = [[] for _ in range(times.size - 1)]
    h = np.diff(times)
    for vehicle, bounds in enumerate(values):
        for value in bounds:
            c = axis[vehicle].copy()
            c[:, 0] -= value
            roots = root_in(c, np.zeros_like(h), h)
            inside = np.isfinite(roots) & (roots > 0.0) & (roots < h)
            if margin > 0.0:
                inside &= (np.abs(c[:, 0]) > margin) & (np.abs(evaluate(c, h)) > margin)
            for k in np.nonzero(inside)[0]:
                splits[k].append(float(roots[k]))
    if not any(splits):
        return times[:-1], h, axis, intervals
    starts, lengths, rows = [], [], []
    for k, points in enumerate(splits):
        cuts = [0.0, *sorted(points), float(times[k + 1] - times[k])]
        for a, b in itertools.pairwise(cuts):
            if b > a:
                starts.append(times[k] + a)
                lengths.append(b - a)
                rows.append((k, a))
    index = np.array([r[0] for r in rows])
    offset = np.array([r[1] for r in rows])
    return np.array(starts), np.array(lengths), shift(axis[:, index], offset[None, :]), intervals[:, index]


def _split_at_map_boundaries(
    times: np.ndarray, axis: np.ndarray, intervals: np.ndarray, maps: tuple[AxisMap, AxisMap]
):
    """Split pieces where an axis crosses from one sub-range of its map to the next."""
    values = tuple(
        sorted_unique(np.concatenate([m.axis_start, m.axis_end]))[1:-1] if m.legs.size >= 2 else ()
        for m in maps
    )
    return split_at_values(times, axis, intervals, values)


def _map_of(axis_map: AxisMap, middle: np.ndarray):
    """Leg, s offset and s sign per piece (the sub-range of the piece's mid-axis), and the map's range."""
    low = np.minimum(axis_map.axis_start, axis_map.axis_end)
    high = np.maximum(axis_map.axis_start, axis_map.axis_end)
    if axis_map.legs.size == 1:
        r = np.zeros(middle.size, dtype=int)
        low_all, high_all = -np.inf, np.inf  # one leg: the affine map holds everywhere
    else:
        gap = np.maximum(low[:, None] - middle[None, :], 0.0) + np.maximum(
            middle[None, :] - high[:, None], 0.0
        )
        r = np.argmin(gap, axis=0)
        low_all, high_all = float(low.min()), float(high.max())
    sign = axis_map.outward[r].astype(float)
    offset = axis_map.s_start[r] - sign * axis_map.axis_start[r]
    leg = np.where((sign == 0.0) & (axis_map.s_start[r] == 0.0), JUNCTION_INDEX, axis_map.legs[r])
    return leg, offset, sign, np.full(middle.size, low_all), np.full(middle.size, high_all)


def schedule_pieces(schedule: Schedule) -> Pieces:
    """Every polynomial piece of ``schedule``, in time order.

    Raises
    ------
    UncheckableKinematicsError
        A section's kinematics are neither piecewise cubic nor TOPPRA's.
    """
    parts = []
    for index, section in enumerate(schedule.sections):
        times, axis, intervals = kinematics_polynomials(section.kinematics)
        starts, lengths, axis, intervals = _split_at_map_boundaries(times, axis, intervals, section.maps)
        keep = lengths > 0.0
        starts, lengths, axis, intervals = starts[keep], lengths[keep], axis[:, keep], intervals[:, keep]
        columns = [_map_of(section.maps[v], evaluate(axis[v], 0.5 * lengths)) for v in range(2)]
        parts.append(
            (section.start_time + starts, lengths, axis, columns, np.full(lengths.size, index), intervals)
        )
    if not parts or sum(p[1].size for p in parts) == 0:
        empty = np.zeros((2, 0))
        return Pieces(
            np.zeros(0),
            np.zeros(0),
            np.zeros((2, 0, DEGREE + 1)),
            empty,
            empty,
            empty,
            empty,
            empty,
            np.zeros(0),
            np.zeros((2, 0)),
        )
    start = np.concatenate([p[0] for p in parts])
    length = np.concatenate([p[1] for p in parts])
    axis = np.concatenate([p[2] for p in parts], axis=1)
    stacked = [
        np.stack([np.concatenate([p[3][v][field] for p in parts]) for v in range(2)]) for field in range(5)
    ]
    section = np.concatenate([p[4] for p in parts])
    interval = np.concatenate([p[5] for p in parts], axis=1)
    leg, offset, sign = stacked[0], stacked[1], stacked[2]
    # a vehicle standing exactly at the junction for a whole piece is on no leg (as Schedule.state says)
    track = axis * sign[:, :, None]
    track[:, :, 0] += offset
    leg = np.where(np.all(track == 0.0, axis=2), JUNCTION_INDEX, leg)
    return Pieces(start, length, axis, leg, offset, sign, stacked[3], stacked[4], section, interval)
