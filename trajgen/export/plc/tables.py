"""Profile tables as a controller interpolates them, and their limits from divided differences.

A PLC does not play a schedule: it plays a table of points and interpolates
between them (linearly, by a cubic spline, or a velocity linearly in time).
:class:`ProfileTable` is one vehicle's table with the interpolation its
controller applies (read along the route and verified by
:mod:`trajgen.export.plc.table_check`). What a table's interpolation leaves
undefined (the acceleration of a linear table, the jerk of a linear velocity
table) is checked from divided differences of its points
(:func:`divided_differences`), with rest before the first point and after the
last: for points sampled from any motion within the limits these never exceed
the limits (mean-value theorem), so a table that fails moves differently.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import Option
from trajgen.errors import InputError
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.values import ArrayValue, readonly
from trajgen.verification import RELATIVE_TOLERANCE

__all__ = [
    "CROSSING_TOLERANCE",
    "END_TOLERANCES",
    "DifferenceCheck",
    "Interpolation",
    "ProfileTable",
    "difference_checks",
    "divided_differences",
    "limit_ratios",
    "slowdown",
]


#: How far from the route's start and goal a table may begin and end, and past a leg's end it may
#: reach, metres. The cubic through two rows of a generic CSV is the reader's, not the drive's: where
#: a motion stops hard at a leg's end (toppra) it overshoots the rows by a few micrometres.
END_TOLERANCES = {"linear": 1e-6, "cubic": 1e-6, "linear-velocity": 1e-6, "hermite": 1e-5}
#: How far past the junction a table's axis must go to count as passing it, metres.
CROSSING_TOLERANCE = 1e-9


class Interpolation(Option):
    """How a controller interpolates a table between its points."""

    LINEAR = "linear"  #: position linear in time (cam tables): velocity steps at the points
    CUBIC = "cubic"  #: position a C2 cubic spline through the points, at rest (v = 0) at both ends
    VELOCITY = "linear-velocity"  #: velocity linear in time, position its integral from the start
    #: position cubic between points through each point's position and velocity: a sampled motion read
    #: back, where the limits beyond velocity are those of the samples (divided differences)
    HERMITE = "hermite"

    @property
    def smoothness(self) -> int:
        """Derivatives of position the interpolation keeps continuous: 0, 1 or 2."""
        return {
            Interpolation.LINEAR: 0,
            Interpolation.VELOCITY: 1,
            Interpolation.HERMITE: 0,
            Interpolation.CUBIC: 2,
        }[self]

    @property
    def closed_form(self) -> int:
        """Derivatives (1 = velocity, ...) checked in closed form on the interpolated pieces.

        The others are checked from divided differences of the points. A Hermite
        table (a sampled motion read back) is judged by its points only: the
        cubic through two samples is the reader's, not the drive's.
        """
        return {
            Interpolation.LINEAR: 1,
            Interpolation.VELOCITY: 2,
            Interpolation.HERMITE: 0,
            Interpolation.CUBIC: 3,
        }[self]


@dataclass(frozen=True, slots=True, eq=False)
class ProfileTable(ArrayValue):
    """One vehicle's table of points and how its controller interpolates them.

    Attributes
    ----------
    times : ndarray, shape (n,)
        Master values: seconds from the start, from 0, strictly increasing.
    values : ndarray, shape (n,)
        Slave values: the signed axis (metres) of position tables, the axis
        velocity (m/s) of :attr:`Interpolation.VELOCITY` tables.
    interpolation : Interpolation
    start : float
        Axis at t = 0 of a velocity table, metres (position tables start at ``values[0]``).
    resolution : float
        Half the step of the numbers as written (metres, or m/s), the round-off
        the limit checks allow for; 0 for exact values.
    velocities : ndarray, shape (n,), or None
        The axis velocity at every point, m/s (:attr:`Interpolation.HERMITE` tables only).
    """

    times: np.ndarray
    values: np.ndarray
    interpolation: Interpolation
    start: float = 0.0
    resolution: float = 0.0
    velocities: np.ndarray | None = None

    def __post_init__(self) -> None:
        times = readonly(np.atleast_1d(np.asarray(self.times, dtype=float)))
        values = readonly(np.atleast_1d(np.asarray(self.values, dtype=float)))
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "interpolation", Interpolation.lookup(self.interpolation))
        if times.ndim != 1 or times.shape != values.shape or times.size < 1:
            raise InputError(
                f"a profile table needs as many times as values, at least one, got {times.shape} and "
                f"{values.shape}"
            )
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values)) and math.isfinite(self.start)):
            raise InputError("a profile table must hold finite numbers only")
        if times[0] != 0.0:
            raise InputError(f"a profile table starts at t = 0 s, got {times[0]!r} s")
        hermite = self.interpolation is Interpolation.HERMITE
        if hermite != (self.velocities is not None):
            raise InputError("a profile table has velocities at its points if and only if it is hermite")
        if hermite:
            velocities = readonly(np.atleast_1d(np.asarray(self.velocities, dtype=float)))
            if velocities.shape != times.shape or not np.all(np.isfinite(velocities)):
                raise InputError(f"a hermite table needs a finite velocity per point, got {velocities.shape}")
            object.__setattr__(self, "velocities", velocities)

    @property
    def round_off(self) -> float:
        """How far each value may be from what it stands for: :attr:`resolution`, or float round-off."""
        scale = float(np.max(np.abs(self.values))) + abs(self.start)
        return max(self.resolution, 4.0 * float(np.finfo(float).eps) * scale)

    @property
    def duration(self) -> float:
        """Time of the last point, seconds."""
        return float(self.times[-1])

    def decreasing_times(self) -> np.ndarray:
        """Indices ``i`` (0-based rows of the points) where ``times[i] <= times[i - 1]``."""
        return np.nonzero(np.diff(self.times) <= 0.0)[0] + 1

    def positions(self) -> np.ndarray:
        """The axis at every point, metres, shape (n,) (a velocity table integrated exactly)."""
        if self.interpolation is not Interpolation.VELOCITY:
            return self.values
        steps = 0.5 * (self.values[:-1] + self.values[1:]) * np.diff(self.times)
        return self.start + np.concatenate([[0.0], np.cumsum(steps)])

    def motion(self) -> PiecewiseCubic:
        """The interpolated motion of the axis as the controller drives it.

        Raises
        ------
        InputError
            The times do not strictly increase.
        """
        bad = self.decreasing_times()
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"profile table times must strictly increase, got {self.times[k - 1]!r} s then "
                f"{self.times[k]!r} s at point {k + 1}"
            )
        times, values = self.times, self.values
        if times.size == 1:
            start = values[0] if self.interpolation is not Interpolation.VELOCITY else self.start
            return PiecewiseCubic(np.array([0.0, 0.0]), np.array([[start, 0.0, 0.0]]), np.zeros(1))
        h = np.diff(times)
        if self.interpolation is Interpolation.LINEAR:
            initial = np.stack([values[:-1], np.diff(values) / h, np.zeros(h.size)], axis=1)
            return PiecewiseCubic(times, initial, np.zeros(h.size))
        if self.interpolation is Interpolation.VELOCITY:
            initial = np.stack([self.positions()[:-1], values[:-1], np.diff(values) / h], axis=1)
            return PiecewiseCubic(times, initial, np.zeros(h.size))
        from scipy.interpolate import CubicHermiteSpline, CubicSpline  # only the spline tables need it

        if self.interpolation is Interpolation.HERMITE:
            spline = CubicHermiteSpline(times, values, self.velocities)
        else:
            spline = CubicSpline(times, values, bc_type=((1, 0.0), (1, 0.0)))
        c = spline.c  # (4, n - 1), highest power first, about each interval's start
        initial = np.stack([c[3], c[2], 2.0 * c[1]], axis=1)
        return PiecewiseCubic(times, initial, 6.0 * c[0])


def divided_differences(times: np.ndarray, values: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """``order! * f[t_i, ..., t_{i+order}]`` for consecutive points, and the round-off weight of each.

    By the mean-value theorem each is the ``order``-th derivative of any smooth
    function through the points somewhere between them (a weighted mean of it
    for a piecewise-smooth one), so it is bounded by that derivative's limit.

    Parameters
    ----------
    times, values : ndarray, shape (n,)
    order : int
        1, 2 or 3.

    Returns
    -------
    ndarray, shape (n - order,)
        The scaled divided differences.
    ndarray, shape (n - order,)
        ``order! * sum_m 1 / prod_{l != m} |t_m - t_l|``: how much a round-off of
        1 in every value can move each difference.
    """
    table = np.asarray(values, dtype=float)
    for k in range(1, order + 1):
        table = (table[1:] - table[:-1]) / (times[k:] - times[:-k])
    weight = np.zeros(table.size)
    n = times.size - order
    for m in range(order + 1):
        product = np.ones(n)
        for other in range(order + 1):
            if other != m:
                product *= np.abs(times[m : m + n] - times[other : other + n])
        weight += 1.0 / product
    return math.factorial(order) * table, math.factorial(order) * weight


def _at_rest_both_ends(table: ProfileTable, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The table's points with ``count`` points of rest added before the start and after the end."""
    times, values = table.times, table.values
    rest_value = 0.0 if table.interpolation is Interpolation.VELOCITY else None
    first_step = times[1] - times[0] if times.size > 1 else 1.0
    last_step = times[-1] - times[-2] if times.size > 1 else 1.0
    before = times[0] - first_step * np.arange(count, 0, -1)
    after = times[-1] + last_step * np.arange(1, count + 1)
    head = np.full(count, values[0] if rest_value is None else rest_value)
    tail = np.full(count, values[-1] if rest_value is None else rest_value)
    return np.concatenate([before, times, after]), np.concatenate([head, values, tail])


