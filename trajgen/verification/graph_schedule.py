"""The verifier of schedules on a track graph: every check in closed form, between samples too.

Independent of how the schedule was computed and of the planner's code. The schedule is cut into
polynomial pieces: at every knot of either vehicle's travel and wherever a vehicle passes from one
segment of its path to the next. On a piece each vehicle's travel is one cubic and each vehicle is on
one edge, so its metres ``s`` from the edge's ``from`` node are a cubic too, and the track distance
between two vehicles is the least of at most five of them: through each pair of edge ends (the node
distances from this package's own Dijkstra, :class:`~trajgen.verification.graph_route.TrackDistances`)
and, on one edge, ``|s1 - s2|``. Their minima are taken in closed form
(:func:`~trajgen.model.polynomials.extrema`); nothing is sampled. Every pair of vehicles is checked: a
schedule may move any number.

Checked: the paths follow the route's moves from its start to its goal, travel starts at 0 and ends at
each path's length at rest, never runs backwards, the vehicles are at rest where a path turns back,
position, velocity (and acceleration when jerk-limited) are continuous, velocity, acceleration (and
jerk) stay within the limits, the separation holds, the schedule passes every conflict in the route's
order (its class, :mod:`~trajgen.verification.graph_class`), and a plan for execution obeys the
braking rule (:mod:`~trajgen.verification.braking_rule`). Before any of it, the schedule's own numbers
(:mod:`~trajgen.verification.integrity`: finite, knots increasing, sections tiling time). A failure's
details name the arrays it lies in (``sections[1].kinematics.vehicles[0].{times,initial,jerk}
interval 3, paths[0].{edges,s_from,s_to,starts}[2]``), as on a junction.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from topology import EdgePoint
from trajgen.model import polynomials
from trajgen.model.blended import ToppraKinematics
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import UncheckableKinematicsError, kinematics_polynomials, split_at_values
from trajgen.model.schedule import CubicKinematics
from trajgen.verification.braking_rule import braking_rule_failures, for_execution
from trajgen.verification.graph_class import check_class
from trajgen.verification.graph_route import TrackDistances
from trajgen.verification.integrity import array_failures, count_failures
from trajgen.verification.piecewise import allowance, continuity_allowance, time_resolution
from trajgen.verification.report import (
    POSITION_TOLERANCE,
    REST_TOLERANCE,
    TRACK_END_TOLERANCE,
    Finding,
    VerificationReport,
)

__all__ = ["place", "verify_graph_schedule"]

#: Pieces whose separation is computed at once (the memory of a table read back stays bounded).
_BLOCK = 1 << 15


class _Pieces:
    """The schedule's polynomial pieces: travel and segment of each vehicle on each."""

    def __init__(self, schedule: GraphSchedule) -> None:
        parts = []
        for number, section in enumerate(schedule.sections):
            times, travel, intervals = kinematics_polynomials(section.kinematics)
            # rows: each vehicle's knot interval, and the section (for the findings' arrays)
            origin = np.vstack([intervals, np.full((1, intervals.shape[1]), number)])
            parts.append((section.start_time + times[:-1], np.diff(times), travel, origin))
        bounds = tuple(path.starts[1:-1] for path in schedule.paths)
        ends = np.concatenate([p[0] for p in parts] + [[parts[-1][0][-1] + parts[-1][1][-1]]])
        travel = np.concatenate([p[2] for p in parts], axis=1)
        origin = np.concatenate([p[3] for p in parts], axis=1)
        start, length, travel, origin = split_at_values(
            ends, travel, origin, bounds, margin=POSITION_TOLERANCE
        )
        keep = length > 0.0
        if not keep.any():  # nothing moves: one piece of no time at the start
            start, length, travel, origin = np.zeros(1), np.zeros(1), travel[:, :1], origin[:, :1]
        else:
            start, length, travel, origin = start[keep], length[keep], travel[:, keep], origin[:, keep]
        self.start, self.length, self.travel = start, length, travel
        self.interval, self.section = origin[:-1], origin[-1]
        middle = np.stack([polynomials.evaluate(travel[v], 0.5 * length) for v in range(len(travel))])
        self.segment = np.stack(
            [
                np.clip(
                    np.searchsorted(path.starts, middle[v], side="right") - 1, 0, max(path.edges.size - 1, 0)
                )
                for v, path in enumerate(schedule.paths)
            ]
        )
        # a piece shorter than the time's round-off holds the numbers of the piece before: its segment too
        sliver = np.nonzero(length <= time_resolution(schedule))[0]
        for k in sliver[sliver > 0]:
            self.segment[:, k] = self.segment[:, k - 1]

    @property
    def count(self) -> int:
        return int(self.length.size)

    def arrays(self, schedule: GraphSchedule, k: int, vehicles: tuple[int, ...] | None = None) -> str:
        """The arrays that define piece ``k`` of the given vehicles (all: ``None``), by their paths."""
        section = int(self.section[k])
        if vehicles is None:
            vehicles = tuple(range(len(schedule.paths)))
        kinematics = schedule.sections[section].kinematics
        named = []
        for vehicle in vehicles:
            if type(kinematics) is ToppraKinematics:
                motion = f"sections[{section}].kinematics.{{grid,speed,times}}"
            else:
                motion = f"sections[{section}].kinematics.vehicles[{vehicle}].{{times,initial,jerk}}"
            named.append(
                f"{motion} interval {int(self.interval[vehicle, k])}, "
                f"paths[{vehicle}].{{edges,s_from,s_to,starts}}[{int(self.segment[vehicle, k])}]"
            )
        return "; ".join(named)

    def at(self, t: float) -> int:
        """The piece at time ``t`` (seconds)."""
        return int(np.clip(np.searchsorted(self.start, t, side="right") - 1, 0, self.count - 1))


