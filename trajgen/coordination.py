"""The coordination diagram of a plan: its conflicts, the order it keeps at each, the frontiers.

Each vehicle drives its path of the plan in *travel* coordinates ``p`` (metres
driven along its own path, cusps included, so ``p`` never decreases). On each
pair of path segments the track distance between the vehicles is affine in
``(p1, p2)`` (``|s1 - s2|`` on one leg, ``s1 + s2`` across the junction), so the
obstacle region ``{(p1, p2): distance < d}`` is a union of convex polygons.
Its connected parts are the **conflicts**. The plan passes each conflict on one
side: the vehicle that passes first is the conflict's **leader**, the other its
**follower** (``ONLINE-EXECUTION.md`` section 2; docs/online.md).

A follower may not come to rest where it would meet a position at which its
leader could still come to rest: the leader's **earliest rest point**
``e = p + v**2 / (2 E)`` onwards (E its emergency deceleration). The smallest
such follower travel over all the conflicts it follows is its **frontier**
(:meth:`CoordinationDiagram.frontier`). Plain floats and tuples: it runs every
control cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from limits import VehicleLimits
from trajgen.paths import VehiclePath
from trajgen.pieces import schedule_pieces

__all__ = [
    "Conflict",
    "CoordinationDiagram",
    "Polygon",
    "earliest_rest",
    "plan_paths",
    "schedule_times",
    "schedule_waypoints",
    "stopping_distance",
]

#: A convex polygon of the diagram: its vertices ``(p1, p2)`` in order, metres of travel.
Polygon = tuple[tuple[float, float], ...]
#: Polygons of less area than this (m²) are boundaries, not obstacles (the region is open).
_AREA = 1e-12
#: Round-off of the diagram's geometry, metres of travel.
_TOUCH = 1e-9
#: Two polygons that share a stretch longer than this (metres) are one conflict; a point is not.
_SHARED = 1e-6


def earliest_rest(p: float, velocity: float, deceleration: float) -> float:
    """Earliest travel at which a vehicle at travel ``p`` moving at ``velocity`` (m/s) can be at rest.

    Parameters
    ----------
    p : float
        Travel, metres.
    velocity : float
        Rate of travel, m/s (a negative rate counts as rest: travel never runs back).
    deceleration : float
        The hardest braking possible (emergency), m/s².

    Examples
    --------
    >>> earliest_rest(3.0, 1.0, 2.0)
    3.25
    """
    v = max(velocity, 0.0)
    return p + v * v / (2.0 * deceleration)


@dataclass(frozen=True, slots=True)
class Conflict:
    """One connected part of the obstacle region, and the order the plan keeps there.

    Attributes
    ----------
    polygons : tuple of Polygon
        Convex pieces (vertices in travel coordinates ``(p1, p2)``, metres).
    leader : int
        The vehicle (0 or 1) that passes first; ``1 - leader`` follows.
    low, high : tuple of 2 float
        Smallest and largest travel of each vehicle over the conflict, metres.
    """

    polygons: tuple[Polygon, ...]
    leader: int
    low: tuple[float, float]
    high: tuple[float, float]

    @property
    def follower(self) -> int:
        """The vehicle that waits for the leader here."""
        return 1 - self.leader

    def bound(self, earliest: float) -> float:
        """The smallest follower travel meeting a leader's travel of ``earliest`` or more (``inf`` if none).

        The region is open (a distance of exactly the separation is allowed): a polygon that
        reaches past ``earliest`` by no more than :data:`_TOUCH` leaves only its boundary.
        """
        leader, follower = self.leader, 1 - self.leader
        best = math.inf
        for polygon in self.polygons:
            if max(vertex[leader] for vertex in polygon) <= earliest + _TOUCH:
                continue  # at most its boundary is left, where the distance is the separation: allowed
            count = len(polygon)
            for k in range(count):
                a, b = polygon[k], polygon[(k + 1) % count]
                if a[leader] >= earliest:
                    best = min(best, a[follower])
                if (a[leader] - earliest) * (b[leader] - earliest) < 0.0:  # the edge crosses the line
                    w = (earliest - a[leader]) / (b[leader] - a[leader])
                    best = min(best, a[follower] + w * (b[follower] - a[follower]))
        return best


def _clip(polygon: list[tuple[float, float]], a: float, b: float, c: float) -> list[tuple[float, float]]:
    """The part of ``polygon`` where ``a x + b y <= c`` (Sutherland-Hodgman, one half-plane)."""
    out: list[tuple[float, float]] = []
    count = len(polygon)
    for k in range(count):
        p, q = polygon[k], polygon[(k + 1) % count]
        fp, fq = a * p[0] + b * p[1] - c, a * q[0] + b * q[1] - c
        if fp <= 0.0:
            out.append(p)
        if fp * fq < 0.0:
            w = fp / (fp - fq)
            out.append((p[0] + w * (q[0] - p[0]), p[1] + w * (q[1] - p[1])))
    return out


def _area(polygon: list[tuple[float, float]]) -> float:
    return 0.5 * abs(
        sum(
            polygon[k][0] * polygon[(k + 1) % len(polygon)][1]
            - polygon[(k + 1) % len(polygon)][0] * polygon[k][1]
            for k in range(len(polygon))
        )
    )


def _segments(path: VehiclePath) -> list[tuple[int, float, float, float, float]]:
    """(leg, travel at start, travel at end, s at start, ds/dp) of each segment of a path."""
    out = []
    for k, leg in enumerate(path.legs):
        start = path.starts[k]
        end = path.starts[k + 1] if k + 1 < len(path.legs) else path.length
        out.append((leg, start, end, path.s_from[k], 1.0 if path.s_to[k] > path.s_from[k] else -1.0))
    return out


def _obstacle(first, second, separation: float) -> list[tuple[float, float]]:
    """The closed part of one segment pair's rectangle where the track distance is at most ``separation``."""
    leg1, a1, b1, s1, sign1 = first
    leg2, a2, b2, s2, sign2 = second
    c1, c2 = s1 - sign1 * a1, s2 - sign2 * a2  # s = c + sign * p on the segment
    polygon = [(a1, a2), (b1, a2), (b1, b2), (a1, b2)]
    if leg1 != leg2:  # across the junction: s1 + s2
        return _clip(polygon, sign1, sign2, separation - c1 - c2)
    polygon = _clip(polygon, sign1, -sign2, separation - c1 + c2)  # s1 - s2 <= d
    return _clip(polygon, -sign1, sign2, separation + c1 - c2) if polygon else polygon  # s2 - s1 <= d