@dataclass(frozen=True, slots=True)
class DifferenceCheck:
    """A limit checked from divided differences: the worst ratio and where it is."""

    quantity: str
    ratio: float
    time: float
    value: float
    limit: float
    allowed: float


def difference_checks(table: ProfileTable, limits, *, jerk: bool) -> list[DifferenceCheck]:
    """The limits a table's interpolation leaves undefined, from divided differences of its points."""
    checks = []
    defined = table.interpolation.closed_form
    if table.times.size < 2 or defined >= 3:
        return checks
    velocity_table = table.interpolation is Interpolation.VELOCITY
    wanted = [
        (quantity, derivative, getattr(limits, f"max_{quantity}"))
        for derivative, quantity in ((1, "velocity"), (2, "acceleration"), (3, "jerk"))
        if derivative > defined and (jerk or derivative < 3)
    ]
    for quantity, derivative, limit in wanted:
        order = derivative - (1 if velocity_table else 0)  # a velocity table's values are one derivative up
        times, values = _at_rest_both_ends(table, order)
        difference, weight = divided_differences(times, values, order)
        explained = table.round_off * weight  # what the values' round-off alone can make of it
        allowed = limit * (1.0 + RELATIVE_TOLERANCE) + explained
        excess = np.abs(difference) - allowed
        k = int(np.argmax(excess))
        middle = 0.5 * (times[k] + times[k + order])
        checks.append(
            DifferenceCheck(
                quantity,
                float(np.max(np.maximum(np.abs(difference) - explained, 0.0)) / limit),
                float(min(max(middle, 0.0), table.duration)),
                float(abs(difference[k])),
                float(limit),
                float(allowed[k]),
            )
        )
    return checks


