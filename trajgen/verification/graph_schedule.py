"""The verifier of schedules on a track graph: every check in closed form, between samples too.

Independent of how the schedule was computed and of the planner's code. The schedule is cut into
polynomial pieces: at every knot of either vehicle's travel and wherever a vehicle passes from one
segment of its path to the next. On a piece each vehicle's travel is one cubic and each vehicle is on
one edge, so its metres ``s`` from the edge's ``from`` node are a cubic too, and the track distance
between the vehicles is the least of at most five of them: through each pair of edge ends (the node
distances from this package's own Dijkstra, :class:`~trajgen.verification.graph_route.TrackDistances`)
and, on one edge, ``|s1 - s2|``. Their minima are taken in closed form
(:func:`~trajgen.model.polynomials.extrema`); nothing is sampled.

Checked: the paths follow the route's moves from its start to its goal, travel starts at 0 and ends at
each path's length at rest, never runs backwards, the vehicles are at rest where a path turns back,
position, velocity (and acceleration when jerk-limited) are continuous, velocity, acceleration (and
jerk) stay within the limits, the separation holds, every number is finite, and the schedule passes
every conflict in the route's order (its class): each convex part of the region closer than the
separation, in the plane of both vehicles' travel, lies on the same side of the schedule's curve as of
the route's.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from topology import EdgePoint
from trajgen.model import polynomials
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import UncheckableKinematicsError, kinematics_polynomials, split_at_values
from trajgen.verification.graph_route import TrackDistances
from trajgen.verification.piecewise import allowance, continuity_allowance, time_resolution
from trajgen.verification.report import (
    POSITION_TOLERANCE,
    REST_TOLERANCE,
    TRACK_END_TOLERANCE,
    VerificationReport,
)

__all__ = ["verify_graph_schedule"]

#: Area below which a convex part of the too-close region is a touching line, not an obstacle, m².
_SLIVER_AREA = 1e-12
#: Pieces whose separation is computed at once (the memory of a table read back stays bounded).
_BLOCK = 1 << 15


class _Pieces:
    """The schedule's polynomial pieces: travel and segment of each vehicle on each."""

    def __init__(self, schedule: GraphSchedule) -> None:
        parts = []
        for section in schedule.sections:
            times, travel, _ = kinematics_polynomials(section.kinematics)
            parts.append((section.start_time + times[:-1], np.diff(times), travel))
        bounds = tuple(path.starts[1:-1] for path in schedule.paths)
        ends = np.concatenate([p[0] for p in parts] + [[parts[-1][0][-1] + parts[-1][1][-1]]])
        travel = np.concatenate([p[2] for p in parts], axis=1)
        start, length, travel, _ = split_at_values(
            ends, travel, np.zeros((2, ends.size - 1), dtype=int), bounds, margin=POSITION_TOLERANCE
        )
        keep = length > 0.0
        if not keep.any():  # nothing moves: one piece of no time at the start
            start, length, travel = np.zeros(1), np.zeros(1), travel[:, :1]
        else:
            start, length, travel = start[keep], length[keep], travel[:, keep]
        self.start, self.length, self.travel = start, length, travel
        middle = np.stack([polynomials.evaluate(travel[v], 0.5 * length) for v in range(2)])
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


def _check_tiling(schedule: GraphSchedule, failures: list[str]) -> None:
    """Sections follow each other without gap or overlap from t = 0."""
    clock = 0.0
    for number, section in enumerate(schedule.sections):
        if not math.isfinite(section.duration) or abs(section.start_time - clock) > 1e-9 * max(1.0, clock):
            failures.append(
                f"section {number + 1} starts at t={section.start_time!r} s: expected the end of the one "
                f"before, t={clock!r} s"
            )
            return
        clock = section.start_time + section.duration


def _track_polynomials(schedule: GraphSchedule, pieces: _Pieces) -> tuple[np.ndarray, np.ndarray]:
    """Edge (2, n) and metres from its ``from`` node as polynomials (2, n, DEGREE + 1) on each piece."""
    edges = np.zeros((2, pieces.count), dtype=int)
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