def _track_polynomials(schedule: GraphSchedule, pieces: _Pieces) -> tuple[np.ndarray, np.ndarray]:
    """Edge (V, n) and metres from its ``from`` node as polynomials (V, n, DEGREE + 1) on each piece."""
    edges = np.zeros((len(schedule.paths), pieces.count), dtype=int)
    s = np.zeros_like(pieces.travel)
    for vehicle, path in enumerate(schedule.paths):
        if path.edges.size == 0:
            edges[vehicle] = path.home.edge
            s[vehicle, :, 0] = path.home.s
            continue
        k = pieces.segment[vehicle]
        direction = np.sign(path.s_to[k] - path.s_from[k])
        edges[vehicle] = path.edges[k]
        s[vehicle] = direction[:, None] * pieces.travel[vehicle]
        s[vehicle, :, 0] += path.s_from[k] - direction * path.starts[k]
    return edges, s


def place(schedule: GraphSchedule, vehicle: int, time: float) -> str:
    """Where ``vehicle`` is at ``time`` (seconds), in words: ``on edge 'c', 1.530 m from 'J2'``."""
    state = schedule.state([time])
    edge = schedule.track.edges[int(state.edge[vehicle, 0])]
    return f"on edge {edge.name!r}, {float(state.s[vehicle, 0]):.3f} m from {edge.start!r}"


