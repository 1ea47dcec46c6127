"""Junctions of 3 to 8 legs (STAR-JUNCTIONS.md), rebuilt from the text: ``G_k``, the retraction, ties.

The checks do not trust ``topology``'s own tables: :class:`SpecGraph` rebuilds ``G_k``
from the text of STAR-JUNCTIONS.md section 2 (vertices and edges by formula, exact
lengths, a Dijkstra of its own) and :func:`spec_retract` rebuilds Baldi's retraction
from ALGORITHM.md section 3. Only the seeded perturbation factors ``1 + eta u`` are
taken from the planner (matched edge by edge through the vertices' configurations),
because the ties of rules 2 and 3 are ties under those lengths.

Used by ``tests/test_planner.py`` and ``tests/test_retract_graph.py``, and by the continuity
cases of :mod:`tests.support.continuity`.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass

import pytest

from topology import Configuration, Homotopy, Instruction, Position, StarGraph, plan
from topology.retract_graph import LENGTH_PERTURBATION, TIE_TOLERANCE

#: Leg index of a vehicle at the junction in the indexed form ``(leg1, s1, leg2, s2)``.
AT_O = -1
ETA = LENGTH_PERTURBATION
#: A 4-way crossing with two short legs (S, E), lengths in metres.
LEGS4 = {"N": 10.0, "W": 10.0, "S": 2.0, "E": 3.0}

# -- the spec, rebuilt from its text -------------------------------------------------------------------


def indexed(graph: StarGraph, c: Configuration) -> tuple[int, float, int, float]:
    """``(leg1, s1, leg2, s2)`` with leg indices in counterclockwise order, ``AT_O`` at the junction."""
    return tuple(x for p in c for x in ((AT_O, 0.0) if p.leg is None else (graph.index(p.leg), p.s)))


def named(graph: StarGraph, c: tuple) -> Configuration:
    """The configuration of an indexed one (inverse of :func:`indexed`)."""
    return Configuration(
        *(Position(None, 0.0) if leg == AT_O else Position(graph.names[leg], s) for leg, s in (c[:2], c[2:]))
    )


def vehicle_distance(la: int, sa: float, lb: int, sb: float) -> float:
    """Track distance of two positions (ALGORITHM.md section 1)."""
    return abs(sa - sb) if la == lb and la != AT_O else sa + sb


def travel(a: tuple, b: tuple) -> float:
    """Track distance of vehicle 1 plus vehicle 2 between two configurations: the metric of the routes."""
    return vehicle_distance(a[0], a[1], b[0], b[1]) + vehicle_distance(a[2], a[3], b[2], b[3])


def separation_of(c: tuple) -> float:
    return vehicle_distance(*c)


def spec_retract(c: tuple, lengths: tuple[float, ...]) -> list[tuple]:
    """ALGORITHM.md section 3 from its text: ``c`` first, its boundary image last, no zero step."""
    out = [c]
    l1, s1, l2, s2 = c
    if l1 == l2:  # triangle: the vehicle nearer O moves to O alone
        c = (AT_O, 0.0, l2, s2) if s1 < s2 else (l1, s1, AT_O, 0.0)
        out.append(c)
        l1, s1, l2, s2 = c
    if l1 == AT_O:  # ray: the other vehicle moves out to its end
        if s2 < lengths[l2]:
            out.append((AT_O, 0.0, l2, lengths[l2]))
    elif l2 == AT_O:
        if s1 < lengths[l1]:
            out.append((l1, lengths[l1], AT_O, 0.0))
    else:  # quadrangle: radially out until one of them reaches its end
        r1, r2 = s1 / lengths[l1], s2 / lengths[l2]
        m = max(r1, r2)
        if m < 1.0:
            first = lengths[l1] if r1 == m else min(s1 / m, lengths[l1])
            second = lengths[l2] if r2 == m else min(s2 / m, lengths[l2])
            out.append((l1, first, l2, second))
    return out


def on_boundary(c: tuple, lengths: tuple[float, ...]) -> bool:
    """One vehicle at its leg's end, the other on another leg or at O (a point of ``G_k``)."""
    l1, s1, l2, s2 = c
    if l1 == l2:
        return False
    return (l1 != AT_O and s1 == lengths[l1]) or (l2 != AT_O and s2 == lengths[l2])


