"""The retract graph ``G_k`` of a junction with k legs and its geodesic planner (docs/star.md).

Baldi's retraction maps every configuration onto ``G_k``: the ``k (k - 1)``
peaks ``P(i, j)`` (vehicle 1 at ``E_i``, vehicle 2 at ``E_j``), the ``2 k``
valleys ``V1(j)`` (vehicle 1 at ``O``, vehicle 2 at ``E_j``) and ``V2(i)``
(vehicle 1 at ``E_i``, vehicle 2 at ``O``), and the edges ``P(i, j) - V1(j)``
(length ``L_i``: vehicle 1 runs leg ``i``) and ``P(i, j) - V2(i)`` (length
``L_j``: vehicle 2 runs leg ``j``). Every edge is oriented from its peak to its
valley.

The route on ``G_k`` between two located points is chosen by three rules:

1. exactly one shortest route under the perturbed edge lengths: take it;
2. exactly two tie: take the one with the larger integral of the 1-form ``w``;
3. three or more tie: the tied route with the largest integral of ``w`` (a
   fixed deterministic choice).

For k >= 4 each edge length is multiplied by ``1 + eta u`` (``eta`` =
:data:`LENGTH_PERTURBATION`, ``u`` in [0, 1) seeded by k and the edge) and
``w`` is a seeded generic weight in [-1, 1] per edge, so that ties of three
or more routes are isolated points and two tied routes differ by a cycle of
non-zero ``w``-integral. For k = 3 ``G_3`` is the 12-cycle of docs/planner.md
section 4: lengths are exact and ``w`` is +1 counterclockwise round the
cycle, so rule 2 is the paper's counterclockwise half turn.
"""

from __future__ import annotations

import heapq
import itertools
import math
import random
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from topology.errors import PositionError
from topology.indexed import JUNCTION_INDEX, IndexedConfiguration
from topology.legs import LegTable
from topology.positions import Configuration

__all__ = [
    "LENGTH_PERTURBATION",
    "PERTURBATION_SEED",
    "TIE_TOLERANCE",
    "Geodesic",
    "GraphPoint",
    "RetractGraph",
]

#: The relative perturbation ``eta`` of the edge lengths of ``G_k`` for k >= 4.
LENGTH_PERTURBATION = 1e-3
#: Seed of the perturbations ``u`` and of the 1-form ``w`` (combined with k).
PERTURBATION_SEED = 5050
#: Two routes tie when their (perturbed) lengths differ by at most this fraction of the total
#: length of ``G_k``: for k = 3, the antipodal tolerance of docs/planner.md (instructions; 1e-9 of the
#: perimeter either side of half a turn).
TIE_TOLERANCE = 2e-9


class GraphPoint(NamedTuple):
    """A point of ``G_k``: a vertex, or a point inside an edge.

    Attributes
    ----------
    vertex : int
        Vertex index, or -1 inside an edge.
    edge : int
        Edge index, or -1 at a vertex.
    offset : float
        Inside an edge: distance from the edge's peak, metres, ``0 < offset < length``; else 0.
    """

    vertex: int
    edge: int
    offset: float


@dataclass(frozen=True, slots=True)
class Geodesic:
    """A route on ``G_k`` between two points, as the three rules chose it.

    Attributes
    ----------
    vertices : tuple of int
        Indices of the vertices passed, in order; shape (m,), ``m >= 0``.
    length : float
        Length along ``G_k``, metres.
    perturbed_length : float
        Length under the perturbed edge lengths, metres.
    weight : float
        Integral of the 1-form ``w`` along the route (an edge traversed whole from peak
        to valley contributes its ``w``).
    tied : int
        How many distinct shortest routes tied (1, 2, or 3 and more): the rule that chose it.
    """

    vertices: tuple[int, ...]
    length: float
    perturbed_length: float
    weight: float
    tied: int


class _Path(NamedTuple):
    vertices: tuple[int, ...]
    weight: float
    length: float
    first_edge: int
    last_edge: int