def limit_ratios(tables: tuple[ProfileTable, ...], limits: Limits, *, jerk: bool = True) -> dict:
    """Largest |v|, |a|, |j| over each limit per vehicle as the controllers interpolate the tables.

    Closed form within the interpolated pieces; divided differences where the
    interpolation leaves a derivative undefined. Without round-off allowance:
    used to find how much a table must be slowed down to fit the limits.

    Returns
    -------
    dict
        ``{"velocity": (r1, r2, ...), "acceleration": (...), "jerk": (...) or None}``, one per table.
    """
    ratios: dict[str, list[float]] = {
        name: [0.0] * len(tables) for name in ("velocity", "acceleration", "jerk")
    }
    for vehicle, table in enumerate(tables):
        vehicle_limits = limits.vehicles[vehicle]
        motion = table.motion()
        peaks = _piece_peaks(motion)
        for name, order in (("velocity", 1), ("acceleration", 2), ("jerk", 3)):
            if order <= table.interpolation.closed_form:
                limit = getattr(vehicle_limits, f"max_{name}")
                ratios[name][vehicle] = peaks[order - 1] / limit
        for check in difference_checks(table, vehicle_limits, jerk=jerk):
            ratios[check.quantity][vehicle] = check.ratio
    return {
        "velocity": tuple(ratios["velocity"]),
        "acceleration": tuple(ratios["acceleration"]),
        "jerk": tuple(ratios["jerk"]) if jerk else None,
    }


def slowdown(ratios: dict) -> float:
    """The uniform slow-down that brings every ratio of :func:`limit_ratios` to at most 1.

    Running a motion ``s`` times slower divides velocity by ``s``, acceleration by ``s**2``
    and jerk by ``s**3``.
    """
    scale = 1.0
    for order, name in enumerate(("velocity", "acceleration", "jerk"), start=1):
        if ratios[name] is not None:
            scale = max(scale, max(ratios[name]) ** (1.0 / order))
    return scale


def _piece_peaks(motion: PiecewiseCubic) -> tuple[float, float, float]:
    """Largest |v|, |a|, |j| of a piecewise cubic, in closed form."""
    h = np.diff(motion.times)
    v0, a0, j = motion.initial[:, 1], motion.initial[:, 2], motion.jerk
    v1 = v0 + h * (a0 + 0.5 * h * j)
    a1 = a0 + h * j
    velocity = np.maximum(np.abs(v0), np.abs(v1))
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(j != 0.0, -a0 / j, -1.0)
    inside = (vertex > 0.0) & (vertex < h)
    velocity = np.where(
        inside, np.maximum(velocity, np.abs(v0 - 0.5 * a0 * a0 / np.where(j != 0, j, 1))), velocity
    )
    return (
        float(velocity.max(initial=0.0)),
        float(np.maximum(np.abs(a0), np.abs(a1)).max(initial=0.0)),
        float(np.abs(j[h > 0.0]).max(initial=0.0)),
    )