def _check_paths(schedule: GraphSchedule, distances: TrackDistances, failures: list[str]) -> None:
    """Each path follows its vehicle's moves of the route, from the route's start to its goal."""
    route, track = schedule.route, schedule.track
    for vehicle, path in enumerate(schedule.paths):
        who, arrays = f"vehicle {vehicle + 1}", f"paths[{vehicle}]"
        broken = [
            (name, int(np.flatnonzero(~np.isfinite(values))[0]))
            for name in ("s_from", "s_to", "starts")
            if not np.all(np.isfinite(values := getattr(path, name)))
        ]
        if broken:
            name, k = broken[0]
            failures.append(
                Finding(
                    f"{who}'s path holds a non-finite number: expected finite metres",
                    f"{arrays}.{name}[{k}] is {getattr(path, name)[k]!r}",
                )
            )
            continue
        m = path.edges.size
        if path.starts.size != m + 1 or path.headings.size != m or path.s_from.size != m:
            failures.append(
                Finding(
                    f"{who}'s path has {m} edges but {path.starts.size} travel marks: expected {m + 1}",
                    f"{arrays}.{{edges,starts,headings,s_from}}",
                )
            )
            continue

        def point(k: int, end: bool, path=path) -> EdgePoint:
            return EdgePoint(int(path.edges[k]), float(path.s_to[k] if end else path.s_from[k]))

        for k in range(m):
            edge = int(path.edges[k])
            if not 0 <= edge < len(track.edges):
                failures.append(
                    Finding(
                        f"{who}'s path runs on edge number {edge}: the track has {len(track.edges)}",
                        f"{arrays}.edges[{k}]",
                    )
                )
                return
            low, high = sorted((path.s_from[k], path.s_to[k]))
            if low < -TRACK_END_TOLERANCE or high > distances.lengths[edge] + TRACK_END_TOLERANCE:
                failures.append(
                    Finding(
                        f"{who}'s path leaves edge {track.edges[edge].name!r} ({low:g} to {high:g} m of "
                        f"{distances.lengths[edge]:g} m)",
                        f"{arrays}.{{s_from,s_to}}[{k}]",
                    )
                )
            if abs((high - low) - (path.starts[k + 1] - path.starts[k])) > POSITION_TOLERANCE:
                failures.append(
                    Finding(
                        f"{who}'s path segment {k + 1} is {high - low:g} m long but counts "
                        f"{path.starts[k + 1] - path.starts[k]:g} m of travel",
                        f"{arrays}.{{s_from,s_to}}[{k}], {arrays}.starts[{k}:{k + 2}]",
                    )
                )
            if k and distances.between(point(k - 1, True), point(k, False)) > POSITION_TOLERANCE:
                failures.append(
                    Finding(
                        f"{who}'s path jumps between its segments {k} and {k + 1}",
                        f"{arrays}.{{edges,s_from,s_to}}[{k - 1}:{k + 1}]",
                    )
                )
            if k:
                turns = (
                    edge == int(path.edges[k - 1])
                    and (path.s_to[k] - path.s_from[k]) * (path.s_to[k - 1] - path.s_from[k - 1]) < 0.0
                )
                if (path.headings[k] != path.headings[k - 1]) != turns:
                    failures.append(
                        Finding(
                            f"{who}'s path {'turns back' if turns else 'goes on'} after its segment {k} but "
                            f"its heading {'does not flip' if turns else 'flips'} there",
                            f"{arrays}.headings[{k - 1}:{k + 1}]",
                        )
                    )
        start = point(0, False) if m else path.home
        goal = point(m - 1, True) if m else path.home
        for what, here, expected, k in (
            ("start", start, route.start[vehicle], 0),
            ("goal", goal, route.goal[vehicle], max(m - 1, 0)),
        ):
            off = distances.between(here, expected)
            if off > POSITION_TOLERANCE:
                failures.append(
                    Finding(
                        f"{who}'s path {what} is {off:.3g} m off the route's {track.name(expected)}",
                        f"{arrays}.{{edges,s_from,s_to}}[{k}]" if m else f"{arrays}.home",
                    )
                )
        if abs(path.length - route.travel[vehicle]) > POSITION_TOLERANCE * max(1.0, route.travel[vehicle]):
            failures.append(
                Finding(
                    f"{who}'s path is {path.length:g} m long: the route moves it {route.travel[vehicle]:g} m",
                    f"{arrays}.starts[{m}]",
                )
            )
        travel = 0.0
        for number, move in enumerate(route.moves):
            if move.vehicle != vehicle:
                continue
            for (a, b), edge in zip(itertools.pairwise(move.points), move.edges, strict=True):
                reached = travel + abs(distances.along(b, edge) - distances.along(a, edge))
                edge, s = path.locate(reached)
                off = distances.between(EdgePoint(int(edge[0]), float(s[0])), b)
                if off > 1e3 * POSITION_TOLERANCE:
                    failures.append(
                        Finding(
                            f"{who}'s path is {off:.3g} m off move {number + 1}'s point {track.name(b)} "
                            f"after {reached:g} m of travel",
                            f"{arrays}.{{edges,s_from,s_to}}[{int(path.segment(reached)[0])}]",
                        )
                    )
                    return
                travel = reached


