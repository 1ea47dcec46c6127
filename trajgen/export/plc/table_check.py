"""Profile tables read along the route as a schedule, and verified as the controllers will drive them.

:class:`TableMotion` turns the two vehicles' :class:`~trajgen.export.plc.tables.ProfileTable` into a
:class:`~trajgen.model.schedule.Schedule` along the route, so the independent verifier
(:mod:`trajgen.verification`) checks the separation, the track, the start and goal and the homotopy class
of exactly what the controllers will drive, in closed form between the points too;
:func:`check_tables` adds the limits from divided differences and returns a :class:`TableCheck`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import JUNCTION_INDEX, GraphRoute, Route
from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.export.plc.row_separation import row_separation
from trajgen.export.plc.tables import (
    CROSSING_TOLERANCE,
    END_TOLERANCES,
    Interpolation,
    ProfileTable,
    difference_checks,
    limit_ratios,
)
from trajgen.model.graph_paths import GraphPath, graph_paths
from trajgen.model.graph_schedule import GraphSchedule, GraphSection
from trajgen.model.paths import VehiclePath
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import AxisMap, CubicKinematics, Schedule, Section, TimingMethod
from trajgen.model.summary import graph_class_label
from trajgen.model.values import sorted_unique
from trajgen.verification import VerificationReport, verify

__all__ = [
    "TableCheck",
    "TableMotion",
    "check_tables",
    "graph_travel",
    "junction_crossings",
    "leg_visits",
    "turning_points",
]


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
    times = _monotone_times(motion)
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


def _slice(
    profile: PiecewiseCubic, begin: float, end: float, cuts: np.ndarray | None = None
) -> PiecewiseCubic:
    """The part of ``profile`` from ``begin`` to ``end`` seconds, in local time (at rest past its end).

    ``cuts``: more times (seconds) at which a piece ends.
    """
    knots = profile.times if cuts is None else sorted_unique(np.concatenate([profile.times, cuts]))
    inner = knots[(knots > begin) & (knots < end)]
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


def _monotone_times(motion: PiecewiseCubic) -> np.ndarray:
    """The piece ends and velocity zeros of ``motion``: it is monotone between consecutive ones."""
    begin = motion.times[:-1]
    length = np.diff(motion.times)
    v0, a0, j = motion.initial[:, 1], motion.initial[:, 2], motion.jerk
    candidates = [motion.times]
    with np.errstate(divide="ignore", invalid="ignore"):  # v(h) = v0 + a0 h + j h^2 / 2 = 0
        root = np.sqrt(a0 * a0 - 2.0 * j * v0)
        for h in ((-a0 + root) / j, (-a0 - root) / j, -v0 / a0):
            inside = np.isfinite(h) & (h > 0.0) & (h < length)
            candidates.append(begin[inside] + h[inside])
    return sorted_unique(np.concatenate(candidates))


def turning_points(
    motion: PiecewiseCubic, tolerance: float, *, expected: np.ndarray | None = None, fine: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and axis values (m) where ``motion`` turns back, once it has gone back ``tolerance``.

    The first move is the axis's positive direction (the convention of the files). A turn is
    where the axis is furthest before it comes back by more than ``tolerance`` metres, so a
    wiggle at rest no larger than the table's round-off is no turn.

    Parameters
    ----------
    motion : PiecewiseCubic
    tolerance : float
        How far back the axis must come to turn, metres.
    expected : ndarray, shape (r,), optional
        The axis values where the path turns, in order. Within ``tolerance`` of the next of them
        a turn counts once the axis has come back ``fine`` metres (a path may back off by less
        than ``tolerance``); elsewhere an interpolation's overshoot at a stop between two rows,
        within ``tolerance``, is no turn.
    fine : float, optional
        The tolerance near the expected turns, metres (``tolerance`` if not given).
    """
    expected = np.empty(0) if expected is None else np.asarray(expected, dtype=float)
    fine = tolerance if fine is None else fine
    times = _monotone_times(motion)
    axis = motion.evaluate(times)[0]
    direction, furthest, where = 1.0, float(axis[0]), 0
    turns: list[int] = []
    for k in range(1, axis.size):
        x = float(axis[k])
        if (x - furthest) * direction > 0.0:
            furthest, where = x, k
            continue
        near = len(turns) < expected.size and abs(furthest - expected[len(turns)]) <= tolerance
        if (furthest - x) * direction > (fine if near else tolerance):
            turns.append(where)
            direction, furthest, where = -direction, x, k
    index = np.array(turns, dtype=int)
    return times[index], axis[index]