@dataclass(frozen=True)
class Point:
    """A point of :class:`SpecGraph`: a vertex, or an edge and the distance from its peak (metres)."""

    vertex: int = -1
    edge: int = -1
    offset: float = 0.0


class SpecGraph:
    """``G_k`` from STAR-JUNCTIONS.md section 2, built from the leg lengths alone.

    Vertices: peaks ``P(i, j)`` (vehicle 1 at ``E_i``, vehicle 2 at ``E_j``, ``i != j``) and
    valleys ``V1(j)`` (vehicle 1 at ``O``, vehicle 2 at ``E_j``), ``V2(i)`` (vehicle 1 at
    ``E_i``, vehicle 2 at ``O``). Edges: ``P(i, j) - V1(j)`` of length ``L_i`` (vehicle 1 runs
    leg ``i``) and ``P(i, j) - V2(i)`` of length ``L_j`` (vehicle 2 runs leg ``j``). The peak
    is each edge's first end. ``factors`` (edge -> ``1 + eta u``) gives the perturbed lengths and
    ``weights`` the 1-form ``w``, both keyed by the (peak, valley) configurations.
    """

    def __init__(
        self, lengths: tuple[float, ...], factors: dict | None = None, weights: dict | None = None
    ) -> None:
        k = len(lengths)
        self.lengths = lengths
        self.vertices: list[tuple] = []
        peak, v1, v2 = {}, {}, {}
        for j in range(k):  # an order of my own: valleys first
            v1[j] = self._add((AT_O, 0.0, j, lengths[j]))
            v2[j] = self._add((j, lengths[j], AT_O, 0.0))
        for i, j in itertools.permutations(range(k), 2):
            peak[i, j] = self._add((i, lengths[i], j, lengths[j]))
        self.index = {c: n for n, c in enumerate(self.vertices)}
        self.edges: list[tuple[int, int]] = []
        self.lengths_of_edges: list[float] = []
        for (i, j), p in peak.items():
            self.edges += [(p, v1[j]), (p, v2[i])]
            self.lengths_of_edges += [lengths[i], lengths[j]]
        self.factors = [1.0] * len(self.edges)
        if factors is not None:
            self.factors = [factors[self.vertices[a], self.vertices[b]] for a, b in self.edges]
        self.weights = [0.0] * len(self.edges)
        if weights is not None:
            self.weights = [weights[self.vertices[a], self.vertices[b]] for a, b in self.edges]
        self.perturbed = [length * f for length, f in zip(self.lengths_of_edges, self.factors, strict=True)]
        self.total_perturbed = math.fsum(self.perturbed)
        self.incident: list[list[int]] = [[] for _ in self.vertices]
        for e, (a, b) in enumerate(self.edges):
            self.incident[a].append(e)
            self.incident[b].append(e)

    def _add(self, c: tuple) -> int:
        self.vertices.append(c)
        return len(self.vertices) - 1

    @classmethod
    def of(cls, graph: StarGraph) -> SpecGraph:
        """The graph of a track, with the planner's perturbation factors (matched by vertex configuration)."""
        rg = graph.retract_graph
        ends = [(rg.vertices[a], rg.vertices[b]) for a, b in rg.edges]
        factors = {pair: float(rg.perturbed_lengths[e] / rg.edge_lengths[e]) for e, pair in enumerate(ends)}
        return cls(graph.lengths, factors, {pair: float(rg.weights[e]) for e, pair in enumerate(ends)})

    # -- points ----------------------------------------------------------------------------------------
    def locate(self, c: tuple) -> Point:
        """The point of a boundary configuration.

        Vehicle 1 at ``E_i`` and vehicle 2 at ``(j, s)`` is on ``P(i, j) - V2(i)``, ``L_j - s`` from
        the peak; symmetrically for vehicle 2 at an end.
        """
        if c in self.index:
            return Point(vertex=self.index[c])
        l1, s1, l2, s2 = c
        lengths = self.lengths
        if l1 != AT_O and s1 == lengths[l1]:
            peak = self.index[(l1, lengths[l1], l2, lengths[l2])]
            valley = self.index[(l1, lengths[l1], AT_O, 0.0)]
            return Point(edge=self.edges.index((peak, valley)), offset=lengths[l2] - s2)
        peak = self.index[(l1, lengths[l1], l2, lengths[l2])]
        valley = self.index[(AT_O, 0.0, l2, lengths[l2])]
        return Point(edge=self.edges.index((peak, valley)), offset=lengths[l1] - s1)

    def configuration(self, point: Point) -> tuple:
        """The boundary configuration at a point (inverse of :meth:`locate`)."""
        if point.vertex >= 0:
            return self.vertices[point.vertex]
        peak, valley = self.edges[point.edge]
        l1, s1, l2, s2 = self.vertices[peak]
        if self.vertices[valley][0] == AT_O:  # vehicle 1 runs its leg
            return (l1, s1 - point.offset, l2, s2)
        return (l1, s1, l2, s2 - point.offset)

    def edges_holding(self, c: tuple) -> set[int]:
        """The edges whose closed segment holds a boundary configuration."""
        point = self.locate(c)
        return set(self.incident[point.vertex]) if point.vertex >= 0 else {point.edge}

    # -- shortest routes ---------------------------------------------------------------------------------
    def _network(self, points, perturbed: bool, removed=(), banned=()) -> tuple[dict, list[int]]:
        """Adjacency ``node -> [(neighbour, length, edge)]`` with the points as extra nodes."""
        size = len(self.vertices)
        nodes, cuts = [], {}
        for n, point in enumerate(points):
            if point.vertex >= 0:
                nodes.append(point.vertex)
            else:
                nodes.append(size + n)
                cuts.setdefault(point.edge, []).append((point.offset, size + n))
        adjacency: dict[int, list] = {}
        for e, (peak, valley) in enumerate(self.edges):
            if e in removed:
                continue
            factor = self.factors[e] if perturbed else 1.0
            chain = [(0.0, peak), *sorted(cuts.get(e, [])), (self.lengths_of_edges[e], valley)]
            for (s0, u), (s1, v) in itertools.pairwise(chain):
                if frozenset((u, v)) in banned:
                    continue
                adjacency.setdefault(u, []).append((v, (s1 - s0) * factor, e))
                adjacency.setdefault(v, []).append((u, (s1 - s0) * factor, e))
        return adjacency, nodes

    def route(
        self, x: Point, y: Point, *, perturbed: bool = False, removed=(), banned=()
    ) -> tuple[float, list[int]]:
        """Length of a shortest route from ``x`` to ``y`` and the vertices of ``G_k`` it passes (Dijkstra).

        ``removed``: edges not to use; ``banned``: pieces ``frozenset({u, v})`` of edges not to
        use, between nodes (a vertex, or ``x`` and ``y`` numbered after the vertices, see :meth:`node`).
        """
        if x == y:
            return 0.0, [x.vertex] if x.vertex >= 0 else []
        adjacency, (origin, target) = self._network((x, y), perturbed, removed, banned)
        best, previous, queue, done = {origin: 0.0}, {}, [(0.0, origin)], set()
        while queue:
            d, u = heapq.heappop(queue)
            if u in done:
                continue
            done.add(u)
            if u == target:
                path = [u]
                while path[-1] != origin:
                    path.append(previous[path[-1]])
                return d, [v for v in reversed(path) if v < len(self.vertices)]
            for v, length, _ in adjacency.get(u, []):
                if d + length < best.get(v, math.inf):
                    best[v], previous[v] = d + length, u
                    heapq.heappush(queue, (d + length, v))
        return math.inf, []

    def length(self, x: Point, y: Point, *, perturbed: bool = False, removed=(), banned=()) -> float:
        return self.route(x, y, perturbed=perturbed, removed=removed, banned=banned)[0]

    def node(self, c: tuple, x: Point, y: Point) -> int:
        """The node of a configuration in the network of a route from ``x`` to ``y``."""
        point = self.locate(c)
        if point.vertex >= 0:
            return point.vertex
        return len(self.vertices) + (0 if point == x else 1)

    def offset(self, c: tuple, edge: int) -> float:
        """Distance from the peak of ``edge`` of a configuration on it, metres."""
        point = self.locate(c)
        if point.vertex < 0:
            return point.offset
        return 0.0 if self.edges[edge][0] == point.vertex else self.lengths_of_edges[edge]

    def common_edge(self, a: tuple, b: tuple) -> int:
        (edge,) = self.edges_holding(a) & self.edges_holding(b)
        return edge

    def w_integral(self, walk: list[tuple]) -> float:
        """Integral of the 1-form ``w`` along a walk on ``G_k`` (peak to valley positive)."""
        total = 0.0
        for a, b in itertools.pairwise(walk):
            e = self.common_edge(a, b)
            total += (self.offset(b, e) - self.offset(a, e)) / self.lengths_of_edges[e] * self.weights[e]
        return total

    def walk(self, x: Point, vertices: list[int], y: Point) -> list[tuple]:
        """The configurations of a route from ``x`` through ``vertices`` to ``y``, no zero step."""
        inner = [self.vertices[v] for v in vertices]
        return drop_zero_steps([self.configuration(x), *inner, self.configuration(y)])

    def ends(self, point: Point) -> list[tuple[int, float]]:
        """(vertex, perturbed distance) to each end of a point's edge (the point itself for a vertex)."""
        if point.vertex >= 0:
            return [(point.vertex, 0.0)]
        peak, valley = self.edges[point.edge]
        factor = self.factors[point.edge]
        return [
            (peak, point.offset * factor),
            (valley, (self.lengths_of_edges[point.edge] - point.offset) * factor),
        ]

    def candidates(self, x: Point, y: Point) -> dict[tuple[int, int], tuple[float, list[int]]]:
        """Per pair (end of x's edge, end of y's edge): perturbed length and vertices of the route via them.

        In between, the route avoids both points' edges, so routes via different ends differ.
        Points on different edges (or at vertices) only.
        """
        removed = {p.edge for p in (x, y) if p.vertex < 0}
        found = {}
        for a, da in self.ends(x):
            for b, db in self.ends(y):
                d, vertices = self.route(Point(vertex=a), Point(vertex=b), perturbed=True, removed=removed)
                found[a, b] = (da + d + db, vertices)
        return found


