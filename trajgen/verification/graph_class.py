"""The class check of a schedule on a track graph: it passes every conflict in its route's order.

For every pair of vehicles, each convex part of the region closer than the separation, in the plane
of the two vehicles' travel, must lie on the same side of the schedule's curve as of the route's (the
class is the order of passing at each conflict). Part of
:func:`~trajgen.verification.graph_schedule.verify_graph_schedule`.
"""

from __future__ import annotations

import itertools

import numpy as np

from trajgen.model import polynomials
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.verification.graph_route import TrackDistances
from trajgen.verification.report import POSITION_TOLERANCE, Finding

__all__ = ["check_class"]

#: Area below which a convex part of the too-close region is a touching line, not an obstacle, m².
_SLIVER_AREA = 1e-12


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


def _too_close_parts(
    schedule: GraphSchedule, distances: TrackDistances, pair: tuple[int, int]
) -> list[tuple[float, float]]:
    """A point inside each convex part of the region where the ``pair`` of vehicles is too close.

    In the plane of the two vehicles' travel.
    """
    required = schedule.limits.min_separation
    first, second = (schedule.paths[v] for v in pair)
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


def _route_curve(schedule: GraphSchedule, pair: tuple[int, int]) -> np.ndarray:
    """The route as a monotone polyline in the ``pair``'s travel plane, shape (m + 1, 2).

    A move of one of them is a step along its axis, a joint move of both a diagonal; moves of the
    other vehicles are steps of no length there.
    """
    return schedule.route.corners()[:, list(pair)]


def _side_of_polyline(curve: np.ndarray, point: tuple[float, float]) -> int:
    """+1 if the point lies above the monotone polyline (the pair's first passes first), -1 below, 0 on it."""
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


def _side_of_schedule(pieces, point: tuple[float, float], pair: tuple[int, int]) -> int:
    """The same side test for the schedule's curve (travel of the pair, piece by piece)."""
    x, y = point
    first, second = (pieces.travel[v] for v in pair)
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


def check_class(schedule: GraphSchedule, pieces, distances: TrackDistances, failures: list[str]) -> bool:
    """Whether, for every pair, each part of its too-close region lies on the same side as the route's."""
    for pair in itertools.combinations(range(len(schedule.paths)), 2):
        route_curve = _route_curve(schedule, pair)
        for point in _too_close_parts(schedule, distances, pair):
            planned, timed = _side_of_polyline(route_curve, point), _side_of_schedule(pieces, point, pair)
            if planned and timed and planned != timed:
                first = pair[0] if planned > 0 else pair[1]
                track = pieces.travel[pair[0]][:, 0]
                k = int(np.clip(np.searchsorted(track, point[0], side="right") - 1, 0, None))
                failures.append(
                    Finding(
                        "the schedule passes a conflict in another order than the route (at travel "
                        f"{point[0]:.3f} m of vehicle {pair[0] + 1} and {point[1]:.3f} m of vehicle "
                        f"{pair[1] + 1} the route lets vehicle {first + 1} pass first): another class than "
                        "the route's",
                        pieces.arrays(schedule, min(k, pieces.count - 1), pair),
                    )
                )
                return False
    return True