def _check_motion(schedule: GraphSchedule, pieces: _Pieces, failures: list[str]) -> tuple[list, float, float]:
    """Ends at rest, travel forward only, continuity, limits (closed form): worst ratios, end errors."""
    names = [("velocity", "max_velocity", "m/s"), ("acceleration", "max_acceleration", "m/s^2")]
    if schedule.jerk_limited:
        names.append(("jerk", "max_jerk", "m/s^3"))
    count = len(schedule.paths)
    ratios: list = [[0.0] * count, [0.0] * count, [0.0] * count if schedule.jerk_limited else None]
    if schedule.checked_limits is not None:  # a table read back: the rest is checked from its points
        names = names[: schedule.checked_limits]
    end_tolerance = POSITION_TOLERANCE if schedule.end_tolerance is None else schedule.end_tolerance
    past_end = max(TRACK_END_TOLERANCE, schedule.end_tolerance or 0.0)
    start_error = goal_error = 0.0
    h = pieces.length
    for vehicle, path in enumerate(schedule.paths):
        who = f"vehicle {vehicle + 1}"
        c = pieces.travel[vehicle]
        low, _, high, _ = polynomials.extrema(c, h)
        first, last = float(c[0, 0]), float(polynomials.evaluate(c[-1:], h[-1:])[0])
        start_error = max(start_error, abs(first))
        goal_error = max(goal_error, abs(last - path.length))
        if abs(first) > end_tolerance or abs(last - path.length) > end_tolerance:
            k = 0 if abs(first) > end_tolerance else pieces.count - 1
            failures.append(
                Finding(
                    f"{who}'s travel runs from {first:.9g} m to {last:.9g} m: expected 0 to its path's "
                    f"{path.length:.9g} m",
                    pieces.arrays(schedule, k, (vehicle,)),
                )
            )
        outside = np.nonzero((low < -past_end) | (high > path.length + past_end))[0]
        if outside.size:
            k = int(outside[0])
            failures.append(
                Finding(
                    f"{who}'s travel leaves 0 to {path.length:g} m from t={pieces.start[k]:.6f} s",
                    pieces.arrays(schedule, k, (vehicle,)),
                )
            )
        derivatives = [c]
        for _ in range(3):
            derivatives.append(polynomials.derivative(derivatives[-1]))
        velocity_low, when, _, _ = polynomials.extrema(derivatives[1], h)
        backwards = np.nonzero(_backwards(schedule, vehicle, c, h, velocity_low))[0]
        if backwards.size:
            k = int(backwards[0])
            at = pieces.start[k] + when[k]
            failures.append(
                Finding(
                    f"{who} drives back along its path at {velocity_low[k]:.3g} m/s at t={at:.6f} s "
                    f"({place(schedule, vehicle, at)}): expected to turn back only at rest where its path "
                    "does",
                    pieces.arrays(schedule, k, (vehicle,)),
                )
            )
        for order in (1, 2):
            begin = abs(float(derivatives[order][0, 0]))
            end = abs(float(polynomials.evaluate(derivatives[order][-1:], h[-1:])[0]))
            if order > schedule.smoothness or (order == 2 and not schedule.jerk_limited):
                continue  # a linearly interpolated table has no velocity at its ends: the drive ramps
            if max(begin, end) > REST_TOLERANCE:
                failures.append(
                    Finding(
                        f"{who} is not at rest at the {'start' if begin > end else 'goal'}: "
                        f"{'velocity' if order == 1 else 'acceleration'} {max(begin, end):.3g}",
                        pieces.arrays(schedule, 0 if begin > end else pieces.count - 1, (vehicle,)),
                    )
                )
        for order, (name, limit_name, unit) in enumerate(names, start=1):
            lo, t_lo, hi, t_hi = polynomials.extrema(derivatives[order], h)
            peak = np.maximum(np.abs(lo), np.abs(hi))
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(peak))
            ratios[order - 1][vehicle] = float(peak[k] / limit)
            if not peak[k] <= limit + allowance(schedule, vehicle, name):
                at = pieces.start[k] + (t_hi[k] if abs(hi[k]) >= abs(lo[k]) else t_lo[k])
                failures.append(
                    Finding(
                        f"{who} {name} reaches {peak[k]:.9g} {unit} at t={at:.6f} s "
                        f"({place(schedule, vehicle, at)}) exceeds its {limit_name} {limit:g} {unit}",
                        pieces.arrays(schedule, k, (vehicle,)),
                    )
                )
        if pieces.count > 1:
            scale = max(1.0, path.length)
            # in travel, which never decreases; where the path turns back (at rest) the travel's
            # acceleration changes sign while the acceleration along the vehicle's axis goes on
            boundary = pieces.travel[vehicle][1:, 0]
            at_cusp = np.zeros(boundary.size, dtype=bool)
            # a table read back turns within its tolerance of the path's cusp, and is placed by the
            # path's axis after the turn: its travel may step there by twice that (at rest)
            window = POSITION_TOLERANCE if schedule.end_tolerance is None else schedule.end_tolerance
            for cusp in path.cusps:
                at_cusp |= np.abs(boundary - cusp) <= window + POSITION_TOLERANCE
            for order, name in enumerate(["position", "velocity", "acceleration"][: schedule.smoothness + 1]):
                before = polynomials.evaluate(derivatives[order][:-1], h[:-1])
                after = derivatives[order][1:, 0]
                tolerance = continuity_allowance(schedule, vehicle, name, scale)
                if order == 0 and schedule.end_tolerance is not None:
                    tolerance = np.where(at_cusp, tolerance + 2.0 * schedule.end_tolerance, tolerance)
                gap = np.abs(before - after)
                if order == 2:
                    gap = np.where(at_cusp, np.minimum(gap, np.abs(before + after)), gap)
                jumps = np.nonzero(~(gap <= tolerance))[0]
                if jumps.size:
                    k = int(jumps[0])
                    failures.append(
                        Finding(
                            f"{who} {name} jumps by {gap[k]:.3g} at t={pieces.start[k + 1]:.6f} s "
                            f"({place(schedule, vehicle, pieces.start[k + 1])})",
                            pieces.arrays(schedule, k + 1, (vehicle,)),
                        )
                    )
        # at rest where the path turns back (the acceleration along its axis is continuous, above)
        if path.cusps.size and pieces.count > 1 and schedule.smoothness >= 1:
            boundary = pieces.travel[vehicle][1:, 0]
            turning = [
                k
                for k in range(pieces.count - 1)
                if pieces.segment[vehicle, k] != pieces.segment[vehicle, k + 1]
                and path.headings[pieces.segment[vehicle, k]] != path.headings[pieces.segment[vehicle, k + 1]]
            ]
            for k in turning:
                speed = abs(float(derivatives[1][k + 1, 0]))
                if speed > REST_TOLERANCE:
                    failures.append(
                        Finding(
                            f"{who} turns back at {boundary[k]:g} m of travel "
                            f"(t={pieces.start[k + 1]:.6f} s) at {speed:.3g} m/s: expected at rest where its "
                            "path turns back",
                            pieces.arrays(schedule, k + 1, (vehicle,)),
                        )
                    )
    return ratios, start_error, goal_error