# -- the planner's route, taken apart ------------------------------------------------------------------


def drop_zero_steps(waypoints: list[tuple]) -> list[tuple]:
    kept = waypoints[:1]
    for c in waypoints[1:]:
        if travel(kept[-1], c) > 0.0:
            kept.append(c)
    return kept


def assert_same_waypoints(got, expected, tolerance: float = 1e-9) -> None:
    assert len(got) == len(expected), (got, expected)
    for a, b in zip(got, expected, strict=True):
        assert (a[0], a[2]) == (b[0], b[2]), (got, expected)
        assert a[1] == pytest.approx(b[1], abs=tolerance), (got, expected)
        assert a[3] == pytest.approx(b[3], abs=tolerance), (got, expected)


def boundary_walk(route, spec: SpecGraph) -> list[tuple]:
    """The part of the route on ``G_k``, checked against the spec: retractions around a walk on ``G_k``.

    Returns the waypoints from ``r(start)`` to ``r(goal)``, after checking that the route is
    ``retract(start)`` + that walk + ``reversed(retract(goal))``, that the walk stays on
    ``G_k``, moves along one edge per segment and stops only at vertices of ``G_k`` inside.
    """
    lengths = spec.lengths
    w = list(route.indexed_waypoints)
    on = [n for n, c in enumerate(w) if on_boundary(c, lengths)]
    assert on, w
    first, last = on[0], on[-1]
    assert on == list(range(first, last + 1)), "the route leaves G_k between the retractions"
    graph = route.graph
    assert_same_waypoints(w[: first + 1], spec_retract(indexed(graph, route.start), lengths))
    assert_same_waypoints(w[last:][::-1], spec_retract(indexed(graph, route.goal), lengths))
    walk = w[first : last + 1]
    for a, b in itertools.pairwise(walk):
        assert spec.edges_holding(a) & spec.edges_holding(b), f"{a} -> {b} is not along an edge of G_k"
    for c in walk[1:-1]:
        assert c in spec.index, f"the walk stops at {c}, not a vertex of G_k"
    return walk