def _joined(p: Polygon, q: Polygon) -> bool:
    """Whether two convex polygons share more than a point: an edge stretch or some area.

    The obstacle region is open, so two pieces that meet only at a point (where the distance is
    exactly the separation) are two conflicts: a plan with no clearance runs between them.
    """
    common = list(p)
    count = len(q)
    orientation = (
        1.0
        if sum(q[k][0] * q[(k + 1) % count][1] - q[(k + 1) % count][0] * q[k][1] for k in range(count)) >= 0
        else -1.0
    )
    for k in range(count):
        (x0, y0), (x1, y1) = q[k], q[(k + 1) % count]
        # inside a counterclockwise polygon: left of each edge, (x1 - x0)(y - y0) - (y1 - y0)(x - x0) >= 0
        a, b = orientation * (y1 - y0), -orientation * (x1 - x0)
        common = _clip(common, a, b, a * x0 + b * y0 + _TOUCH * math.hypot(a, b))
        if not common:
            return False
    return max(math.dist(u, w) for u in common for w in common) > _SHARED


class _Curve:
    """The plan's curve ``(p1(t), p2(t))``: travel from each vehicle's axis, exact between samples."""

    def __init__(self, schedule, times: np.ndarray) -> None:
        self.schedule = schedule
        self.times = times
        axis = schedule.state(times).axis  # (2, n)
        self.axis = axis
        self.travel = np.concatenate(
            [np.zeros((2, 1)), np.cumsum(np.abs(np.diff(axis, axis=1)), axis=1)], axis=1
        )

    def at(self, t: float) -> tuple[float, float]:
        k = min(max(int(np.searchsorted(self.times, t, side="right")) - 1, 0), self.times.size - 2)
        axis = self.schedule.state([t]).axis[:, 0]
        return tuple(float(self.travel[v, k] + abs(axis[v] - self.axis[v, k])) for v in (0, 1))  # type: ignore[return-value]

    def second_when_first_reaches(self, a: float) -> float:
        """``p2`` at the first instant ``p1 >= a`` (the plan's curve is monotone)."""
        k = int(np.searchsorted(self.travel[0], a, side="left"))
        if k == 0:
            return float(self.travel[1, 0])
        if k >= self.times.size:
            return float(self.travel[1, -1])
        low, high = float(self.times[k - 1]), float(self.times[k])
        for _ in range(60):
            middle = 0.5 * (low + high)
            if self.at(middle)[0] >= a:
                high = middle
            else:
                low = middle
        return self.at(high)[1]