class RetractGraph:
    """Per-track tables of ``G_k``: vertices, edges, perturbed lengths, the 1-form, shortest paths.

    Parameters
    ----------
    names : tuple of str, shape (k,)
        Leg names in counterclockwise order.
    lengths : tuple of float, shape (k,)
        Leg lengths, metres.

    Attributes
    ----------
    vertices : tuple of IndexedConfiguration, shape (k (k + 1),)
        Peaks ``P(i, j)`` in the order of ``(i, j)``, then valleys ``V1(0..k-1)``,
        then valleys ``V2(0..k-1)``.
    vertex_configurations : tuple of Configuration, shape (k (k + 1),)
        The same vertices as configurations.
    edges : tuple of (int, int), shape (2 k (k - 1),)
        ``(peak, valley)`` vertex indices of each edge (its orientation).
    edge_lengths : numpy.ndarray, shape (2 k (k - 1),)
        Lengths, metres (read-only).
    perturbed_lengths : numpy.ndarray, shape (2 k (k - 1),)
        Lengths times ``1 + eta u``, metres (read-only; exact for k = 3).
    weights : numpy.ndarray, shape (2 k (k - 1),)
        The 1-form ``w``, per edge from peak to valley (read-only).
    distances : numpy.ndarray, shape (k (k + 1), k (k + 1))
        Shortest perturbed distance between vertices, metres (read-only); the shortest
        vertex paths themselves are tabulated too, so that a query only looks them up.
    total_length : float
        Sum of the perturbed edge lengths, metres: the scale of the tie tolerance.
    """

    __slots__ = (
        "_adjacent",
        "_distance_rows",
        "_edge_length",
        "_legs",
        "_paths",
        "_peak",
        "_perturbed_length",
        "_tolerance",
        "_valley_first_at_junction",
        "_valley_second_at_junction",
        "_weight",
        "distances",
        "edge_lengths",
        "edges",
        "names",
        "perturbed_lengths",
        "total_length",
        "vertex_configuration",
        "vertex_configurations",
        "vertices",
        "weights",
    )

    def __init__(self, names: tuple[str, ...], lengths: tuple[float, ...]) -> None:
        count = len(names)
        self.names = names
        self._legs = LegTable(names, lengths)
        vertices: list[IndexedConfiguration] = []
        self._peak: dict[tuple[int, int], int] = {}
        for i in range(count):
            for j in range(count):
                if i != j:
                    self._peak[(i, j)] = len(vertices)
                    vertices.append((i, lengths[i], j, lengths[j]))
        self._valley_first_at_junction = {j: len(vertices) + j for j in range(count)}
        vertices.extend((JUNCTION_INDEX, 0.0, j, lengths[j]) for j in range(count))
        self._valley_second_at_junction = {i: len(vertices) + i for i in range(count)}
        vertices.extend((i, lengths[i], JUNCTION_INDEX, 0.0) for i in range(count))
        self.vertices = tuple(vertices)
        self.vertex_configurations = tuple(self._legs.configuration(c) for c in vertices)
        #: Vertex tuple -> its Configuration, so route waypoints at vertices share one object.
        self.vertex_configuration = dict(zip(self.vertices, self.vertex_configurations, strict=True))

        edges: list[tuple[int, int]] = []
        edge_lengths: list[float] = []
        counterclockwise: list[float] = []
        for (i, j), peak in self._peak.items():
            edges.append((peak, self._valley_first_at_junction[j]))  # vehicle 1 runs leg i
            edge_lengths.append(lengths[i])
            counterclockwise.append(1.0 if i == (j + 1) % count else -1.0)
            edges.append((peak, self._valley_second_at_junction[i]))  # vehicle 2 runs leg j
            edge_lengths.append(lengths[j])
            counterclockwise.append(1.0 if j == (i + 1) % count else -1.0)
        self.edges = tuple(edges)
        self.edge_lengths = _read_only(np.array(edge_lengths))
        if count == 3:  # the circle: exact lengths, w counterclockwise (docs/planner.md)
            factors = np.ones(len(edges))
            weights = np.array(counterclockwise)
        else:
            rng = random.Random(f"{PERTURBATION_SEED}-{count}")
            factors = np.array([1.0 + LENGTH_PERTURBATION * rng.random() for _ in edges])
            weights = np.array([rng.uniform(-1.0, 1.0) for _ in edges])
        self.perturbed_lengths = _read_only(self.edge_lengths * factors)
        self.weights = _read_only(weights)
        # plain floats for the queries (faster than numpy scalars, and results are Python floats)
        self._edge_length = tuple(self.edge_lengths.tolist())
        self._perturbed_length = tuple(self.perturbed_lengths.tolist())
        self._weight = tuple(self.weights.tolist())
        self.total_length = float(math.fsum(self.perturbed_lengths))
        self._tolerance = TIE_TOLERANCE * self.total_length

        self._adjacent: list[list[tuple[int, int]]] = [[] for _ in vertices]
        for e, (peak, valley) in enumerate(edges):
            self._adjacent[peak].append((valley, e))
            self._adjacent[valley].append((peak, e))
        size = len(vertices)
        distances = np.full((size, size), np.inf)
        np.fill_diagonal(distances, 0.0)
        for e, (peak, valley) in enumerate(edges):
            distances[peak, valley] = distances[valley, peak] = self.perturbed_lengths[e]
        for via in range(size):  # Floyd-Warshall, one row and column at a time
            np.minimum(distances, distances[:, via, None] + distances[None, via, :], out=distances)
        self.distances = _read_only(distances)
        self._distance_rows = distances.tolist()
        self._paths: dict[tuple[int, int], tuple[_Path, ...]] = {}
        for a in range(size):
            for b in range(size):
                self._shortest_paths(a, b)

    # -- points of G_k -----------------------------------------------------
    def locate(self, c: IndexedConfiguration) -> GraphPoint:
        """The point of ``G_k`` of a boundary configuration (one vehicle at a leg's end).

        Vehicle 1 at ``E_i`` and vehicle 2 at ``(j, s)`` lie on the edge
        ``P(i, j) - V2(i)``, ``L_j - s`` from the peak; symmetrically for
        vehicle 2 at an endpoint.
        """
        l1, s1, l2, s2 = c
        lengths = self._legs.lengths
        if l1 != JUNCTION_INDEX and s1 == lengths[l1]:  # vehicle 1 at E_l1
            if l2 == JUNCTION_INDEX:
                return GraphPoint(self._valley_second_at_junction[l1], -1, 0.0)
            peak = self._peak[(l1, l2)]
            if s2 == lengths[l2]:
                return GraphPoint(peak, -1, 0.0)
            return GraphPoint(-1, 2 * peak + 1, lengths[l2] - s2)
        if l2 == JUNCTION_INDEX or s2 != lengths[l2]:
            raise PositionError(
                f"configuration {c!r} is not on the boundary: expected a vehicle at a leg's end "
                "(retract it first)"
            )
        if l1 == JUNCTION_INDEX:
            return GraphPoint(self._valley_first_at_junction[l2], -1, 0.0)
        return GraphPoint(-1, 2 * self._peak[(l1, l2)], lengths[l1] - s1)

    def configuration(self, point: GraphPoint) -> Configuration:
        """The boundary configuration at a point of ``G_k``."""
        if point.vertex >= 0:
            return self.vertex_configurations[point.vertex]
        peak = self.vertices[self.edges[point.edge][0]]
        l1, s1, l2, s2 = peak
        if point.edge % 2:  # vehicle 2 runs its leg
            return self._legs.configuration((l1, s1, l2, s2 - point.offset))
        return self._legs.configuration((l1, s1 - point.offset, l2, s2))

    def same_point(self, x: GraphPoint, y: GraphPoint, tolerance: float) -> bool:
        """Whether two points are within ``tolerance`` metres of each other along their edge (or equal)."""
        if x.vertex >= 0 or y.vertex >= 0:
            return x == y or self._distance_along(x, y) <= tolerance
        return x.edge == y.edge and abs(x.offset - y.offset) <= tolerance

    def _distance_along(self, x: GraphPoint, y: GraphPoint) -> float:
        if x.vertex >= 0 and y.vertex >= 0:
            return math.inf
        vertex, point = (x, y) if x.vertex >= 0 else (y, x)
        peak, valley = self.edges[point.edge]
        if vertex.vertex == peak:
            return point.offset
        if vertex.vertex == valley:
            return self._edge_length[point.edge] - point.offset
        return math.inf

    # -- routes ------------------------------------------------------------
    def _ends(self, point: GraphPoint, leaving: bool) -> list[tuple[int, float, float, float, int]]:
        """(vertex, perturbed distance, w-integral, metres, edge) from/to each end of a point's edge."""
        if point.vertex >= 0:
            return [(point.vertex, 0.0, 0.0, 0.0, -1)]
        e = point.edge
        peak, valley = self.edges[e]
        length = self._edge_length[e]
        factor = self._perturbed_length[e] / length
        fraction = point.offset / length
        w = self._weight[e]
        sign = -1.0 if leaving else 1.0  # leaving towards the peak runs against the orientation
        rest = length - point.offset
        return [
            (peak, point.offset * factor, sign * fraction * w, point.offset, e),
            (valley, rest * factor, -sign * (1.0 - fraction) * w, rest, e),
        ]

    def _shortest_paths(self, a: int, b: int) -> tuple[_Path, ...]:
        """Every shortest vertex path from ``a`` to ``b`` (one, except for exact ties: k = 3)."""
        key = (a, b)
        paths = self._paths.get(key)
        if paths is not None:
            return paths
        if a == b:
            paths = (_Path((a,), 0.0, 0.0, -1, -1),)
        else:
            found = []
            target = self._distance_rows[a][b]
            for neighbour, e in self._adjacent[a]:
                if self._perturbed_length[e] + self._distance_rows[neighbour][b] <= target + self._tolerance:
                    forward = 1.0 if self.edges[e][0] == a else -1.0
                    for rest in self._shortest_paths(neighbour, b):
                        found.append(
                            _Path(
                                (a, *rest.vertices),
                                forward * self._weight[e] + rest.weight,
                                self._edge_length[e] + rest.length,
                                e,
                                e if rest.last_edge < 0 else rest.last_edge,
                            )
                        )
            paths = tuple(found)
        self._paths[key] = paths
        return paths

    def candidates(self, x: GraphPoint, y: GraphPoint) -> list[Geodesic]:
        """The locally shortest routes from ``x`` to ``y`` the rules choose among, shortest first.

        One per pair of ends of the two points' edges (and the direct one along a shared
        edge), without those that run back along their own edge.
        """
        found: list[Geodesic] = []
        for a, da, wa, ra, ea in self._ends(x, leaving=True):
            for b, db, wb, rb, eb in self._ends(y, leaving=False):
                row = self._distance_rows[a][b]
                for path in self._shortest_paths(a, b):
                    if ea >= 0 and (path.first_edge == ea or (len(path.vertices) == 1 and ea == eb)):
                        continue  # runs back along x's edge: the same route as via its other end
                    if eb >= 0 and path.last_edge == eb:
                        continue
                    found.append(
                        Geodesic(
                            path.vertices, ra + path.length + rb, da + row + db, wa + path.weight + wb, 0
                        )
                    )
        if x.vertex < 0 and x.edge == y.edge:
            length = self._edge_length[x.edge]
            factor = self._perturbed_length[x.edge] / length
            along = abs(y.offset - x.offset)
            weight = (y.offset - x.offset) / length * self._weight[x.edge]
            found.append(Geodesic((), along, along * factor, weight, 0))
        found.sort(key=lambda g: g.perturbed_length)
        return found

    def shortest(self, x: GraphPoint, y: GraphPoint) -> Geodesic:
        """The route of the three rules from ``x`` to ``y``; ``tied`` tells the rule."""
        found = self.candidates(x, y)
        bound = found[0].perturbed_length + self._tolerance
        tied = [g for g in found if g.perturbed_length <= bound]
        best = max(tied, key=lambda g: g.weight) if len(tied) > 1 else tied[0]
        return Geodesic(best.vertices, best.length, best.perturbed_length, best.weight, min(len(tied), 3))

    def second_shortest(self, x: GraphPoint, y: GraphPoint, route: Geodesic) -> Geodesic:
        """The shortest route from ``x`` to ``y`` other than ``route`` (another homotopy class).

        Every simple route other than ``route`` misses one of its edges, so this is the
        shortest of the shortest routes with one of ``route``'s edges removed.
        """
        adjacency, nodes = self._split(x, y)
        origin, target = nodes
        steps = self._steps(origin, route.vertices, target)
        best: tuple[float, list[int]] | None = None
        for banned in steps:
            found = _dijkstra(adjacency, origin, target, banned)
            if found is not None and (best is None or found[0] < best[0]):
                best = found
        if best is None:  # G_k is connected with cycles, so this does not happen
            raise RuntimeError("no second route on the retract graph")
        path = best[1]
        length = weight = 0.0
        for u, v in itertools.pairwise(path):
            _e, fraction_weight, metres = adjacency[u][v][1:]
            length += metres
            weight += fraction_weight
        vertices = tuple(v for v in path if v < len(self.vertices))
        return Geodesic(vertices, length, best[0], weight, 1)

    def _split(self, x: GraphPoint, y: GraphPoint):
        """Adjacency ``u -> {v: (perturbed, edge, w-integral u->v, metres)}`` with x and y as vertices."""
        size = len(self.vertices)
        adjacency: list[dict[int, tuple[float, int, float, float]]] = [{} for _ in range(size + 2)]

        def connect(u: int, v: int, e: int, start: float, end: float) -> None:
            length = self._edge_length[e]
            metres = end - start
            factor = self._perturbed_length[e] / length
            w = self._weight[e] * metres / length
            adjacency[u][v] = (metres * factor, e, w, metres)
            adjacency[v][u] = (metres * factor, e, -w, metres)

        nodes = []
        cuts: dict[int, list[tuple[float, int]]] = {}
        for k, point in enumerate((x, y)):
            if point.vertex >= 0:
                nodes.append(point.vertex)
            else:
                nodes.append(size + k)
                cuts.setdefault(point.edge, []).append((point.offset, size + k))
        for e, (peak, valley) in enumerate(self.edges):
            chain = [(0.0, peak), *sorted(cuts.get(e, [])), (self._edge_length[e], valley)]
            for (s0, u), (s1, v) in itertools.pairwise(chain):
                if u != v:
                    connect(u, v, e, s0, s1)
        return adjacency, nodes

    def _steps(self, origin: int, vertices: tuple[int, ...], target: int) -> list[tuple[int, int]]:
        sequence = [origin, *vertices, target]
        return [(u, v) for u, v in itertools.pairwise(sequence) if u != v]


def _dijkstra(adjacency, origin: int, target: int, banned: tuple[int, int]):
    """Shortest (perturbed) path from origin to target avoiding the edge ``banned``; None if none."""
    best = {origin: 0.0}
    previous: dict[int, int] = {}
    queue = [(0.0, origin)]
    done = set()
    while queue:
        d, u = heapq.heappop(queue)
        if u in done:
            continue
        done.add(u)
        if u == target:
            path = [u]
            while path[-1] != origin:
                path.append(previous[path[-1]])
            return d, path[::-1]
        for v, (weight, *_rest) in adjacency[u].items():
            if (u, v) == banned or (v, u) == banned:
                continue
            candidate = d + weight
            if candidate < best.get(v, math.inf):
                best[v] = candidate
                previous[v] = u
                heapq.heappush(queue, (candidate, v))
    return None


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array