def walk_length(walk: list[tuple]) -> float:
    return math.fsum(travel(a, b) for a, b in itertools.pairwise(walk))


def segment_legs(a: tuple, b: tuple) -> tuple[int, int]:
    """The leg of each vehicle during a segment (``AT_O`` when it stays at the junction), checked."""
    legs = []
    for la, lb in ((a[0], b[0]), (a[2], b[2])):
        assert AT_O in (la, lb) or la == lb, f"a vehicle changes legs inside the segment {a} -> {b}"
        legs.append(la if la != AT_O else lb)
    return legs[0], legs[1]


def closed_form_min_separation(a: tuple, b: tuple) -> float:
    """Least track distance along a segment: ``s1 + s2`` (different legs) or ``|s1 - s2|`` is linear."""
    l1, l2 = segment_legs(a, b)
    if l1 == l2 != AT_O:
        d0, d1 = a[1] - a[3], b[1] - b[3]
        return 0.0 if d0 * d1 <= 0.0 else min(abs(d0), abs(d1))
    return min(a[1] + a[3], b[1] + b[3])


def sampled_min_separation(a: tuple, b: tuple, count: int = 64) -> float:
    l1, l2 = segment_legs(a, b)
    least = math.inf
    for n in range(count + 1):
        f = n / count
        s1, s2 = (1 - f) * a[1] + f * b[1], (1 - f) * a[3] + f * b[3]
        least = min(least, abs(s1 - s2) if l1 == l2 != AT_O and s1 > 0 and s2 > 0 else s1 + s2)
    return least


