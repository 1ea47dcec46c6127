"""Tracks with several junctions and loops: a connected metric graph, its points and its track distance.

A :class:`TrackGraph` has named nodes (ends, junctions, bends; x/y in metres optional) and named
edges, each between two nodes with a length in metres; parallel edges (a passing loop) and rings
are allowed, self-loops are not. A point of the track is an :class:`EdgePoint`: ``s`` metres from
its edge's ``from`` node. The track distance between two points is the length of the shortest way
along the track between them (docs/graphs.md, 'The track'); two vehicles are apart iff it is at
least the minimum separation. The node-to-node distances are computed once, at construction.

Examples
--------
>>> track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.5), "m": ("J", "C", 8.0)})
>>> track.distance(track.point("a:2"), track.point("b:1"))
3.0
>>> track.distance(track.point("A"), track.point("a:6"))
0.0
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from topology.errors import PositionError, TrackError
from topology.validation import finite_real, short_repr

__all__ = ["EdgePoint", "TrackEdge", "TrackGraph"]

#: Metres within which two points of an edge are one point, and a length may undercut the straight
#: distance of its nodes (rounding of coordinates).
POINT_TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True)
class TrackEdge:
    """An edge of the track: ``length`` metres from node ``start`` to node ``end``.

    Parameters
    ----------
    name : str
    start, end : str
        Node names: the edge's ``from`` and ``to``. Positions on it count from ``start``.
    length : float
        Metres, positive.
    """

    name: str
    start: str
    end: str
    length: float


@dataclass(frozen=True, slots=True)
class EdgePoint:
    """A point of a track: ``s`` metres along edge number ``edge`` from its ``from`` node.

    A node is the point of one of its edges at ``s = 0`` or the edge's length; :meth:`TrackGraph.point`
    gives it in one canonical form (its first edge), so equal points compare equal.
    """

    edge: int
    s: float


def _name(value: object, what: str) -> str:
    if not isinstance(value, str) or not value or value != value.strip() or ":" in value:
        raise TrackError(
            f"{what} {short_repr(value)} is not a name: expected a non-empty string without ':' or "
            "surrounding spaces"
        )
    return value


@dataclass(frozen=True, slots=True, eq=False)
class TrackGraph:
    """A connected track graph: named nodes, named edges with lengths, optional node coordinates.

    Build one with :meth:`from_edges` (or the scenario file's ``[track]`` with ``edges``). The
    node-to-node track distances are computed once, at construction.

    Parameters
    ----------
    nodes : tuple of str
        Node names, in the order given.
    edges : tuple of TrackEdge
    coordinates : tuple of (float, float), optional
        Each node's x/y in metres, in the order of ``nodes`` (``None``: no coordinates).
    directions : tuple of (float, float), optional
        Each edge's change of x/y per metre along it from its ``from`` node, in the order of ``edges``
        (needs ``coordinates``; ``None``: the straight line of its nodes, ``(end - start) / length``).
        A point ``s`` metres along an edge is drawn at ``start + s * direction``. A star's legs give
        their angle's cosine and sine (:meth:`~topology.StarGraph.track_graph`).
    numbered_legs : bool, optional
        Every edge leaves one node, the junction of a star: rows and tables name where a vehicle is
        by the number of its edge (1 for the first, 0 at the junction), in a column ``leg``, as a
        star's always have, and VDA 5050 orders name a leg's end by its leg and metres (``A:10``).
        Default False: by the edge's name, in a column ``edge``.

    Raises
    ------
    TrackError
        A self-loop, an unknown or duplicate name, a disconnected track, a length that is not a
        positive number or is shorter than the straight distance of its nodes, coordinates of some
        nodes only, directions that do not lead from an edge's ``from`` node to its ``to`` node,
        numbered legs that do not all leave one node.
    """

    nodes: tuple[str, ...]
    edges: tuple[TrackEdge, ...]
    coordinates: tuple[tuple[float, float], ...] | None = None
    directions: tuple[tuple[float, float], ...] | None = None
    numbered_legs: bool = False
    _node_index: dict[str, int] = field(init=False, repr=False)
    _edge_index: dict[str, int] = field(init=False, repr=False)
    _node_distance: np.ndarray = field(init=False, repr=False)
    _ends: np.ndarray = field(init=False, repr=False)
    _lengths: np.ndarray = field(init=False, repr=False)
    _node_points: tuple[EdgePoint, ...] = field(init=False, repr=False)
    _hash: int = field(init=False, repr=False)

    def __post_init__(self) -> None:
        nodes = tuple(_name(n, "node") for n in self.nodes)
        if len(set(nodes)) != len(nodes):
            twice = sorted({n for n in nodes if nodes.count(n) > 1})
            raise TrackError(f"node names {twice!r} are given twice: expected each name once")
        if not nodes:
            raise TrackError("the track has no node: expected at least two nodes and one edge")
        index = {n: i for i, n in enumerate(nodes)}
        edges = tuple(self.edges)
        if not edges:
            raise TrackError("the track has no edge: expected at least one edge")
        seen: dict[str, int] = {}
        for edge in edges:
            _name(edge.name, "edge")
            if edge.name in seen or edge.name in index:
                raise TrackError(
                    f"edge name {edge.name!r} is given twice (or is also a node's): expected each name once"
                )
            seen[edge.name] = len(seen)
            for end in (edge.start, edge.end):
                if end not in index:
                    raise TrackError(
                        f"edge {edge.name!r} names node {short_repr(end)}, which the track does not have: "
                        f"expected one of {list(nodes)!r}"
                    )
            if edge.start == edge.end:
                raise TrackError(
                    f"edge {edge.name!r} runs from node {edge.start!r} to itself (a self-loop): expected "
                    "two different nodes (a ring needs at least two edges)"
                )
            length = finite_real(edge.length, f"length of edge {edge.name!r} (m)", TrackError)
            if length <= 0.0:
                raise TrackError(f"length of edge {edge.name!r} is {length!r} m: expected a positive length")
        coordinates = None
        if self.coordinates is not None:
            coordinates = tuple(
                (
                    finite_real(x, f"x of node {n!r} (m)", TrackError),
                    finite_real(y, f"y of node {n!r} (m)", TrackError),
                )
                for n, (x, y) in zip(nodes, self.coordinates, strict=True)
            )
            for edge in edges:
                (x0, y0), (x1, y1) = coordinates[index[edge.start]], coordinates[index[edge.end]]
                straight = math.hypot(x1 - x0, y1 - y0)
                if edge.length < straight - POINT_TOLERANCE * max(1.0, straight):
                    raise TrackError(
                        f"edge {edge.name!r} is {edge.length!r} m long but its nodes {edge.start!r} and "
                        f"{edge.end!r} are {straight:.6g} m apart: expected at least the straight distance "
                        "(a curve is longer, never shorter)"
                    )
        ends = np.array([[index[e.start], index[e.end]] for e in edges], dtype=np.intp)
        lengths = np.array([float(e.length) for e in edges])
        directions = _directions(edges, coordinates, ends, lengths, self.directions)
        if self.numbered_legs is not False and self.numbered_legs is not True:
            raise TrackError(
                f"numbered_legs {short_repr(self.numbered_legs)} is not a bool: expected True or False"
            )
        if self.numbered_legs and len({e.start for e in edges}) != 1:
            raise TrackError(
                f"numbered legs leave nodes {sorted({e.start for e in edges})!r}: expected every edge to "
                "leave one node (a star's junction)"
            )
        distance = _all_pairs(len(nodes), ends, lengths)
        if not np.isfinite(distance).all():
            reached = np.isfinite(distance[0])
            apart = [n for n, r in zip(nodes, reached, strict=True) if not r]
            raise TrackError(
                f"the track is not connected: nodes {apart[:5]!r}{' ...' if len(apart) > 5 else ''} cannot "
                f"be reached from {nodes[0]!r}: expected one connected track"
            )
        distance.setflags(write=False)
        ends.setflags(write=False)
        lengths.setflags(write=False)
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "edges", edges)
        object.__setattr__(self, "coordinates", coordinates)
        object.__setattr__(self, "directions", directions)
        object.__setattr__(self, "_node_index", index)
        object.__setattr__(self, "_edge_index", {e.name: i for i, e in enumerate(edges)})
        object.__setattr__(self, "_node_distance", distance)
        object.__setattr__(self, "_ends", ends)
        object.__setattr__(self, "_lengths", lengths)
        first: dict[int, EdgePoint] = {}
        for k, (start, end) in enumerate(ends.tolist()):
            first.setdefault(start, EdgePoint(k, 0.0))
            first.setdefault(end, EdgePoint(k, float(lengths[k])))
        object.__setattr__(self, "_node_points", tuple(first[n] for n in range(len(nodes))))
        # immutable: hashed once (caches keyed on the track look it up per call)
        object.__setattr__(self, "_hash", hash(self._key()))

    @classmethod
    def from_edges(
        cls,
        edges: Mapping[str, tuple[str, str, float | None]],
        *,
        coordinates: Mapping[str, tuple[float, float]] | None = None,
        directions: Mapping[str, tuple[float, float]] | None = None,
        numbered_legs: bool = False,
    ) -> TrackGraph:
        """A track from ``{edge name: (from node, to node, length)}``; nodes in order of appearance.

        A length of ``None`` is the straight distance of the nodes (``coordinates`` needed).
        ``directions`` (``{edge name: (dx, dy)}``, every edge) and ``numbered_legs`` are as the
        class's.
        """
        nodes: list[str] = list(coordinates or ())
        built = []
        for name, (start, end, length) in edges.items():
            for node in (start, end):
                if node not in nodes:
                    nodes.append(node)
            if length is None:
                if coordinates is None or start not in coordinates or end not in coordinates:
                    raise TrackError(
                        f"edge {name!r} has no length and its nodes no x/y: expected a length, or "
                        "coordinates of both nodes"
                    )
                (x0, y0), (x1, y1) = coordinates[start], coordinates[end]
                length = math.hypot(float(x1) - float(x0), float(y1) - float(y0))
            built.append(TrackEdge(name, start, end, length))
        xy = None
        if coordinates is not None:
            missing = [n for n in nodes if n not in coordinates]
            if missing:
                raise TrackError(
                    f"nodes {missing!r} have no x/y while others do: expected coordinates of every node, "
                    "or of none"
                )
            xy = tuple(tuple(coordinates[n]) for n in nodes)
        steps = None
        if directions is not None:
            missing = [name for name in edges if name not in directions]
            if missing:
                raise TrackError(
                    f"edges {missing[:5]!r} have no direction while others do: expected a direction of "
                    "every edge, or of none"
                )
            steps = tuple(tuple(directions[name]) for name in edges)
        return cls(tuple(nodes), tuple(built), xy, steps, numbered_legs)

    # -- points ---------------------------------------------------------------------------------

    @property
    def edge_count(self) -> int:
        """Number of edges."""
        return len(self.edges)

    @property
    def total_length(self) -> float:
        """Sum of the edges' lengths, metres."""
        return float(self._lengths.sum())

    def edge(self, name: str) -> int:
        """The number of the edge called ``name``."""
        try:
            return self._edge_index[name]
        except (KeyError, TypeError):
            raise PositionError(
                f"edge {short_repr(name)} is not on the track: expected one of {list(self._edge_index)[:8]!r}"
            ) from None

    def node(self, name: str) -> int:
        """The number of the node called ``name``."""
        try:
            return self._node_index[name]
        except (KeyError, TypeError):
            raise PositionError(
                f"node {short_repr(name)} is not on the track: expected one of {list(self.nodes)[:8]!r}"
            ) from None

    def length(self, edge: int) -> float:
        """Length of edge number ``edge``, metres."""
        return float(self._lengths[edge])

    def ends(self, edge: int) -> tuple[int, int]:
        """The node numbers of edge ``edge``'s ``from`` and ``to``."""
        start, end = self._ends[edge]
        return int(start), int(end)

    def node_point(self, node: int) -> EdgePoint:
        """Node number ``node`` as a point: its first edge (in the track's order), at 0 or its length."""
        return self._node_points[node]

    def canonical(self, point: EdgePoint) -> EdgePoint:
        """``point`` with a node written as :meth:`node_point` (so equal points compare equal)."""
        node = self.node_at(point)
        return point if node is None else self.node_point(node)

    def node_at(self, point: EdgePoint) -> int | None:
        """The node ``point`` is at (within 1e-9 m), else ``None``."""
        start, end = self._ends[point.edge]
        if point.s <= POINT_TOLERANCE:
            return int(start)
        if point.s >= self._lengths[point.edge] - POINT_TOLERANCE:
            return int(end)
        return None

    def position_on(self, point: EdgePoint, edge: int) -> float | None:
        """``point``'s metres along ``edge`` (a node is 0 or the edge's length there), or ``None``."""
        if point.edge == edge:
            return point.s
        node = self.node_at(point)
        start, end = self.ends(edge)
        if node is not None and node == start:
            return 0.0
        if node is not None and node == end:
            return self.length(edge)
        return None

    def point(self, text: str | EdgePoint) -> EdgePoint:
        """The point written ``"EDGE:s"`` (metres from the edge's ``from`` node) or ``"NODE"``.

        Raises
        ------
        PositionError
            An unknown edge or node, ``s`` not a number or off the edge.
        """
        if isinstance(text, EdgePoint):
            return self.canonical(self._checked(text.edge, text.s, text))
        if not isinstance(text, str):
            raise PositionError(f"position {short_repr(text)} is not 'EDGE:s' or a node's name")
        if ":" not in text:
            return self.node_point(self.node(text.strip()))
        name, _, number = text.partition(":")
        edge = self.edge(name.strip())
        try:
            s = float(number)
        except ValueError:
            raise PositionError(
                f"position {short_repr(text)}: {short_repr(number.strip())} is not a number of metres"
            ) from None
        return self.canonical(self._checked(edge, s, text))

    def _checked(self, edge: int, s: float, text: object) -> EdgePoint:
        if not 0 <= edge < len(self.edges):
            raise PositionError(f"position {short_repr(text)}: no edge number {edge}")
        s = finite_real(s, f"position {short_repr(text)}: s (m)", PositionError)
        length = float(self._lengths[edge])
        if not -POINT_TOLERANCE <= s <= length + POINT_TOLERANCE:
            raise PositionError(
                f"position {short_repr(text)} is off edge {self.edges[edge].name!r}: s = {s!r} m, expected "
                f"0 to its length {length:g} m"
            )
        return EdgePoint(edge, min(max(s, 0.0), length))

    def name(self, point: EdgePoint) -> str:
        """``point`` as written in a scenario: a node's name, or ``EDGE:s``."""
        node = self.node_at(point)
        if node is not None:
            return self.nodes[node]
        return f"{self.edges[point.edge].name}:{point.s:g}"

    def xy(self, point: EdgePoint) -> tuple[float, float] | None:
        """The point's x/y in metres, on the straight line of its edge's nodes (``None`` without x/y)."""
        if self.coordinates is None:
            return None
        x, y = self.xy_along([point.edge], [point.s])
        return (float(x[0]), float(y[0]))

    def xy_along(self, edge, s) -> tuple[np.ndarray, np.ndarray] | None:
        """The x and y, metres, of the points ``s`` metres along edges ``edge``, shape (n,) each.

        ``start + s * direction`` (:attr:`directions`); ``None`` without x/y.
        """
        if self.coordinates is None:
            return None
        edge = np.asarray(edge, dtype=np.intp)
        s = np.asarray(s, dtype=float)
        start = np.asarray(self.coordinates, dtype=float)[self._ends[edge, 0]]
        step = np.asarray(self.directions, dtype=float)[edge]
        return start[..., 0] + s * step[..., 0], start[..., 1] + s * step[..., 1]

    # -- distances ------------------------------------------------------------------------------

    @property
    def node_distances(self) -> np.ndarray:
        """Track distance between every two nodes, metres, shape (n, n), read-only."""
        return self._node_distance

    def distance(self, a: EdgePoint, b: EdgePoint) -> float:
        """The track distance between two points, metres: the shortest way along the track."""
        return float(self.distances([a.edge], [a.s], [b.edge], [b.s])[0])

    def distances(self, edge_a, s_a, edge_b, s_b) -> np.ndarray:
        """Track distances between points ``(edge_a[i], s_a[i])`` and ``(edge_b[i], s_b[i])``, shape (m,).

        The shortest way leaves each point through one end of its edge (four ways), or, on one
        edge, runs along it.
        """
        ea, eb = np.asarray(edge_a, dtype=np.intp), np.asarray(edge_b, dtype=np.intp)
        sa, sb = np.asarray(s_a, dtype=float), np.asarray(s_b, dtype=float)
        ua, va = self._ends[ea, 0], self._ends[ea, 1]
        ub, vb = self._ends[eb, 0], self._ends[eb, 1]
        ra, rb = self._lengths[ea] - sa, self._lengths[eb] - sb
        d = self._node_distance
        best = np.minimum.reduce(
            [d[ua, ub] + sa + sb, d[ua, vb] + sa + rb, d[va, ub] + ra + sb, d[va, vb] + ra + rb]
        )
        return np.where(ea == eb, np.minimum(best, np.abs(sa - sb)), best)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TrackGraph):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return self._hash

    def _key(self) -> tuple:
        return (self.nodes, self.edges, self.coordinates, self.directions, self.numbered_legs)