def _check_paths(schedule: GraphSchedule, distances: TrackDistances, failures: list[str]) -> None:
    """Each path follows its vehicle's moves of the route, from the route's start to its goal."""
    route, track = schedule.route, schedule.track
    for vehicle, path in enumerate(schedule.paths):
        who = f"vehicle {vehicle + 1}"
        arrays = [path.s_from, path.s_to, path.starts]
        if not all(np.all(np.isfinite(a)) for a in arrays):
            failures.append(f"{who}'s path holds a non-finite number: expected finite metres")
            continue
        m = path.edges.size
        if path.starts.size != m + 1 or path.headings.size != m or path.s_from.size != m:
            failures.append(
                f"{who}'s path has {m} edges but {path.starts.size} travel marks: expected {m + 1}"
            )
            continue

        def point(k: int, end: bool, path=path) -> EdgePoint:
            return EdgePoint(int(path.edges[k]), float(path.s_to[k] if end else path.s_from[k]))

        for k in range(m):
            edge = int(path.edges[k])
            if not 0 <= edge < len(track.edges):
                failures.append(f"{who}'s path runs on edge number {edge}: the track has {len(track.edges)}")
                return
            low, high = sorted((path.s_from[k], path.s_to[k]))
            if low < -TRACK_END_TOLERANCE or high > distances.lengths[edge] + TRACK_END_TOLERANCE:
                failures.append(
                    f"{who}'s path leaves edge {track.edges[edge].name!r} ({low:g} to {high:g} m of "
                    f"{distances.lengths[edge]:g} m)"
                )
            if abs((high - low) - (path.starts[k + 1] - path.starts[k])) > POSITION_TOLERANCE:
                failures.append(
                    f"{who}'s path segment {k + 1} is {high - low:g} m long but counts "
                    f"{path.starts[k + 1] - path.starts[k]:g} m of travel"
                )
            if k and distances.between(point(k - 1, True), point(k, False)) > POSITION_TOLERANCE:
                failures.append(f"{who}'s path jumps between its segments {k} and {k + 1}")
            if k:
                turns = (
                    edge == int(path.edges[k - 1])
                    and (path.s_to[k] - path.s_from[k]) * (path.s_to[k - 1] - path.s_from[k - 1]) < 0.0
                )
                if (path.headings[k] != path.headings[k - 1]) != turns:
                    failures.append(
                        f"{who}'s path {'turns back' if turns else 'goes on'} after its segment {k} but its "
                        f"heading {'does not flip' if turns else 'flips'} there"
                    )
        start = point(0, False) if m else path.home
        goal = point(m - 1, True) if m else path.home
        for what, here, expected in (
            ("start", start, route.start[vehicle]),
            ("goal", goal, route.goal[vehicle]),
        ):
            off = distances.between(here, expected)
            if off > POSITION_TOLERANCE:
                failures.append(f"{who}'s path {what} is {off:.3g} m off the route's {track.name(expected)}")
        if abs(path.length - route.travel[vehicle]) > POSITION_TOLERANCE * max(1.0, route.travel[vehicle]):
            failures.append(
                f"{who}'s path is {path.length:g} m long: the route moves it {route.travel[vehicle]:g} m"
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
                        f"{who}'s path is {off:.3g} m off move {number + 1}'s point {track.name(b)} after "
                        f"{reached:g} m of travel"
                    )
                    return
                travel = reached