def check_valid_route(graph: StarGraph, start, goal, separation: float, route) -> None:
    """ALGORITHM.md section 5's promises, for any k: exact ends, one leg per segment, separation, length."""
    assert route.waypoints[0] == start
    assert route.waypoints[-1] == goal
    w = route.indexed_waypoints
    assert w[0] == indexed(graph, start)
    assert w[-1] == indexed(graph, goal)
    for c, configuration in zip(w, route.waypoints, strict=True):
        assert named(graph, c) == configuration
    floor = min(graph.separation(start), graph.separation(goal), graph.shortest_leg)
    assert floor >= separation
    tolerance = 1e-9 * graph.boundary_length
    steps = []
    for a, b in itertools.pairwise(w):
        steps.append(travel(a, b))
        assert steps[-1] > 0.0, f"zero-length segment {a} -> {b}"
        assert closed_form_min_separation(a, b) >= floor - tolerance, (a, b, floor)
        assert sampled_min_separation(a, b) >= floor - tolerance, (a, b, floor)
    assert route.length == pytest.approx(math.fsum(steps), rel=1e-12, abs=1e-12)
    assert route.cumulative_travel == pytest.approx(
        list(itertools.accumulate(steps, initial=0.0)), rel=1e-12, abs=1e-12
    )
    assert route.instruction in Instruction.of_track(graph)
    assert route.homotopy is Homotopy.PLANNED or route.homotopy is Homotopy.OTHER


def plan_indexed(graph: StarGraph, start: tuple, goal: tuple):
    """The planner's route between two indexed configurations."""
    return plan(graph, named(graph, start), named(graph, goal))


# -- ties of two and three routes, built from the perturbed lengths ---------------------------------------


def arrivals(spec: SpecGraph, x: Point, edge: int) -> tuple[float, float]:
    """Perturbed length of the best route from ``x`` to the peak and to the valley of ``edge``.

    The routes leave ``x`` through an end of its edge and do not run along ``edge``.
    """
    removed = {edge} | ({x.edge} if x.vertex < 0 else set())
    return tuple(
        min(
            dx + spec.length(Point(vertex=a), Point(vertex=end), perturbed=True, removed=removed)
            for a, dx in spec.ends(x)
        )
        for end in spec.edges[edge]
    )


def two_tie(spec: SpecGraph, x: Point, edge: int) -> float | None:
    """The offset on ``edge`` where the routes from ``x`` via its peak and via its valley tie.

    ``None`` unless it lies well inside the edge and the two tied routes beat every other
    candidate by a clear margin (so exactly two tie).
    """
    if x.vertex < 0 and x.edge == edge:
        return None
    to_peak, to_valley = arrivals(spec, x, edge)
    length, factor = spec.lengths_of_edges[edge], spec.factors[edge]
    t = (to_valley - to_peak + length * factor) / (2 * factor)
    if not 0.02 * length < t < 0.98 * length:
        return None
    lengths = sorted(d for d, _ in spec.candidates(x, Point(edge=edge, offset=t)).values())
    if (
        lengths[1] - lengths[0] > 1e-9 * spec.total_perturbed
        or lengths[2] - lengths[0] < MARGIN * spec.total_perturbed
    ):
        return None
    return t