class CoordinationDiagram:
    """The conflicts of a plan and the order it passes them in, for the executor's frontiers.

    Parameters
    ----------
    paths : tuple of 2 VehiclePath
        Each vehicle's path of the plan, in travel coordinates.
    separation : float
        Track distance the conflicts keep, metres.
    schedule : Schedule
        The verified plan: it decides who passes each conflict first.
    times : ndarray, shape (n,)
        Instants of the plan at which neither vehicle turns between two consecutive ones (the
        plan's piece ends and velocity roots: :func:`schedule_times`).
    """

    __slots__ = ("_by_follower", "conflicts", "paths", "separation")

    def __init__(self, paths: tuple[VehiclePath, VehiclePath], separation: float, schedule, times) -> None:
        self.paths = paths
        self.separation = float(separation)
        first, second = _segments(paths[0]), _segments(paths[1])
        polygons: list[Polygon] = []
        where: list[tuple[int, int]] = []
        for i, a in enumerate(first):
            for j, b in enumerate(second):
                polygon = _obstacle(a, b, self.separation)
                if len(polygon) >= 3 and _area(polygon) > _AREA:
                    polygons.append(tuple(polygon))
                    where.append((i, j))
        parent = list(range(len(polygons)))

        def root(k: int) -> int:
            while parent[k] != k:
                parent[k] = parent[parent[k]]
                k = parent[k]
            return k

        for m in range(len(polygons)):
            for n in range(m + 1, len(polygons)):
                near = abs(where[m][0] - where[n][0]) <= 1 and abs(where[m][1] - where[n][1]) <= 1
                if near and _joined(polygons[m], polygons[n]):
                    parent[root(m)] = root(n)
        groups: dict[int, list[Polygon]] = {}
        for k, polygon in enumerate(polygons):
            groups.setdefault(root(k), []).append(polygon)
        curve = _Curve(schedule, np.asarray(times, dtype=float)) if groups else None
        conflicts = []
        for members in groups.values():
            xs = [x for polygon in members for x, _ in polygon]
            ys = [y for polygon in members for _, y in polygon]
            largest = max(members, key=lambda polygon: _area(list(polygon)))
            cx = sum(x for x, _ in largest) / len(largest)
            cy = sum(y for _, y in largest) / len(largest)
            # the plan passes below the conflict (smaller p2 when p1 reaches it): vehicle 1 goes first
            leader = 0 if curve.second_when_first_reaches(cx) < cy else 1  # type: ignore[union-attr]
            conflicts.append(Conflict(tuple(members), leader, (min(xs), min(ys)), (max(xs), max(ys))))
        conflicts.sort(key=lambda c: (c.low[c.leader], c.low[c.follower]))
        self.conflicts = tuple(conflicts)
        self._by_follower = tuple(tuple(c for c in conflicts if c.follower == v) for v in (0, 1))

    def frontier(self, follower: int, earliest: float) -> float:
        """The farthest travel ``follower`` may come to rest at, metres (``inf``: nothing binds it).

        Parameters
        ----------
        follower : int
            0 or 1.
        earliest : float
            The other vehicle's earliest rest point (:func:`earliest_rest`), metres of its travel.
        """
        best = math.inf
        for conflict in self._by_follower[follower]:
            if conflict.high[conflict.leader] <= earliest + _TOUCH:
                continue  # the leader cannot stop before it is past this conflict
            best = min(best, conflict.bound(earliest))
        return best

    def leading(self, vehicle: int, travel: float) -> tuple[Conflict, ...]:
        """The conflicts ``vehicle`` leads that it has not yet passed at ``travel``."""
        return tuple(c for c in self.conflicts if c.leader == vehicle and c.high[vehicle] > travel)