def _check_motion(schedule: GraphSchedule, pieces: _Pieces, failures: list[str]) -> tuple[list, float, float]:
    """Ends at rest, travel forward only, continuity, limits (closed form): worst ratios, end errors."""
    names = [("velocity", "max_velocity", "m/s"), ("acceleration", "max_acceleration", "m/s^2")]
    if schedule.jerk_limited:
        names.append(("jerk", "max_jerk", "m/s^3"))
    ratios: list = [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0] if schedule.jerk_limited else None]
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
            failures.append(
                f"{who}'s travel runs from {first:.9g} m to {last:.9g} m: expected 0 to its path's "
                f"{path.length:.9g} m"
            )
        if np.any(low < -past_end) or np.any(high > path.length + past_end):
            failures.append(f"{who}'s travel leaves 0 to {path.length:g} m")
        derivatives = [c]
        for _ in range(3):
            derivatives.append(polynomials.derivative(derivatives[-1]))
        velocity_low, when, _, _ = polynomials.extrema(derivatives[1], h)
        backwards = np.nonzero(_backwards(schedule, vehicle, c, h, velocity_low))[0]
        if backwards.size:
            k = int(backwards[0])
            failures.append(
                f"{who} drives back along its path at {velocity_low[k]:.3g} m/s at t="
                f"{pieces.start[k] + when[k]:.6f} s: expected to turn back only at rest where its path does"
            )
        for order in (1, 2):
            begin = abs(float(derivatives[order][0, 0]))
            end = abs(float(polynomials.evaluate(derivatives[order][-1:], h[-1:])[0]))
            if order > schedule.smoothness or (order == 2 and not schedule.jerk_limited):
                continue  # a linearly interpolated table has no velocity at its ends: the drive ramps
            if max(begin, end) > REST_TOLERANCE:
                failures.append(
                    f"{who} is not at rest at the {'start' if begin > end else 'goal'}: "
                    f"{'velocity' if order == 1 else 'acceleration'} {max(begin, end):.3g}"
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
                    f"{who} {name} reaches {peak[k]:.9g} {unit} at t={at:.6f} s: exceeds its {limit_name} "
                    f"{limit:g} {unit}"
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
                    failures.append(f"{who} {name} jumps by {gap[k]:.3g} at t={pieces.start[k + 1]:.6f} s")
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
                        f"{who} turns back at {boundary[k]:g} m of travel (t={pieces.start[k + 1]:.6f} s) at "
                        f"{speed:.3g} m/s: expected at rest where its path turns back"
                    )
    return ratios, start_error, goal_error