#: Third-best route at least this fraction of the total length of G_k behind a tie of two.
MARGIN = 1e-6


def three_tie(spec: SpecGraph, edge_x: int, edge_y: int, missing: tuple[int, int]):
    """Offsets ``(a, b)`` on two edges where the three routes via all pairs of ends but ``missing`` tie.

    ``missing`` is (end of x, end of y) by position 0 (peak) or 1 (valley). Solves the two
    linear equations in the offsets; ``None`` if the point is not well inside both edges or
    the fourth route is not clearly longer.
    """
    if edge_x == edge_y:
        return None
    removed = {edge_x, edge_y}
    ends_x, ends_y = spec.edges[edge_x], spec.edges[edge_y]
    fx, fy = spec.factors[edge_x], spec.factors[edge_y]
    lx, ly = spec.lengths_of_edges[edge_x], spec.lengths_of_edges[edge_y]

    def form(ex: int, ey: int) -> tuple[float, float, float]:
        """(coefficient of a, coefficient of b, constant) of the perturbed length via ends ex, ey."""
        d = spec.length(Point(vertex=ends_x[ex]), Point(vertex=ends_y[ey]), perturbed=True, removed=removed)
        return (
            fx if ex == 0 else -fx,
            fy if ey == 0 else -fy,
            d + (lx * fx if ex else 0.0) + (ly * fy if ey else 0.0),
        )

    pairs = [p for p in itertools.product((0, 1), repeat=2) if p != missing]
    (a1, b1, c1), (a2, b2, c2), (a3, b3, c3) = (form(*p) for p in pairs)
    if math.inf in (c1, c2, c3):
        return None
    det = (a1 - a2) * (b1 - b3) - (a1 - a3) * (b1 - b2)
    if det == 0.0:
        return None
    a = ((c2 - c1) * (b1 - b3) - (c3 - c1) * (b1 - b2)) / det
    b = ((a1 - a2) * (c3 - c1) - (a1 - a3) * (c2 - c1)) / det
    if not (0.02 * lx < a < 0.98 * lx and 0.02 * ly < b < 0.98 * ly):
        return None
    am, bm, cm = form(*missing)
    if am * a + bm * b + cm - (a1 * a + b1 * b + c1) < MARGIN * spec.total_perturbed:
        return None
    return a, b


def tied_routes(spec: SpecGraph, x: Point, y: Point) -> list[tuple[float, list[int]]]:
    """The candidate routes within the tie tolerance of the shortest, shortest first (computed here)."""
    found = sorted(spec.candidates(x, y).values())
    return [r for r in found if r[0] <= found[0][0] + TIE_TOLERANCE * spec.total_perturbed]


def scaled_indexed(c: tuple, factor: float) -> tuple:
    """Both vehicles pulled toward the junction by ``factor`` in (0, 1]: the same boundary image."""
    return (c[0], c[1] * factor, c[2], c[3] * factor)


def first_two_tie(spec: SpecGraph) -> tuple[Point, Point]:
    """The first (x a third along edge 0, y on the first edge that works) where exactly two routes tie."""
    x = Point(edge=0, offset=spec.lengths_of_edges[0] / 3)
    for edge in range(len(spec.edges)):
        t = two_tie(spec, x, edge)
        if t is not None:
            return x, Point(edge=edge, offset=t)
    raise AssertionError("no tie of two routes found")


def first_three_tie(spec: SpecGraph) -> tuple[Point, Point]:
    """The first pair of edges (and route left out) whose three-way tie point is well inside both edges."""
    for edge_x, edge_y in itertools.product(range(len(spec.edges)), repeat=2):
        for missing in itertools.product((0, 1), repeat=2):
            found = three_tie(spec, edge_x, edge_y, missing)
            if found is not None:
                return Point(edge=edge_x, offset=found[0]), Point(edge=edge_y, offset=found[1])
    raise AssertionError("no tie of three routes found")
