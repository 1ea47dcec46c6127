"""The coordination diagram of a plan: its conflicts, the order it keeps at each, the frontiers.

Each vehicle drives its path of the plan in *travel* coordinates ``p`` (metres
driven along its own path, cusps included, so ``p`` never decreases), on the
schedule's track graph (a junction's legs are its edges). On each pair of path
segments each way between the vehicles is affine in ``(p1, p2)``, so the obstacle
region ``{(p1, p2): distance < d}`` is a union of convex polygons
(:func:`~trajgen.model.graph_cells.too_close_polygons`, one code for every track).
Its connected parts are the **conflicts**. The plan passes each conflict on one
side: the vehicle that passes first is the conflict's **leader**, the other its
**follower** (docs/online.md, 'The executor').

A follower may not come to rest where it would meet a position at which its
leader could still come to rest: the leader's **earliest rest point**
``e = p + v**2 / (2 E)`` onwards (E its emergency deceleration). The smallest
such follower travel over all the conflicts it follows is its **frontier**
(:meth:`CoordinationDiagram.frontier`). Plain floats and tuples: it runs every
control cycle.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from limits import VehicleLimits
from trajgen.model.graph_cells import too_close_polygons
from trajgen.model.graph_paths import GraphPath, path_through
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import Pieces, kinematics_polynomials, schedule_pieces
from trajgen.model.values import sorted_unique

__all__ = [
    "Conflict",
    "CoordinationDiagram",
    "Polygon",
    "SchedulePair",
    "earliest_rest",
    "pair_diagrams",
    "schedule_paths",
    "schedule_times",
    "schedule_waypoints",
    "stopping_distance",
    "stopping_distances",
]

#: A convex polygon of the diagram: its vertices ``(p1, p2)`` in order, metres of travel.
Polygon = tuple[tuple[float, float], ...]
#: Round-off of the diagram's geometry, metres of travel.
_TOUCH = 1e-9
#: Two polygons that share a stretch longer than this (metres) are one conflict; a point is not.
_SHARED = 1e-6


def earliest_rest(p: float, velocity: float, deceleration: float, reversal: float = math.inf) -> float:
    """Earliest travel at which a vehicle at travel ``p`` moving at ``velocity`` (m/s) can be at rest.

    Parameters
    ----------
    p : float
        Travel, metres.
    velocity : float
        Rate of travel, m/s (a negative rate counts as rest: travel never runs back).
    deceleration : float
        The hardest braking possible (emergency), m/s².
    reversal : float, optional
        Travel of the next reversal (or the path's end), metres. A vehicle too fast to stop there
        would come to rest beyond the tip, off its path; the tip stands for it, which only adds
        places to rest (the frontier is a minimum over all places from here on).

    Examples
    --------
    >>> earliest_rest(3.0, 1.0, 2.0)
    3.25
    >>> earliest_rest(3.0, 1.0, 2.0, reversal=3.1)
    3.1
    """
    v = max(velocity, 0.0)
    return min(p + v * v / (2.0 * deceleration), max(reversal, p))


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
    _reaches: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # the leader's largest travel over each polygon: :meth:`bound` runs every control cycle
        reaches = tuple(max(vertex[self.leader] for vertex in polygon) for polygon in self.polygons)
        object.__setattr__(self, "_reaches", reaches)

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
        for polygon, reach in zip(self.polygons, self._reaches, strict=True):
            if reach <= earliest + _TOUCH:
                continue  # at most its boundary is left, where the distance is the separation: allowed
            count = len(polygon)
            for k in range(count):
                a, b = polygon[k], polygon[(k + 1) % count]
                if a[leader] >= earliest and a[follower] < best:
                    best = a[follower]
                if (a[leader] - earliest) * (b[leader] - earliest) < 0.0:  # the edge crosses the line
                    w = (earliest - a[leader]) / (b[leader] - a[leader])
                    crossing = a[follower] + w * (b[follower] - a[follower])
                    if crossing < best:
                        best = crossing
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


def _cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
    """The z of ``(a - o) x (b - o)``: positive when ``o, a, b`` turn counterclockwise."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _area(polygon: list[tuple[float, float]]) -> float:
    return 0.5 * abs(
        sum(
            polygon[k][0] * polygon[(k + 1) % len(polygon)][1]
            - polygon[(k + 1) % len(polygon)][0] * polygon[k][1]
            for k in range(len(polygon))
        )
    )


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
    """The plan's curve ``(p1(t), p2(t))``: travel from each vehicle's axis, exact between samples.

    Between two of the plan's instants no vehicle turns, so its travel there is the travel at the
    instant before plus how far its axis has moved since (on every track: a track graph's schedule
    signs its axis by its path's heading).
    """

    def __init__(self, schedule, times: np.ndarray) -> None:
        self.schedule = schedule
        self.times = times
        axis = schedule.state(times).axis  # (2, n)
        self.axis = axis
        self.travel = np.concatenate(
            [np.zeros((2, 1)), np.cumsum(np.abs(np.diff(axis, axis=1)), axis=1)], axis=1
        )

    def at(self, t: np.ndarray, k: int) -> np.ndarray:
        """Both vehicles' travel at times ``t`` of ``[times[k], times[k + 1]]``, shape (2, n)."""
        axis = self.schedule.state(t).axis
        return self.travel[:, k : k + 1] + np.abs(axis - self.axis[:, k : k + 1])

    def second_when_first_reaches(self, a: float) -> float:
        """``p2`` at the first instant ``p1 >= a`` (the plan's curve is monotone)."""
        k = int(np.searchsorted(self.travel[0], a, side="left"))
        if k == 0:
            return float(self.travel[1, 0])
        if k >= self.times.size:
            return float(self.travel[1, -1])
        low, high = float(self.times[k - 1]), float(self.times[k])
        for _ in range(4):  # 33 points a round: the bracket shrinks 32-fold each time
            t = np.linspace(low, high, 33)
            p = self.at(t, k - 1)
            first = int(np.searchsorted(p[0], a, side="left"))
            first = min(max(first, 1), 32)
            low, high = float(t[first - 1]), float(t[first])
        return float(self.at(np.array([high]), k - 1)[1, 0])


class CoordinationDiagram:
    """The conflicts of a plan and the order it passes them in, for the executor's frontiers.

    Parameters
    ----------
    paths : tuple of 2 GraphPath
        Each vehicle's path of the plan on the schedule's track graph (a junction's too:
        :func:`schedule_paths`), in travel coordinates.
    separation : float
        Track distance the conflicts keep, metres.
    schedule : Schedule or GraphSchedule
        The verified plan: it decides who passes each conflict first.
    times : ndarray, shape (n,)
        Instants of the plan at which neither vehicle turns between two consecutive ones (the
        plan's piece ends and velocity roots: :func:`schedule_times`).
    """

    __slots__ = ("_by_follower", "_chain_table", "_last", "conflicts", "paths", "separation")

    def __init__(self, paths: tuple[GraphPath, ...], separation: float, schedule, times) -> None:
        self.paths = paths
        self.separation = float(separation)
        polygons: list[Polygon] = []
        where: list[tuple[int, int]] = []
        for part in too_close_polygons(
            schedule.track, paths, self.separation
        ):  # convex, one per cell and way
            polygons.append(part.polygon)
            where.append(part.segments)
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
        self._chain_table = tuple(self._chains(v) for v in (0, 1))
        self._last = [(math.nan, math.inf), (math.nan, math.inf)]  # (earliest, frontier) per follower

    def _chains(self, follower: int) -> tuple[tuple[np.ndarray, np.ndarray, float], ...]:
        """The rising lower chain of each polygon of the conflicts ``follower`` follows (:meth:`frontiers`).

        In the plane of (leader's travel, follower's travel) the least follower travel of a convex
        polygon right of a leader travel ``e`` is its lower chain at ``max(e, x*)``, ``x*`` where the
        chain is lowest: from there on the chain only rises. Each entry: the rising part's leader
        and follower travels (increasing leader travel, at least one point) and the polygon's reach.
        """
        chains = []
        for conflict in self._by_follower[follower]:
            leader = conflict.leader
            for polygon, reach in zip(conflict.polygons, conflict._reaches, strict=True):
                points = sorted({(a[leader], a[1 - leader]) for a in polygon})
                lower: list[tuple[float, float]] = []
                for point in points:
                    while len(lower) >= 2 and _cross(lower[-2], lower[-1], point) <= 0.0:
                        lower.pop()
                    if lower and lower[-1][0] == point[0]:
                        continue  # above a point of the same leader travel: not on the lower chain
                    lower.append(point)
                lowest = min(range(len(lower)), key=lambda k: lower[k][1])
                rising = np.array(lower[lowest:])
                chains.append((rising[:, 0].copy(), rising[:, 1].copy(), float(reach)))
        return tuple(chains)

    def frontier(self, follower: int, earliest: float) -> float:
        """The farthest travel ``follower`` may come to rest at, metres (``inf``: nothing binds it).

        Parameters
        ----------
        follower : int
            0 or 1.
        earliest : float
            The other vehicle's earliest rest point (:func:`earliest_rest`), metres of its travel.
        """
        last_earliest, last_frontier = self._last[follower]
        if earliest == last_earliest:  # a leader at rest: the same frontier as the cycle before
            return last_frontier
        best = math.inf
        for conflict in self._by_follower[follower]:
            if conflict.high[conflict.leader] <= earliest + _TOUCH:
                continue  # the leader cannot stop before it is past this conflict
            best = min(best, conflict.bound(earliest))
        self._last[follower] = (earliest, best)
        return best

    def frontiers(self, follower: int, earliest: np.ndarray) -> np.ndarray:
        """:meth:`frontier` for many earliest rest points at once, shape of ``earliest`` (metres).

        Each polygon's least follower travel right of the leader's earliest rest, read off its rising
        lower chain (:meth:`_chains`): time and memory grow with the polygons times the points, one
        array of the points at a time.
        """
        earliest = np.asarray(earliest, dtype=float)
        best = np.full(earliest.shape, math.inf)
        for leader_travel, follower_travel, reach in self._chain_table[follower]:
            value = np.interp(earliest, leader_travel, follower_travel)  # flat left of the lowest point
            # polygons reaching past the earliest rest by more than a boundary
            np.minimum(best, np.where(reach > earliest + _TOUCH, value, math.inf), out=best)
        return best

    def leading(self, vehicle: int, travel: float) -> tuple[Conflict, ...]:
        """The conflicts ``vehicle`` leads that it has not yet passed at ``travel``."""
        return tuple(c for c in self.conflicts if c.leader == vehicle and c.high[vehicle] > travel)


@dataclass(frozen=True, slots=True)
class SchedulePair:
    """Two vehicles of a schedule of any number, as the schedule of two a coordination diagram reads.

    Attributes
    ----------
    schedule : Schedule or GraphSchedule
    pair : tuple of 2 int
        The two vehicles' indices in ``schedule``, in the diagram's order.
    """

    schedule: object
    pair: tuple[int, int]

    @property
    def track(self):
        """The schedule's track graph."""
        return self.schedule.track

    def state(self, t):
        """The two vehicles' states at times ``t`` (:meth:`~trajgen.model.state.TrackState.of`)."""
        return self.schedule.state(t).of(self.pair)


def pair_diagrams(
    schedule, paths: tuple[GraphPath, ...], separation: float, times
) -> tuple[tuple[tuple[int, int], CoordinationDiagram], ...]:
    """The coordination diagram of every pair of a schedule's vehicles: ``((i, j), diagram)``.

    Pairs in the order of ``itertools.combinations``; ``paths`` and ``times`` as
    :func:`schedule_paths` gives them, ``separation`` the distance the conflicts keep, metres.
    """
    return tuple(
        (
            pair,
            CoordinationDiagram(
                (paths[pair[0]], paths[pair[1]]), separation, SchedulePair(schedule, pair), times
            ),
        )
        for pair in itertools.combinations(range(len(paths)), 2)
    )


def stopping_distance(
    velocity: float, acceleration: float, limits: VehicleLimits, *, jerk_limited: bool = True
) -> float:
    """How far the time-optimal jerk-limited stop from a state travels, metres (travel coordinates).

    The stop Ruckig computes (velocity control to rest, within ``max_acceleration`` ``A`` and
    ``max_jerk`` ``J``): jerk ``-J`` until the deceleration peaks (at ``A``, or at
    ``sqrt(J v + a^2 / 2)`` if that is less), held, then ``+J`` back to rest. A vehicle that
    already brakes harder than that comes to rest at the first instant its speed reaches 0.

    Parameters
    ----------
    velocity, acceleration : float
        Rate of travel (m/s, >= 0) and its acceleration (m/s², ``|a| <= A``).
    limits : VehicleLimits
    jerk_limited : bool, optional
        ``False``: the deceleration steps to ``A`` at once, ``v^2 / (2 A)`` (the braking a plan
        that does not limit jerk assumes).

    Examples
    --------
    >>> from limits import VehicleLimits
    >>> stopping_distance(1.0, 0.0, VehicleLimits(1.0, 0.5, 1.0))
    1.25
    >>> stopping_distance(1.0, 0.3, VehicleLimits(1.0, 0.5, 1.0), jerk_limited=False)
    1.0
    """
    # plain floats (it runs every control cycle); stopping_distances is the same for arrays
    a_max, j_max = limits.max_acceleration, limits.max_jerk
    v0, a0 = max(velocity, 0.0), acceleration
    if not jerk_limited:
        return v0 * v0 / (2.0 * a_max)
    if v0 <= 0.0 and a0 <= 0.0:
        return 0.0
    if a0 < 0.0 and v0 - a0 * a0 / (2.0 * j_max) < 0.0:  # braking harder than needed
        t = (-a0 - math.sqrt(max(a0 * a0 - 2.0 * j_max * v0, 0.0))) / j_max
        return v0 * t + a0 * t * t / 2.0 + j_max * t**3 / 6.0
    peak = min(math.sqrt(j_max * v0 + 0.5 * a0 * a0), a_max)
    t1 = max((a0 + peak) / j_max, 0.0)
    v1 = v0 + a0 * t1 - j_max * t1 * t1 / 2.0
    t2 = max((v1 - peak * peak / (2.0 * j_max)) / peak, 0.0) if peak > 0.0 else 0.0
    return _three_phase_distance(v0, a0, j_max, peak, t1, v1, t2)


def _three_phase_distance(v0, a0, j_max, peak, t1, v1, t2):
    """Distance of the S-curve stop: jerk down to ``-peak`` (``t1``), hold it (``t2``), jerk back to 0.

    Floats or arrays alike (``v1``: the speed after the first phase; the last phase lasts ``peak / j_max``).
    """
    v2 = v1 - peak * t2
    t3 = peak / j_max
    return (
        v0 * t1
        + a0 * t1 * t1 / 2.0
        - j_max * t1**3 / 6.0
        + v1 * t2
        - peak * t2 * t2 / 2.0
        + v2 * t3
        - peak * t3 * t3 / 2.0
        + j_max * t3**3 / 6.0
    )


def stopping_distances(
    velocity, acceleration, limits: VehicleLimits, *, jerk_limited: bool = True
) -> np.ndarray:
    """:func:`stopping_distance` of arrays of states, metres; shape of the broadcast inputs."""
    a_max, j_max = limits.max_acceleration, limits.max_jerk
    v0 = np.maximum(np.asarray(velocity, dtype=float), 0.0)
    a0 = np.asarray(acceleration, dtype=float)
    v0, a0 = np.broadcast_arrays(v0, a0)
    if not jerk_limited:
        return v0 * v0 / (2.0 * a_max)
    # braking harder than needed: the speed reaches 0 (under jerk +J at once) while still braking
    overdone = (a0 < 0.0) & (v0 - a0 * a0 / (2.0 * j_max) < 0.0)
    t_zero = (-a0 - np.sqrt(np.maximum(a0 * a0 - 2.0 * j_max * v0, 0.0))) / j_max
    d_zero = v0 * t_zero + a0 * t_zero**2 / 2.0 + j_max * t_zero**3 / 6.0
    peak = np.minimum(np.sqrt(j_max * v0 + 0.5 * a0 * a0), a_max)
    t1 = np.maximum((a0 + peak) / j_max, 0.0)
    v1 = v0 + a0 * t1 - j_max * t1 * t1 / 2.0
    cruise = np.divide(v1 - peak * peak / (2.0 * j_max), peak, out=np.zeros_like(v1), where=peak > 0.0)
    t2 = np.maximum(cruise, 0.0)
    distance = _three_phase_distance(v0, a0, j_max, peak, t1, v1, t2)
    at_rest = (v0 <= 0.0) & (a0 <= 0.0)
    return np.where(at_rest, 0.0, np.where(overdone, d_zero, distance))


def schedule_times(schedule, pieces: Pieces | None = None) -> np.ndarray:
    """Instants of a schedule between which neither vehicle turns, shape (n,), seconds.

    Every piece boundary and middle, and every instant a vehicle comes to rest and turns (a root of
    its velocity). ``pieces``: the schedule's (:func:`~trajgen.model.pieces.schedule_pieces`), if at hand.
    """
    if isinstance(schedule, GraphSchedule):  # travel never turns: the piece boundaries and middles
        times = [np.array([0.0, schedule.duration])]
        for section in schedule.sections:
            knots = section.start_time + kinematics_polynomials(section.kinematics)[0]
            times += [knots, 0.5 * (knots[:-1] + knots[1:])]
        return sorted_unique(np.clip(np.concatenate(times), 0.0, schedule.duration))
    pieces = schedule_pieces(schedule) if pieces is None else pieces
    times = [np.array([0.0, schedule.duration]), pieces.start, pieces.start + 0.5 * pieces.length]
    if pieces.count:
        # the velocity's real roots inside each piece: eigenvalues of its companion matrices, all at once
        velocity = pieces.axis[:, :, 1:] * np.arange(1, pieces.axis.shape[2])  # (2, n, d): increasing powers
        for v in (0, 1):
            c = velocity[v]
            degree = c.shape[1] - 1
            while degree > 0 and np.all(np.abs(c[:, degree]) <= 1e-300):
                degree -= 1
            for d in range(1, degree + 1):  # rows whose leading coefficient is of power d
                rows = np.nonzero(
                    (np.abs(c[:, d]) > 1e-300) & np.all(np.abs(c[:, d + 1 :]) <= 1e-300, axis=1)
                )[0]
                if not rows.size:
                    continue
                companion = np.zeros((rows.size, d, d))
                companion[:, 1:, :-1] = np.eye(d - 1)
                companion[:, :, -1] = -c[rows, :d] / c[rows, d : d + 1]
                roots = np.linalg.eigvals(companion)
                real = (
                    (np.abs(roots.imag) <= 1e-12)
                    & (roots.real > 0.0)
                    & (roots.real < pieces.length[rows, None])
                )
                times.append((pieces.start[rows, None] + roots.real)[real])
    return sorted_unique(np.clip(np.concatenate(times), 0.0, schedule.duration))


def schedule_waypoints(schedule, times: np.ndarray | None = None) -> list[tuple[int, float, int, float]]:
    """Both vehicles' positions along a schedule at :func:`schedule_times`: ``(leg1, s1, leg2, s2)``."""
    times = schedule_times(schedule) if times is None else times
    state = schedule.state(times)
    return [
        (int(state.leg[0, i]), float(state.s[0, i]), int(state.leg[1, i]), float(state.s[1, i]))
        for i in range(times.size)
    ]


def schedule_paths(
    schedule, pieces: Pieces | None = None
) -> tuple[tuple[GraphPath, ...], np.ndarray, np.ndarray]:
    """Both vehicles' paths of a schedule, the instants of :func:`schedule_times`, and the travel there.

    Returns
    -------
    paths : tuple of 2 GraphPath
        On the schedule's track graph, in travel coordinates: a track graph's schedule's own; a
        junction's through its places at the instants (:func:`~trajgen.model.graph_paths.path_through`).
    times : ndarray, shape (n,)
        Seconds.
    travel : ndarray, shape (2, n)
        Each vehicle's travel at ``times``, metres: between two of them a vehicle does not turn, so
        its travel at any ``t`` is the one before plus how far its axis moved since.
    """
    times = schedule_times(schedule, pieces)
    if isinstance(schedule, GraphSchedule):  # its paths are the route's, its travel the schedule's
        return schedule.paths, times, schedule.travel(times)[:, 0]
    state = schedule.state(times)  # between two of the times no vehicle turns: it drives from one to the next
    paths = tuple(path_through(schedule.track, state.edge[v], state.s[v]) for v in range(state.edge.shape[0]))
    travel = np.concatenate(
        [np.zeros((2, 1)), np.cumsum(np.abs(np.diff(state.axis, axis=1)), axis=1)], axis=1
    )
    return paths, times, travel