def _distance_terms(schedule: GraphSchedule, distances: TrackDistances, edges: np.ndarray, s: np.ndarray):
    """The four ways of the track distance on each piece, shape (n, 4, DEGREE + 1), and ``s1 - s2``."""
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
    schedule: GraphSchedule, distances: TrackDistances, edges: np.ndarray, s: np.ndarray, length: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least track distance on each piece, when (from the piece's start) and whether they pass there.

    Returns three arrays of shape (n,): the least distance (m), its time from the piece's start (s),
    whether the vehicles pass each other on one edge.
    """
    terms, along = _distance_terms(schedule, distances, edges, s)
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
    """The least track distance over the whole schedule, in closed form."""
    edges, s = _track_polynomials(schedule, pieces)
    closest, when, crossing = np.empty(pieces.count), np.empty(pieces.count), np.empty(pieces.count, bool)
    # in blocks of pieces: a table read back has a piece per row, up to a million
    for first in range(0, pieces.count, _BLOCK):
        block = slice(first, min(first + _BLOCK, pieces.count))
        closest[block], when[block], crossing[block] = _closest_on_pieces(
            schedule, distances, edges[:, block], s[:, block], pieces.length[block]
        )
    if not np.all(np.isfinite(closest)):
        failures.append("the track distance is not finite on some piece: expected finite numbers")
        return math.nan
    k = int(np.argmin(closest))
    required = schedule.limits.min_separation
    if crossing.any():
        j = int(np.argmax(crossing))
        failures.append(
            f"the vehicles pass each other on edge {schedule.track.edges[edges[0, j]].name!r} between "
            f"t={pieces.start[j]:.6f} s and t={pieces.start[j] + pieces.length[j]:.6f} s"
        )
    elif closest[k] < required - _separation_slack(schedule):
        failures.append(
            f"separation {closest[k]:.9g} m at t={pieces.start[k] + when[k]:.6f} s is below the minimum "
            f"{required:g} m (vehicle 1 on {schedule.track.edges[edges[0, k]].name!r}, vehicle 2 on "
            f"{schedule.track.edges[edges[1, k]].name!r})"
        )
    return float(closest[k])


def _clip(polygon: list, a: float, b: float, c: float) -> list:
    """The part of a convex polygon where ``a x + b y < c`` (Sutherland–Hodgman, one half-plane)."""
    out = []
    for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        f0, f1 = a * x0 + b * y0 - c, a * x1 + b * y1 - c
        if f0 < 0.0:
            out.append((x0, y0))
        if (f0 < 0.0) != (f1 < 0.0):
            r = f0 / (f0 - f1)
            out.append((x0 + r * (x1 - x0), y0 + r * (y1 - y0)))
    return out


def _centroid(polygon: list) -> tuple[float, float, float]:
    """Area and centroid of a convex polygon."""
    area = cx = cy = 0.0
    for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        cross = x0 * y1 - x1 * y0
        area += cross
        cx += (x0 + x1) * cross
        cy += (y0 + y1) * cross
    if abs(area) < 1e-300:
        return 0.0, 0.0, 0.0
    return 0.5 * abs(area), cx / (3.0 * area), cy / (3.0 * area)


def _too_close_parts(schedule: GraphSchedule, distances: TrackDistances) -> list[tuple[float, float]]:
    """A point inside each convex part of the region closer than the separation, in the travel plane."""
    required = schedule.limits.min_separation
    first, second = schedule.paths
    points = []
    for k1, k2 in itertools.product(range(first.edges.size), range(second.edges.size)):
        e1, e2 = int(first.edges[k1]), int(second.edges[k2])
        p_low, p_high = float(first.starts[k1]), float(first.starts[k1 + 1])
        q_low, q_high = float(second.starts[k2]), float(second.starts[k2 + 1])
        rectangle = [(p_low, q_low), (p_high, q_low), (p_high, q_high), (p_low, q_high)]
        # s_i = offset_i + sign_i * travel_i on these segments
        sign_1 = float(np.sign(first.s_to[k1] - first.s_from[k1]))
        sign_2 = float(np.sign(second.s_to[k2] - second.s_from[k2]))
        offset_1 = float(first.s_from[k1]) - sign_1 * p_low
        offset_2 = float(second.s_from[k2]) - sign_2 * q_low
        parts = []
        for end_1, end_2 in itertools.product((0, 1), (0, 1)):
            # distance through ends: (s1 or L1 - s1) + D + (s2 or L2 - s2) < d, as a x + b y < c
            f1 = -1.0 if end_1 else 1.0
            f2 = -1.0 if end_2 else 1.0
            constant = distances.nodes[distances.ends[e1][end_1]][distances.ends[e2][end_2]]
            constant += (distances.lengths[e1] if end_1 else 0.0) + (distances.lengths[e2] if end_2 else 0.0)
            constant += f1 * offset_1 + f2 * offset_2
            parts.append(_clip(rectangle, f1 * sign_1, f2 * sign_2, required - constant))
        if e1 == e2:  # |s1 - s2| < d: a strip
            strip = _clip(rectangle, sign_1, -sign_2, required - offset_1 + offset_2)
            parts.append(_clip(strip, -sign_1, sign_2, required + offset_1 - offset_2))
        for polygon in parts:
            if len(polygon) >= 3:
                area, cx, cy = _centroid(polygon)
                if area > _SLIVER_AREA:
                    points.append((cx, cy))
    return points


def _route_curve(schedule: GraphSchedule) -> np.ndarray:
    """The route's moves as a monotone staircase in the travel plane, shape (m + 1, 2)."""
    corners = [(0.0, 0.0)]
    for move in schedule.route.moves:
        here = list(corners[-1])
        here[move.vehicle] += move.length
        corners.append((here[0], here[1]))
    return np.array(corners)


def _side_of_polyline(curve: np.ndarray, point: tuple[float, float]) -> int:
    """+1 if the point lies above the monotone polyline (vehicle 1 passes first), -1 below, 0 on it."""
    x, y = point
    lows, highs = [], []
    for (x0, y0), (x1, y1) in itertools.pairwise(curve):
        if min(x0, x1) <= x <= max(x0, x1):
            if x1 == x0:
                lows.append(min(y0, y1))
                highs.append(max(y0, y1))
            else:
                y_at = y0 + (x - x0) / (x1 - x0) * (y1 - y0)
                lows.append(y_at)
                highs.append(y_at)
    if not lows:
        return 0
    return 1 if y > max(highs) + POSITION_TOLERANCE else (-1 if y < min(lows) - POSITION_TOLERANCE else 0)


def _side_of_schedule(pieces: _Pieces, point: tuple[float, float]) -> int:
    """The same side test for the schedule's curve (travel of both vehicles, piece by piece)."""
    x, y = point
    first, second = pieces.travel
    begin = first[:, 0]
    end = polynomials.evaluate(first, pieces.length)
    lo, hi = np.minimum(begin, end), np.maximum(begin, end)
    hits = np.nonzero((lo <= x) & (x <= hi))[0]
    if hits.size == 0:
        return 0
    values = []
    for k in hits:
        c = first[k : k + 1].copy()
        c[0, 0] -= x
        if begin[k] == end[k]:  # standing at x for the piece: the other's whole range
            _, _, top, _ = polynomials.extrema(second[k : k + 1], pieces.length[k : k + 1])
            values += [float(second[k, 0]), float(top[0])]
            continue
        root = polynomials.root_in(c, np.zeros(1), pieces.length[k : k + 1])
        if np.isfinite(root[0]):
            values.append(float(polynomials.evaluate(second[k : k + 1], root)[0]))
    if not values:
        return 0
    return 1 if y > max(values) + POSITION_TOLERANCE else (-1 if y < min(values) - POSITION_TOLERANCE else 0)


def _check_class(
    schedule: GraphSchedule, pieces: _Pieces, distances: TrackDistances, failures: list[str]
) -> bool:
    """Whether every part of the too-close region lies on the same side of the schedule as of the route."""
    route_curve = _route_curve(schedule)
    for point in _too_close_parts(schedule, distances):
        planned, timed = _side_of_polyline(route_curve, point), _side_of_schedule(pieces, point)
        if planned and timed and planned != timed:
            first = "vehicle 1" if planned > 0 else "vehicle 2"
            failures.append(
                "the schedule passes a conflict in another order than the route (at travel "
                f"{point[0]:.3f} m, "
                f"{point[1]:.3f} m the route lets {first} pass first): another class than the route's"
            )
            return False
    return True


def verify_graph_schedule(schedule: GraphSchedule) -> VerificationReport:
    """Check a schedule on a track graph independently of how it was computed (see the module)."""
    failures: list[str] = []
    distances = TrackDistances(schedule.track)
    _check_paths(schedule, distances, failures)
    _check_tiling(schedule, failures)
    if failures:
        return VerificationReport.failed(tuple(failures))
    try:
        pieces = _Pieces(schedule)
    except UncheckableKinematicsError as error:
        return VerificationReport.failed((str(error),))
    ratios, start_error, goal_error = _check_motion(schedule, pieces, failures)
    closest = _check_separation(schedule, pieces, distances, failures)
    same_class = _check_class(schedule, pieces, distances, failures)
    return VerificationReport(
        passed=not failures,
        failures=tuple(failures),
        pieces=pieces.count,
        min_separation=closest,
        separation_margin=closest - schedule.limits.min_separation,
        velocity_ratio=(ratios[0][0], ratios[0][1]),
        acceleration_ratio=(ratios[1][0], ratios[1][1]),
        jerk_ratio=None if ratios[2] is None else (ratios[2][0], ratios[2][1]),
        start_error=start_error,
        goal_error=goal_error,
        regions_match=same_class,
    )