def stopping_distance(velocity: float, acceleration: float, limits: VehicleLimits) -> float:
    """An upper bound of the jerk-limited service stopping distance, metres (travel coordinates).

    From rest acceleration, ``D(v) = v^2 / (2 A) + v A / (2 J)`` (exact once ``A`` is reached,
    above the exact ``v sqrt(v / J)`` below that). A positive acceleration ``a`` is first brought
    to 0 in ``a / J`` seconds, covering ``v a / J + a^3 / (3 J^2)`` and gaining ``a^2 / (2 J)`` of
    speed; a negative one only shortens the stop.

    Parameters
    ----------
    velocity, acceleration : float
        Rate of travel (m/s, >= 0) and its acceleration (m/s²).
    limits : VehicleLimits

    Examples
    --------
    >>> from limits import VehicleLimits
    >>> stopping_distance(1.0, 0.0, VehicleLimits(1.0, 0.5, 1.0))
    1.25
    """
    a_max, j_max = limits.max_acceleration, limits.max_jerk
    v = max(velocity, 0.0)
    a = max(acceleration, 0.0)
    ramp = v * a / j_max + a**3 / (3.0 * j_max * j_max)
    peak = v + a * a / (2.0 * j_max)
    return ramp + peak * peak / (2.0 * a_max) + peak * a_max / (2.0 * j_max)


def schedule_times(schedule) -> np.ndarray:
    """Instants of a schedule between which neither vehicle turns, shape (n,), seconds.

    Every piece boundary, four points inside each piece, and every instant a vehicle comes to rest
    and turns (a root of its velocity).
    """
    pieces = schedule_pieces(schedule)
    times = [0.0, schedule.duration]
    for k in range(pieces.count):
        start, length = float(pieces.start[k]), float(pieces.length[k])
        times.extend(start + length * f for f in (0.0, 0.2, 0.4, 0.6, 0.8))
        for v in (0, 1):
            c = pieces.axis[v, k]
            derivative = [i * c[i] for i in range(len(c) - 1, 0, -1)]  # highest power first
            while derivative and abs(derivative[0]) <= 1e-300:
                derivative.pop(0)
            if len(derivative) > 1:
                for root in np.roots(derivative):
                    if abs(root.imag) <= 1e-12 and 0.0 < root.real < length:
                        times.append(start + float(root.real))
    return np.unique(np.clip(times, 0.0, schedule.duration))


def schedule_waypoints(schedule, times: np.ndarray | None = None) -> list[tuple[int, float, int, float]]:
    """Both vehicles' positions along a schedule at :func:`schedule_times`: ``(leg1, s1, leg2, s2)``."""
    times = schedule_times(schedule) if times is None else times
    state = schedule.state(times)
    return [
        (int(state.leg[0, i]), float(state.s[0, i]), int(state.leg[1, i]), float(state.s[1, i]))
        for i in range(times.size)
    ]


def plan_paths(schedule) -> tuple[tuple[VehiclePath, VehiclePath], np.ndarray, np.ndarray]:
    """Both vehicles' paths of a schedule, the instants of :func:`schedule_times`, and the travel there.

    Returns
    -------
    paths : tuple of 2 VehiclePath
        Travel coordinates, each vehicle's axis as the schedule's.
    times : ndarray, shape (n,)
        Seconds.
    travel : ndarray, shape (2, n)
        Each vehicle's travel at ``times``, metres: between two of them a vehicle does not turn, so
        its travel at any ``t`` is the one before plus how far its axis moved since.
    """
    times = schedule_times(schedule)
    waypoints = schedule_waypoints(schedule, times)
    axis = schedule.state(times).axis
    paths = tuple(VehiclePath.from_waypoints(waypoints, v, axis_start=float(axis[v, 0])) for v in (0, 1))
    travel = np.concatenate([np.zeros((2, 1)), np.cumsum(np.abs(np.diff(axis, axis=1)), axis=1)], axis=1)
    return (paths[0], paths[1]), times, travel