def graph_travel(
    motion: PiecewiseCubic, tolerance: float, path: GraphPath | None = None, *, fine: float | None = None
) -> tuple[PiecewiseCubic, np.ndarray]:
    """The metres a vehicle has driven (its travel) under an axis ``motion``, and the travel at each turn.

    Between turns (:func:`turning_points`) the travel is the axis, signed by the direction of
    that stretch, so it grows while the vehicle drives either way. With ``path``, whose cusps the
    turns are matched to (as many), each stretch after a turn is placed by the path's own axis: a
    table that turns a little short of or beyond the path's cusp (within its tolerance) is where
    its axis says after the turn, not off by twice that.

    Returns
    -------
    PiecewiseCubic
        The travel over the motion's time, with a piece end at each turn.
    ndarray, shape (r,)
        The travel at each turn, metres, as the table's own axis gives it.
    """
    start = float(motion.initial[0, 0]) if motion.jerk.size else 0.0
    expected = None if path is None else start + path.axis(path.cusps)
    turn_times, turn_axis = turning_points(motion, tolerance, expected=expected, fine=fine)
    whole = _slice(motion, 0.0, motion.duration, turn_times)
    run = np.searchsorted(turn_times, whole.times[:-1], side="right")
    signs = np.where(np.arange(turn_times.size + 1) % 2 == 0, 1.0, -1.0)
    anchors = np.concatenate([[start], turn_axis])
    travel_at = np.concatenate([[0.0], np.cumsum(signs[:-1] * np.diff(anchors))])
    turns = travel_at[1:].copy()
    if path is not None and path.cusps.size == turn_times.size:
        travel_at[1:] = path.cusps
        anchors[1:] = start + path.axis(path.cusps)
    sign = signs[run]
    initial = sign[:, None] * whole.initial
    initial[:, 0] += travel_at[run] - sign * anchors[run]
    return PiecewiseCubic(whole.times, initial, sign * whole.jerk), turns


def _turn_failures(turns: np.ndarray, path: GraphPath, vehicle: int, tolerance: float) -> list[str]:
    """A table turns back exactly where its path does: as often, at the same travel."""
    who = f"vehicle {vehicle + 1}"
    cusps = path.cusps
    if turns.size != cusps.size:
        where = ", ".join(f"{p:.6g}" for p in turns[:5]) or "nowhere"
        return [
            f"{who}'s table turns back {turns.size} time(s) (at {where} m of travel): expected "
            f"{cusps.size}, where its path turns back"
            + (f" (at {', '.join(f'{p:.6g}' for p in cusps[:5])} m)" if cusps.size else "")
        ]
    off = np.abs(turns - cusps)
    if off.size and off.max() > tolerance:
        k = int(np.argmax(off))
        return [
            f"{who}'s table turns back at {turns[k]:.9g} m of travel: expected {cusps[k]:.9g} m, where its "
            "path turns back"
        ]
    return []