def _distance_terms(distances: TrackDistances, edges: np.ndarray, s: np.ndarray):
    """The four ways of the track distance on each piece, shape (n, 4, DEGREE + 1), and ``s1 - s2``.

    ``edges`` (2, n) and ``s`` (2, n, DEGREE + 1): the two vehicles of one pair.
    """
    n = edges.shape[1]
    ends = np.array(distances.ends, dtype=int)
    lengths = np.array(distances.lengths)
    nodes = np.array(distances.nodes)
    terms = np.zeros((n, 4, s.shape[2]))
    way = 0
    for end_1 in (0, 1):
        for end_2 in (0, 1):
            to_1 = s[0] if end_1 == 0 else -s[0]
            to_2 = s[1] if end_2 == 0 else -s[1]
            term = to_1 + to_2
            term[:, 0] += nodes[ends[edges[0], end_1], ends[edges[1], end_2]]
            term[:, 0] += (lengths[edges[0]] if end_1 else 0.0) + (lengths[edges[1]] if end_2 else 0.0)
            terms[:, way] = term
            way += 1
    return terms, s[0] - s[1]


def _separation_slack(schedule: GraphSchedule) -> float:
    """How far below the separation a schedule may come, metres: round-off.

    A table judged by its points only (``checked_limits == 0``: a generic CSV read back, whose
    cubic between two rows is the reader's, not the drive's) is held to the separation at its
    points exactly and between them to its tolerance.
    """
    if schedule.checked_limits == 0 and schedule.end_tolerance is not None:
        return max(POSITION_TOLERANCE, schedule.end_tolerance)
    return POSITION_TOLERANCE