def _directions(
    edges: tuple[TrackEdge, ...],
    coordinates: tuple[tuple[float, float], ...] | None,
    ends: np.ndarray,
    lengths: np.ndarray,
    given: object,
) -> tuple[tuple[float, float], ...] | None:
    """Each edge's x/y per metre: the given ones (checked to lead to its end), else the straight line."""
    if coordinates is None:
        if given is not None:
            raise TrackError("the edges have directions but the nodes no x/y: expected coordinates too")
        return None
    xy = np.asarray(coordinates, dtype=float)
    if given is None:
        return tuple(
            ((xy[v, 0] - xy[u, 0]) / length, (xy[v, 1] - xy[u, 1]) / length)
            for (u, v), length in zip(ends.tolist(), lengths.tolist(), strict=True)
        )
    given = tuple(given)
    if len(given) != len(edges):
        raise TrackError(f"{len(given)} directions for {len(edges)} edges: expected one per edge")
    steps = []
    for edge, (u, v), length, step in zip(edges, ends.tolist(), lengths.tolist(), given, strict=True):
        dx = finite_real(step[0], f"direction x of edge {edge.name!r} (per metre)", TrackError)
        dy = finite_real(step[1], f"direction y of edge {edge.name!r} (per metre)", TrackError)
        miss = math.hypot(xy[u, 0] + length * dx - xy[v, 0], xy[u, 1] + length * dy - xy[v, 1])
        if miss > POINT_TOLERANCE * max(1.0, length):
            raise TrackError(
                f"edge {edge.name!r}'s direction ({dx:g}, {dy:g}) leads {miss:.3g} m from its node "
                f"{edge.end!r}: expected it to lead from {edge.start!r} to {edge.end!r} over its length"
            )
        steps.append((dx, dy))
    return tuple(steps)


def _all_pairs(count: int, ends: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Shortest distances between all nodes (Floyd-Warshall over the shortest edge of each pair)."""
    distance = np.full((count, count), np.inf)
    np.fill_diagonal(distance, 0.0)
    for (u, v), length in zip(ends, lengths, strict=True):
        if length < distance[u, v]:
            distance[u, v] = distance[v, u] = length
    for k in range(count):
        np.minimum(distance, distance[:, k, None] + distance[None, k, :], out=distance)
    return distance