@dataclass(frozen=True, slots=True)
class TableMotion(TimingMethod):
    """The motion two controllers drive from two profile tables, as a schedule along a route.

    Not a registered timing method: it times nothing, it reads what the tables
    say, so the verifier can check them like any schedule.

    Parameters
    ----------
    tables : tuple of ProfileTable
        One per vehicle: each the signed axis of its vehicle.
    orientations : tuple of int
        ``ds/d axis`` of each vehicle at its start: +1 if its axis grows away from
        the junction (the first move of a schedule is its axis's positive direction).
    jerk : bool
        Whether the tables are held to the jerk limits (default True).
    motions : tuple of PiecewiseCubic, optional
        The tables' :meth:`ProfileTable.motion`, if already computed.
    """

    name: ClassVar[str] = "table"
    summary: ClassVar[str] = "the motion of two interpolated profile tables"

    tables: tuple[ProfileTable, ...]
    orientations: tuple[int, int] = (1, 1)
    jerk: bool = True
    motions: tuple[PiecewiseCubic, ...] | None = field(default=None, compare=False, repr=False)

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
        return Schedule(route, limits, self, tuple(sections), jerk_limited=self.jerk, **self._read_back())

    def _read_back(self) -> dict:
        """What a table read back is held to: its interpolation's smoothness, tolerances and limits."""
        return {
            "smoothness": min(table.interpolation.smoothness for table in self.tables),
            "end_tolerance": max(END_TOLERANCES[table.interpolation] for table in self.tables),
            "checked_limits": min(table.interpolation.closed_form for table in self.tables),
        }

    def turn_tolerances(self, paths: tuple[GraphPath, GraphPath]) -> tuple[tuple[float, float], ...]:
        """How far back each table must come to count as turning, metres: ``(tolerance, fine)``.

        ``tolerance``: the interpolation's, and more than the values' round-off; a wiggle within
        it (an interpolation's overshoot at a stop between two rows) is no turn. ``fine``, near
        where the path turns: less than half of the shortest stretch between its path's turns (a
        vehicle that backs off a micrometre turns twice in a micrometre), and more than the
        round-off (a turn of one unit of a nanometre file's last decimal counts).
        """
        tolerance = self._read_back()["end_tolerance"]
        out = []
        for table, path in zip(self.tables, paths, strict=True):
            runs = np.diff(np.concatenate([[0.0], path.cusps, [path.length]]))
            shortest = float(runs.min()) if path.cusps.size else math.inf
            fine = max(min(tolerance, 0.5 * shortest), table.round_off)
            out.append((max(tolerance, table.round_off), fine))
        return tuple(out)

    def schedule_graph(self, route: GraphRoute, limits: Limits) -> GraphSchedule:
        """The tables' motion along a route on a track graph: each vehicle's travel along its path.

        The axis of a table turns back where its path does (checked by :func:`check_tables`);
        between turns its travel is the axis, signed by the stretch's direction.
        """
        given = self.motions or tuple(table.motion() for table in self.tables)
        paths = graph_paths(route)
        tolerances = self.turn_tolerances(paths)
        travels = [
            graph_travel(motion, tolerances[v][0], paths[v], fine=tolerances[v][1])[0]
            for v, motion in enumerate(given)
        ]
        end = max(travel.duration for travel in travels)
        kinematics = CubicKinematics(tuple(_slice(travel, 0.0, end) for travel in travels))
        return GraphSchedule(
            route,
            limits,
            self,
            paths,
            (GraphSection(0.0, kinematics),),
            jerk_limited=self.jerk,
            **self._read_back(),
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
    route : Route or GraphRoute
        The route the tables were read along.
    schedule : Schedule, GraphSchedule or None
        The tables' motion along it, as verified (None if they could not be read along it).
    """

    passed: bool
    failures: tuple[str, ...]
    report: VerificationReport
    ratios: dict
    route: Route | GraphRoute
    schedule: Schedule | GraphSchedule | None = None

    def summary(self) -> dict:
        """JSON-ready verdict (``homotopy`` on a junction; on a track graph ``class``, the moves)."""
        if isinstance(self.route, GraphRoute):
            where = {"class": graph_class_label(self.route)}
        else:
            where = {"homotopy": self.route.homotopy.value}
        return {
            "passed": self.passed,
            "failures": list(self.failures),
            "min_separation_m": self.report.min_separation,
            "ratios": {k: (list(v) if v is not None else None) for k, v in self.ratios.items()},
            **where,
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
    """The axis must grow in the direction of the first move (the convention of the files).

    A step of one unit of a nanometre file's last decimal is a move (a back-off of a nanometre or
    two before a long move the other way is the first move).
    """
    steps = np.diff(table.positions())
    moving = np.nonzero(np.abs(steps) > min(CROSSING_TOLERANCE, table.round_off))[0]
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


def _check_graph_tables(
    tables: tuple[ProfileTable, ...],
    motions: tuple[PiecewiseCubic, ...],
    route: GraphRoute,
    limits: Limits,
    *,
    jerk: bool,
    failures: list[str],
) -> TableCheck:
    """:func:`check_tables` along a route on a track graph: the axes turn back where the paths do."""
    method = TableMotion(tables, jerk=jerk, motions=motions)
    schedule = method.schedule_graph(route, limits)
    tolerance = max(schedule.end_tolerance, 1e-6)
    turn_tolerances = method.turn_tolerances(schedule.paths)
    for vehicle, motion in enumerate(motions):
        coarse, fine = turn_tolerances[vehicle]
        turns = graph_travel(motion, coarse, schedule.paths[vehicle], fine=fine)[1]
        failures += _turn_failures(turns, schedule.paths[vehicle], vehicle, tolerance)
    report = verify(schedule)
    failures += list(report.failures)
    failures += row_separation(tables, schedule)
    ratios = limit_ratios(tables, limits, jerk=jerk)
    return TableCheck(not failures, tuple(failures), report, ratios, route, schedule)


def check_tables(
    tables: tuple[ProfileTable, ...], route: Route | GraphRoute, limits: Limits, *, jerk: bool = True
) -> TableCheck:
    """Verify profile tables, one per vehicle, as their controllers interpolate them, along ``route``.

    Parameters
    ----------
    tables : tuple of ProfileTable
        One per vehicle.
    route : Route or GraphRoute
        The route the tables follow (its homotopy class is checked; on a track graph, its
        class: which vehicle passes first at each conflict, and each vehicle's path).
    limits : Limits
    jerk : bool, optional
        Hold the tables to the jerk limits (default True).

    Returns
    -------
    TableCheck
    """
    if len(tables) != limits.count or not all(isinstance(table, ProfileTable) for table in tables):
        raise InputError(
            f"check_tables expects {limits.count} ProfileTables, one per vehicle, got {short_repr(tables)}"
        )
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
        report = VerificationReport.failed(tuple(failures), count=len(tables))
        return TableCheck(False, tuple(failures), report, {}, route)
    units = {"velocity": "m/s", "acceleration": "m/s^2", "jerk": "m/s^3"}
    for vehicle, table in enumerate(tables):
        failures += _first_move(table, vehicle)
        for check in difference_checks(table, limits.vehicles[vehicle], jerk=jerk):
            if check.value > check.allowed:
                unit = units[check.quantity]
                failures.append(
                    f"vehicle {vehicle + 1} {check.quantity} reaches {check.value:.9g} {unit} at "
                    f"t={check.time:.6f} s exceeds its max_{check.quantity} {check.limit:g} {unit} "
                    "(from the table's points)"
                )
        failures += _velocity_steps(table, vehicle, limits.vehicles[vehicle].max_acceleration)
    motions = tuple(table.motion() for table in tables)
    if isinstance(route, GraphRoute):
        return _check_graph_tables(tables, motions, route, limits, jerk=jerk, failures=failures)
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