def _backwards(
    schedule: GraphSchedule, vehicle: int, c: np.ndarray, h: np.ndarray, velocity_low: np.ndarray
) -> np.ndarray:
    """Pieces on which a vehicle drives back along its path, by more than a table's tolerance.

    A computed schedule never drives back (beyond velocity round-off); a table read back may wiggle
    back at rest by no more than its ``end_tolerance`` (metres), its interpolation's round-off.
    """
    if schedule.end_tolerance is None:
        return velocity_low < -allowance(schedule, vehicle, "velocity")
    low, t_low, high, t_high = polynomials.extrema(c, h)
    before = np.concatenate([[-np.inf], np.maximum.accumulate(high)[:-1]])
    furthest = np.maximum(np.maximum(before, c[:, 0]), np.where(t_high < t_low, high, -np.inf))
    return furthest - low > schedule.end_tolerance


def _closest_on_pieces(
    distances: TrackDistances, edges: np.ndarray, s: np.ndarray, length: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least track distance of a pair on each piece, when (from the piece's start), whether they pass there.

    ``edges`` (2, n) and ``s`` (2, n, DEGREE + 1) are the pair's. Returns three arrays of shape (n,):
    the least distance (m), its time from the piece's start (s), whether the two pass each other on
    one edge.
    """
    terms, along = _distance_terms(distances, edges, s)
    count = length.size
    low, t_low, _, _ = polynomials.extrema(terms.reshape(-1, terms.shape[2]), np.repeat(length, 4))
    low, t_low = low.reshape(-1, 4), t_low.reshape(-1, 4)
    way = np.argmin(low, axis=1)
    closest = low[np.arange(count), way]
    when = t_low[np.arange(count), way]
    same = edges[0] == edges[1]
    a_low, at_low, a_high, at_high = polynomials.extrema(along, length)
    crossing = same & (a_low < 0.0) & (a_high > 0.0)
    gap = np.where(a_high <= 0.0, -a_high, a_low)
    gap_when = np.where(a_high <= 0.0, at_high, at_low)
    nearer = same & (gap < closest)
    closest = np.where(nearer, np.where(crossing, 0.0, gap), closest)
    when = np.where(nearer, gap_when, when)
    return closest, when, crossing


def _check_separation(
    schedule: GraphSchedule, pieces: _Pieces, distances: TrackDistances, failures: list[str]
) -> float:
    """The least track distance between any two vehicles over the whole schedule, in closed form."""
    edges, s = _track_polynomials(schedule, pieces)
    least = math.inf
    for pair in itertools.combinations(range(len(schedule.paths)), 2):
        closest = _check_pair(schedule, pieces, distances, failures, pair, edges[list(pair)], s[list(pair)])
        if math.isnan(closest):
            return math.nan
        least = min(least, closest)
    return least


def _check_pair(
    schedule: GraphSchedule,
    pieces: _Pieces,
    distances: TrackDistances,
    failures: list[str],
    pair: tuple[int, int],
    edges: np.ndarray,
    s: np.ndarray,
) -> float:
    """The least track distance between the ``pair`` of vehicles (``edges``, ``s``: theirs), metres."""
    closest, when, crossing = np.empty(pieces.count), np.empty(pieces.count), np.empty(pieces.count, bool)
    # in blocks of pieces: a table read back has a piece per row, up to a million
    for first in range(0, pieces.count, _BLOCK):
        block = slice(first, min(first + _BLOCK, pieces.count))
        closest[block], when[block], crossing[block] = _closest_on_pieces(
            distances, edges[:, block], s[:, block], pieces.length[block]
        )
    if not np.all(np.isfinite(closest)):
        k = int(np.argmax(~np.isfinite(closest)))
        failures.append(
            Finding(
                f"the track distance is not finite from t={pieces.start[k]:.6f} s: expected finite numbers",
                pieces.arrays(schedule, k, pair),
            )
        )
        return math.nan
    k = int(np.argmin(closest))
    required = schedule.limits.min_separation
    one, other = (f"vehicle {v + 1}" for v in pair)
    if crossing.any():
        j = int(np.argmax(crossing))
        failures.append(
            Finding(
                f"{one} and {other} pass each other on edge {schedule.track.edges[edges[0, j]].name!r} "
                f"between t={pieces.start[j]:.6f} s and t={pieces.start[j] + pieces.length[j]:.6f} s",
                pieces.arrays(schedule, j, pair),
            )
        )
    elif closest[k] < required - _separation_slack(schedule):
        failures.append(
            Finding(
                f"separation {closest[k]:.9g} m at t={pieces.start[k] + when[k]:.6f} s is below the minimum "
                f"{required:g} m ({one} on {schedule.track.edges[edges[0, k]].name!r}, {other} on "
                f"{schedule.track.edges[edges[1, k]].name!r})",
                pieces.arrays(schedule, k, pair),
            )
        )
    return float(closest[k])


def verify_graph_schedule(schedule: GraphSchedule) -> VerificationReport:
    """Check a schedule on a track graph independently of how it was computed (see the module)."""
    counted = count_failures(schedule)
    if counted:  # every other check reads one path and one motion per vehicle
        return VerificationReport.failed(tuple(counted), count=len(schedule.route.start))
    own = array_failures(schedule)
    if own:  # the motion is read from these numbers: broken ones make every other check meaningless
        return VerificationReport.failed(tuple(own), count=len(schedule.paths))
    failures: list[str] = []
    distances = TrackDistances(schedule.track)
    _check_paths(schedule, distances, failures)
    if failures:
        return VerificationReport.failed(tuple(failures), count=len(schedule.paths))
    try:
        pieces = _Pieces(schedule)
    except UncheckableKinematicsError as error:
        known = (CubicKinematics, ToppraKinematics)
        k = next((k for k, s in enumerate(schedule.sections) if type(s.kinematics) not in known), 0)
        return VerificationReport.failed(
            (Finding(str(error), f"sections[{k}].kinematics"),), count=len(schedule.paths)
        )
    ratios, start_error, goal_error = _check_motion(schedule, pieces, failures)
    closest = _check_separation(schedule, pieces, distances, failures)
    same_class = check_class(schedule, pieces, distances, failures)
    if not failures and for_execution(schedule):
        # a plan for execution: each follower can always stop short of its frontier
        for failure in braking_rule_failures(schedule):
            k = pieces.at(failure.time)
            where = place(schedule, failure.vehicle, failure.time)
            failures.append(Finding(failure.message(where), pieces.arrays(schedule, k, (failure.vehicle,))))
    return VerificationReport(
        passed=not failures,
        failures=tuple(failures),
        pieces=pieces.count,
        min_separation=closest,
        separation_margin=closest - schedule.limits.min_separation,
        velocity_ratio=tuple(ratios[0]),
        acceleration_ratio=tuple(ratios[1]),
        jerk_ratio=None if ratios[2] is None else tuple(ratios[2]),
        start_error=start_error,
        goal_error=goal_error,
        regions_match=same_class,
    )
