"""Profile tables as a controller interpolates them, and their verification along a route.

A PLC does not play a schedule: it plays a table of points and interpolates
between them (linearly, by a cubic spline, or a velocity linearly in time).
:class:`ProfileTable` is one vehicle's table with the interpolation its
controller applies; :class:`TableMotion` turns the two tables into a
:class:`~trajgen.schedule.Schedule` along the route, so the independent
verifier (:mod:`trajgen.verify`) checks the separation, the track, the start
and goal and the homotopy class of exactly what the controllers will drive,
in closed form between the points too. What a table's interpolation leaves
undefined (the acceleration of a linear table, the jerk of a linear velocity
table) is checked from divided differences of its points
(:func:`divided_differences`), with rest before the first point and after the
last: for points sampled from any motion within the limits these never exceed
the limits (mean-value theorem), so a table that fails moves differently.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from limits import Limits
from topology import JUNCTION_INDEX, Option, Route
from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.paths import VehiclePath
from trajgen.profiles import PiecewiseCubic
from trajgen.schedule import AxisMap, CubicKinematics, Schedule, Section, TimingMethod
from trajgen.values import ArrayValue, readonly
from trajgen.verify import RELATIVE_TOLERANCE, VerificationReport, verify

__all__ = [
    "Interpolation",
    "ProfileTable",
    "TableCheck",
    "TableMotion",
    "check_tables",
    "divided_differences",
    "junction_crossings",
    "leg_visits",
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


def _difference_checks(table: ProfileTable, limits, *, jerk: bool) -> list[DifferenceCheck]:
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


def limit_ratios(tables: tuple[ProfileTable, ProfileTable], limits: Limits, *, jerk: bool = True) -> dict:
    """Largest |v|, |a|, |j| over each limit per vehicle as the controllers interpolate the tables.

    Closed form within the interpolated pieces; divided differences where the
    interpolation leaves a derivative undefined. Without round-off allowance:
    used to find how much a table must be slowed down to fit the limits.

    Returns
    -------
    dict
        ``{"velocity": (r1, r2), "acceleration": (r1, r2), "jerk": (r1, r2) or None}``.
    """
    ratios: dict[str, list[float]] = {"velocity": [0.0, 0.0], "acceleration": [0.0, 0.0], "jerk": [0.0, 0.0]}
    for vehicle, table in enumerate(tables):
        vehicle_limits = limits.vehicles[vehicle]
        motion = table.motion()
        peaks = _piece_peaks(motion)
        for name, order in (("velocity", 1), ("acceleration", 2), ("jerk", 3)):
            if order <= table.interpolation.closed_form:
                limit = getattr(vehicle_limits, f"max_{name}")
                ratios[name][vehicle] = peaks[order - 1] / limit
        for check in _difference_checks(table, vehicle_limits, jerk=jerk):
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


def leg_visits(route: Route, vehicle: int) -> tuple[int, ...]:
    """The legs ``vehicle`` drives on, in order, one entry per stay (it passes the junction between)."""
    path = VehiclePath.from_route(route, vehicle)
    if not path.legs:
        return (path.home[0],)
    visits = [path.legs[0]]
    for leg in path.legs[1:]:
        if leg != visits[-1]:
            visits.append(leg)
    return tuple(visits)


def _start(route: Route, vehicle: int) -> tuple[int, float]:
    first = route.indexed_waypoints[0]
    return int(first[2 * vehicle]), float(first[2 * vehicle + 1])


def junction_crossings(motion: PiecewiseCubic, junction: float) -> list[float]:
    """Times at which ``motion`` crosses the axis value ``junction`` (touching it is no crossing).

    Between consecutive piece ends and velocity zeros the motion is monotone, so each sign
    change of ``axis - junction`` there holds one crossing, found by bisection.
    """
    begin = motion.times[:-1]
    length = np.diff(motion.times)
    v0, a0, j = motion.initial[:, 1], motion.initial[:, 2], motion.jerk
    roots = []
    with np.errstate(divide="ignore", invalid="ignore"):  # v(h) = v0 + a0 h + j h^2 / 2 = 0
        root = np.sqrt(a0 * a0 - 2.0 * j * v0)
        roots += [(-a0 + root) / j, (-a0 - root) / j, -v0 / a0]
    candidates = [motion.times]
    for h in roots:
        inside = np.isfinite(h) & (h > 0.0) & (h < length)
        candidates.append(begin[inside] + h[inside])
    times = np.unique(np.concatenate(candidates))
    gap = motion.evaluate(times)[0] - junction
    sign = np.where(np.abs(gap) <= CROSSING_TOLERANCE, 0.0, np.sign(gap))
    nonzero = np.nonzero(sign)[0]
    flips = nonzero[1:][sign[nonzero[1:]] != sign[nonzero[:-1]]]
    crossings = []
    for k in flips:
        side = sign[nonzero[np.searchsorted(nonzero, k) - 1]]
        low, high = float(times[k - 1]), float(times[k])
        for _ in range(80):
            middle = 0.5 * (low + high)
            if np.sign(motion.evaluate(np.array([middle]))[0, 0] - junction) == side:
                low = middle
            else:
                high = middle
        crossings.append(0.5 * (low + high))
    return crossings


def _stays(
    route: Route, vehicle: int, table: ProfileTable, motion: PiecewiseCubic, orientation: int
) -> tuple[list[float], list[AxisMap], int]:
    """When each stay on a leg begins, its axis map, and the junction crossings beyond the route's.

    The axis is a line through the legs: ``s = s0 + orientation * (axis - axis0)`` on the first
    leg, and every time the axis passes the junction's value the vehicle goes on to the next leg
    its route visits, where ``s`` grows the other way round.
    """
    leg, s0 = _start(route, vehicle)
    axis0 = float(table.positions()[0])
    if not VehiclePath.from_route(route, vehicle).legs:  # its route does not move it
        return [0.0], [AxisMap.parked(axis0, leg, s0)], 0
    visits = leg_visits(route, vehicle)
    if leg == JUNCTION_INDEX:  # starts at the junction: the axis grows onto its first leg
        leg = visits[0]
    junction = axis0 - orientation * s0
    crossings = junction_crossings(motion, junction)
    starts = [0.0]
    maps = [
        AxisMap(
            np.array([axis0]), np.array([axis0]), np.array([leg]), np.array([s0]), np.array([orientation])
        )
    ]
    slope = orientation
    for n, time in enumerate(crossings[: len(visits) - 1], start=1):
        slope = -slope
        maps.append(
            AxisMap(
                np.array([junction]),
                np.array([junction]),
                np.array([visits[n]]),
                np.zeros(1),
                np.array([slope]),
            )
        )
        starts.append(time)
    return starts, maps, max(0, len(crossings) - (len(visits) - 1))


def _slice(profile: PiecewiseCubic, begin: float, end: float) -> PiecewiseCubic:
    """The part of ``profile`` from ``begin`` to ``end`` seconds, in local time (at rest past its end)."""
    inner = profile.times[(profile.times > begin) & (profile.times < end)]
    times = np.concatenate([[begin], inner, [end]])
    last = profile.duration
    k = np.clip(np.searchsorted(profile.times, times[:-1], side="right") - 1, 0, len(profile.jerk) - 1)
    h = np.minimum(times[:-1], last) - profile.times[k]
    p0, v0, a0, j = profile.initial[k, 0], profile.initial[k, 1], profile.initial[k, 2], profile.jerk[k]
    initial = np.stack(
        [p0 + h * (v0 + h * (a0 / 2.0 + h * j / 6.0)), v0 + h * (a0 + h * j / 2.0), a0 + h * j], axis=1
    )
    jerk = j.copy()
    ended = times[:-1] >= last
    if ended.any():
        end_position = profile.end_state()[0]
        initial[ended] = (end_position, 0.0, 0.0)
        jerk[ended] = 0.0
    return PiecewiseCubic(times - begin, initial, jerk)


@dataclass(frozen=True, slots=True)
class TableMotion(TimingMethod):
    """The motion two controllers drive from two profile tables, as a schedule along a route.

    Not a registered timing method: it times nothing, it reads what the tables
    say, so the verifier can check them like any schedule.

    Parameters
    ----------
    tables : tuple of 2 ProfileTable
        Vehicle 1's and vehicle 2's tables: each the signed axis of its vehicle.
    orientations : tuple of 2 int
        ``ds/d axis`` of each vehicle at its start: +1 if its axis grows away from
        the junction (the first move of a schedule is its axis's positive direction).
    jerk : bool
        Whether the tables are held to the jerk limits (default True).
    motions : tuple of 2 PiecewiseCubic, optional
        The tables' :meth:`ProfileTable.motion`, if already computed.
    """

    name: ClassVar[str] = "table"
    summary: ClassVar[str] = "the motion of two interpolated profile tables"

    tables: tuple[ProfileTable, ProfileTable]
    orientations: tuple[int, int] = (1, 1)
    jerk: bool = True
    motions: tuple[PiecewiseCubic, PiecewiseCubic] | None = field(default=None, compare=False, repr=False)

    @property
    def jerk_limited(self) -> bool:
        """Whether the tables are held to the jerk limits."""
        return self.jerk

    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """The tables' motion along ``route``: a section for each stay of either vehicle on a leg."""
        motions, stay_maps, stay_starts = [], [], []
        given = self.motions or tuple(table.motion() for table in self.tables)
        for vehicle, table in enumerate(self.tables):
            motion = given[vehicle]
            starts, maps, _ = _stays(route, vehicle, table, motion, self.orientations[vehicle])
            motions.append(motion)
            stay_starts.append(starts)
            stay_maps.append(maps)
        end = max(motion.duration for motion in motions)
        cuts = sorted({0.0, end, *stay_starts[0], *stay_starts[1]})
        cuts = [t for t in cuts if t <= end]
        sections = []
        for begin, finish in itertools.pairwise(cuts) if len(cuts) > 1 else [(0.0, 0.0)]:
            maps = []
            for vehicle in range(2):
                stay = int(np.searchsorted(stay_starts[vehicle], begin, side="right") - 1)
                maps.append(stay_maps[vehicle][stay])
            kinematics = CubicKinematics(tuple(_slice(m, begin, finish) for m in motions))
            sections.append(Section(begin, kinematics, tuple(maps)))
        smoothness = min(table.interpolation.smoothness for table in self.tables)
        return Schedule(
            route,
            limits,
            self,
            tuple(sections),
            jerk_limited=self.jerk,
            continuity=smoothness,
            end_tolerance=max(END_TOLERANCES[table.interpolation] for table in self.tables),
            checked_limits=min(table.interpolation.closed_form for table in self.tables),
        )


@dataclass(frozen=True, slots=True)
class TableCheck:
    """The verdict on two profile tables along a route.

    Attributes
    ----------
    passed : bool
    failures : tuple of str
        Each names the time, the quantity, its value and its limit.
    report : VerificationReport
        The verifier's report on the tables' motion (separation, track, start
        and goal, homotopy class, closed-form limits).
    ratios : dict
        Worst |v|, |a|, |j| over each limit per vehicle (:func:`limit_ratios`).
    route : Route
        The route the tables were read along.
    schedule : Schedule or None
        The tables' motion along it, as verified (None if they could not be read along it).
    """

    passed: bool
    failures: tuple[str, ...]
    report: VerificationReport
    ratios: dict
    route: Route
    schedule: Schedule | None = None

    def summary(self) -> dict:
        """JSON-ready verdict."""
        return {
            "passed": self.passed,
            "failures": list(self.failures),
            "min_separation_m": self.report.min_separation,
            "ratios": {k: (list(v) if v is not None else None) for k, v in self.ratios.items()},
            "homotopy": self.route.homotopy.value,
        }


#: A drive that ramps through a linear table's velocity step at its acceleration limit leaves the
#: table by ``step**2 / (8 * max_acceleration)`` at most; this is the most allowed, metres.
TRACKING_TOLERANCE = 1e-3


def _velocity_steps(table: ProfileTable, vehicle: int, max_acceleration: float) -> list[str]:
    """A linear table's velocity steps at its points (rest before and after), if a drive cannot follow.

    The controller's velocity jumps at each point of a linear table; a drive
    ramping through the step at ``max_acceleration``, centred on the point,
    departs from the table by ``step**2 / (8 * max_acceleration)``.
    """
    if table.interpolation is not Interpolation.LINEAR or table.times.size < 2:
        return []
    velocity = np.diff(table.values) / np.diff(table.times)
    steps = np.abs(np.diff(np.concatenate([[0.0], velocity, [0.0]])))
    departure = steps**2 / (8.0 * max_acceleration)
    k = int(np.argmax(departure))
    if departure[k] <= TRACKING_TOLERANCE:
        return []
    return [
        f"vehicle {vehicle + 1} velocity steps by {steps[k]:.6g} m/s at t={table.times[k]:.6f} s: a drive "
        f"ramping at its max_acceleration {max_acceleration:g} m/s^2 would leave the table by "
        f"{1e3 * departure[k]:.3g} mm, expected at most {1e3 * TRACKING_TOLERANCE:g} mm (more points)"
    ]


def _first_move(table: ProfileTable, vehicle: int) -> list[str]:
    """The axis must grow in the direction of the first move (the convention of the files)."""
    steps = np.diff(table.positions())
    moving = np.nonzero(np.abs(steps) > CROSSING_TOLERANCE)[0]
    if moving.size and steps[moving[0]] < 0.0:
        k = int(moving[0])
        return [
            f"vehicle {vehicle + 1}'s axis first moves backwards (at t={table.times[k]:.6f} s): expected "
            "it to grow in the direction of the first move"
        ]
    return []


def _orientations(route: Route) -> list[tuple[int, int]]:
    """Both vehicles' start orientations to try: the route's first moves first."""
    first = []
    for vehicle in range(2):
        path = VehiclePath.from_route(route, vehicle)
        first.append(1 if not path.legs or path.s_to[0] > path.s_from[0] else -1)
    return [(first[0] * a, first[1] * b) for a, b in ((1, 1), (-1, 1), (1, -1), (-1, -1))]


def check_tables(
    tables: tuple[ProfileTable, ProfileTable], route: Route, limits: Limits, *, jerk: bool = True
) -> TableCheck:
    """Verify two profile tables as their controllers interpolate them, along ``route``.

    Parameters
    ----------
    tables : tuple of 2 ProfileTable
    route : Route
        The route the tables follow (its homotopy class is checked).
    limits : Limits
    jerk : bool, optional
        Hold the tables to the jerk limits (default True).

    Returns
    -------
    TableCheck
    """
    if len(tables) != 2 or not all(isinstance(table, ProfileTable) for table in tables):
        raise InputError(f"check_tables expects two ProfileTables, got {short_repr(tables)}")
    failures: list[str] = []
    for vehicle, table in enumerate(tables):
        bad = table.decreasing_times()
        if bad.size:
            k = int(bad[0])
            failures.append(
                f"vehicle {vehicle + 1} time {table.times[k]:.9g} s at point {k + 1} does not increase "
                f"(previous {table.times[k - 1]:.9g} s)"
            )
    if failures:
        report = VerificationReport.failed(tuple(failures))
        return TableCheck(False, tuple(failures), report, {}, route)
    units = {"velocity": "m/s", "acceleration": "m/s^2", "jerk": "m/s^3"}
    for vehicle, table in enumerate(tables):
        failures += _first_move(table, vehicle)
        for check in _difference_checks(table, limits.vehicles[vehicle], jerk=jerk):
            if check.value > check.allowed:
                unit = units[check.quantity]
                failures.append(
                    f"vehicle {vehicle + 1} {check.quantity} reaches {check.value:.9g} {unit} at "
                    f"t={check.time:.6f} s exceeds its max_{check.quantity} {check.limit:g} {unit} "
                    "(from the table's points)"
                )
        failures += _velocity_steps(table, vehicle, limits.vehicles[vehicle].max_acceleration)
    motions = tuple(table.motion() for table in tables)
    # the files do not say which way along its leg each vehicle's axis grows: read both ways
    verdicts = []
    for orientations in _orientations(route):
        found = []
        for vehicle, table in enumerate(tables):
            *_, extra = _stays(route, vehicle, table, motions[vehicle], orientations[vehicle])
            if extra:
                found.append(
                    f"vehicle {vehicle + 1} passes the junction {extra} more time(s) than its route does"
                )
        schedule = TableMotion(tables, orientations, jerk=jerk, motions=motions).schedule(route, limits)
        report = verify(schedule)
        verdicts.append((found + list(report.failures), report, schedule))
        if not verdicts[-1][0]:
            break
    found, report, schedule = min(verdicts, key=lambda verdict: len(verdict[0]))
    failures += found
    ratios = limit_ratios(tables, limits, jerk=jerk)
    return TableCheck(not failures, tuple(failures), report, ratios, route, schedule)
