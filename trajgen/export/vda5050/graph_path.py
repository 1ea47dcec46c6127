"""The node and edge graph of each vehicle's VDA 5050 path on a track graph, from its verified schedule.

Each vehicle's nodes are where its path starts and ends, every node of the track it passes (a
junction, or where one edge meets the next), every end of one of its moves of the route (a
*parking point*: there it can wait while the other vehicle moves, so the release of the bases can
follow the route's order), every reversal (where its path turns back on an edge), and a *hold
node* the separation before and after each junction it passes (there it can wait while the other
vehicle passes the junction, and beyond it the junction is free for the other). With
``spacing``, release nodes split longer edges. Each order edge covers a stretch of the path, on one
or more edges of the track, and carries the highest speed the schedule reaches on it (``maxSpeed``).
A node's ``claim`` and an edge's ``claim`` are the stretches of track edges ``(edge, low, high)`` the
vehicle may be on there; :meth:`GraphOrderPath.gap` is the track distance between two claims, which
the release of the bases (:class:`~trajgen.export.vda5050.release.BaseRelease`) keeps at least the
separation.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np

from topology import EdgePoint, TrackGraph
from trajgen.export.vda5050.path import HOLD_MARGIN, NodeKind, hold_description, metres_text
from trajgen.model.graph_paths import GraphPath
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.paths import MOVE_RESOLUTION
from trajgen.model.pieces import kinematics_polynomials, shift
from trajgen.model.polynomials import derivative, extrema

__all__ = ["GraphOrderPath", "GraphPathEdge", "GraphPathNode", "graph_vehicle_path", "point_id"]

#: A claim: stretches ``(edge, low, high)`` of track edges, metres from each edge's ``from`` node.
Claim = tuple[tuple[int, float, float], ...]


@functools.lru_cache(maxsize=16)
def _scalar_metric(track: TrackGraph) -> tuple[list, list, list]:
    """``track``'s edge ends, edge lengths and node-to-node distances as Python lists.

    The release rule measures tens of thousands of gaps between single stretches: plain floats
    do each in microseconds where a NumPy call per gap takes tens
    (:meth:`~topology.TrackGraph.distances` computes the same ways).
    """
    ends = [track.ends(k) for k in range(track.edge_count)]
    lengths = [track.length(k) for k in range(track.edge_count)]
    return ends, lengths, track.node_distances.tolist()


@dataclass(frozen=True, slots=True)
class GraphPathNode:
    """A node of one vehicle's path on a track graph.

    Attributes
    ----------
    travel : float
        Metres the vehicle has driven along its path when there.
    point : EdgePoint
        Where it is: an edge and the metres from its ``from`` node (a track node canonically).
    axis : float
        The vehicle's signed axis there, metres.
    arrival, departure : float
        When the schedule reaches and leaves the node, seconds.
    kinds : tuple of NodeKind
    junction : str or None
        The junction a hold node is the separation away from (its name).
    """

    travel: float
    point: EdgePoint
    axis: float
    arrival: float
    departure: float
    kinds: tuple[NodeKind, ...]
    junction: str | None = None

    @property
    def description(self) -> str:
        """Why the node is there, for ``nodeDescription``: its kinds, a hold's junction."""
        return ", ".join(
            f"hold: the minimum separation from junction {self.junction}"
            if kind is NodeKind.HOLD
            else kind.value
            for kind in self.kinds
        )

    @property
    def claim(self) -> Claim:
        """The node as a stretch of no length."""
        return ((self.point.edge, self.point.s, self.point.s),)


@dataclass(frozen=True, slots=True)
class GraphPathEdge:
    """An edge of one vehicle's path, from node ``index`` to node ``index + 1``.

    Attributes
    ----------
    index : int
    stretches : tuple of (int, float, float)
        The track edges it runs along, in order: ``(edge, low, high)``, metres from each edge's
        ``from`` node.
    length : float
        Metres.
    max_speed : float
        Highest speed the schedule reaches on it, m/s, at most the vehicle's limit (rounded up to 1 µm/s).
    backward : bool
        Whether the vehicle drives it against the direction of its first move (after a reversal).
    """

    index: int
    stretches: Claim
    length: float
    max_speed: float
    backward: bool

    @property
    def claim(self) -> Claim:
        """The track the vehicle may be on while it drives the edge."""
        return self.stretches


@dataclass(frozen=True, slots=True)
class GraphOrderPath:
    """One vehicle's nodes and edges on a track graph (``len(edges) == len(nodes) - 1``)."""

    track: TrackGraph
    nodes: tuple[GraphPathNode, ...]
    edges: tuple[GraphPathEdge, ...]

    def gap(self, first: Claim, second: Claim) -> float:
        """Track distance between two claims, metres: 0 where they share track.

        Each way between two points (along one edge, or through an end of each edge) is affine in
        each point's position, so its least value over two stretches is at a pair of their ends.
        """
        ends, lengths, between = _scalar_metric(self.track)
        low = math.inf
        for (edge_a, low_a, high_a), (edge_b, low_b, high_b) in itertools.product(first, second):
            if edge_a == edge_b and low_a <= high_b and low_b <= high_a:
                return 0.0
            (ua, va), (ub, vb) = ends[edge_a], ends[edge_b]
            row_u, row_v = between[ua], between[va]
            la, lb = lengths[edge_a], lengths[edge_b]
            for sa in (low_a, high_a):
                ra = la - sa
                for sb in (low_b, high_b):
                    rb = lb - sb
                    way = min(
                        row_u[ub] + sa + sb, row_u[vb] + sa + rb, row_v[ub] + ra + sb, row_v[vb] + ra + rb
                    )
                    if edge_a == edge_b:
                        way = min(way, abs(sa - sb))
                    low = min(low, way)
        return low

    def placed(self, index: int) -> bool:
        """Whether node ``index``'s x/y is known.

        The track has coordinates, and the node is a node of the track or lies on a straight edge:
        an edge longer than the straight line between its nodes curves in a way the scenario does
        not say.
        """
        if self.track.coordinates is None:
            return False
        point = self.nodes[index].point
        if self.track.node_at(point) is not None:
            return True
        start, end = self.track.ends(point.edge)
        (x0, y0), (x1, y1) = self.track.coordinates[start], self.track.coordinates[end]
        return self.track.length(point.edge) <= math.hypot(x1 - x0, y1 - y0) + 1e-9

    def node_xy(self, index: int) -> tuple[float, float] | None:
        """Node ``index``'s x/y, metres (``None`` where it is not known: :meth:`placed`)."""
        return self.track.xy(self.nodes[index].point) if self.placed(index) else None

    def node_description(self, index: int) -> str:
        """Why node ``index`` is on the path, in words (``nodeDescription``).

        On a track whose legs are numbered (a junction's) a hold names its metres from the
        junction, as the junction's order paths always have.
        """
        node = self.nodes[index]
        if not self.track.numbered_legs or NodeKind.HOLD not in node.kinds:
            return node.description
        junction = self.track.node_point(self.track.ends(0)[0])
        metres = self.track.distance(node.point, junction)
        return ", ".join(
            hold_description(metres) if kind is NodeKind.HOLD else kind.value for kind in node.kinds
        )

    def edge_direction(self, index: int) -> str | None:
        """The track edge edge ``index`` takes where it leaves a junction (``None`` elsewhere)."""
        edge = self.edges[index]
        leaving = self.junction_at(index) and edge.length > 0.0
        return self.track.edges[edge.stretches[0][0]].name if leaving else None

    def junction_at(self, index: int) -> bool:
        """Whether node ``index`` is a junction of the track (a node where three or more edges meet)."""
        node = self.track.node_at(self.nodes[index].point)
        if node is None:
            return False
        return sum(node in self.track.ends(k) for k in range(len(self.track.edges))) >= 3

    def node_id(self, index: int) -> str:
        """Node ``index``'s id: a track node's name, or ``"<edge>:<metres>"``.

        The metres to 1 µm, or to 1 nm on an edge where two of the path's nodes more than
        :data:`~trajgen.model.paths.MOVE_RESOLUTION` apart would share their micrometre: distinct
        places keep distinct ids.
        """
        point = self.nodes[index].point
        return point_id(self.track, point, decimals=self._decimals(point.edge))

    def _decimals(self, edge: int) -> int:
        """Decimal places of the metres in the ids of the path's nodes on ``edge``: 6, or 9 if needed."""
        # every pair sharing a micrometre, not only neighbours: a chain of places under
        # MOVE_RESOLUTION apart can span more than it
        spans: dict[str, tuple[float, float]] = {}
        for node in self.nodes:
            if node.point.edge == edge:
                s = node.point.s
                low, high = spans.get(f"{s:.6f}", (s, s))
                spans[f"{s:.6f}"] = (min(low, s), max(high, s))
        return 9 if any(high - low > MOVE_RESOLUTION for low, high in spans.values()) else 6


def _marks(
    schedule: GraphSchedule, path: GraphPath, vehicle: int, holds: dict[float, str]
) -> dict[float, set[NodeKind]]:
    """Travel (metres) of every node of the path, and why each is there.

    ``holds`` is filled with the junction each hold node is the separation away from, by travel.
    """
    marks: dict[float, set[NodeKind]] = {0.0: {NodeKind.START}}
    marks.setdefault(path.length, set()).add(NodeKind.GOAL)
    for k in range(1, path.edges.size):
        kind = NodeKind.JUNCTION if path.edges[k] != path.edges[k - 1] else NodeKind.REVERSAL
        marks.setdefault(float(path.starts[k]), set()).add(kind)
    travel = 0.0
    track = schedule.track
    for move in schedule.route.moves:  # each move's end: a parking point of the route
        if move.vehicle != vehicle:
            continue
        for a, b, edge in zip(move.points[:-1], move.points[1:], move.edges, strict=True):
            travel += abs(track.position_on(b, edge) - track.position_on(a, edge))
        marks.setdefault(min(travel, path.length), set()).add(NodeKind.STOP)
    # the edge of each junction's zone, the separation before and after it: there a vehicle can
    # wait while the other passes the junction, and beyond it it has left the junction to the other
    separation = schedule.limits.min_separation
    degree = np.bincount(
        np.array([track.ends(k) for k in range(len(track.edges))]).ravel(), minlength=len(track.nodes)
    )
    for k in range(1, path.edges.size):
        node = track.node_at(EdgePoint(int(path.edges[k]), float(path.s_from[k])))
        if node is None or degree[node] < 3:
            continue
        for hold in (float(path.starts[k]) - separation, float(path.starts[k]) + separation):
            if HOLD_MARGIN < hold < path.length - HOLD_MARGIN:
                marks.setdefault(hold, set()).add(NodeKind.HOLD)
                holds[hold] = track.nodes[node]
    merged: dict[float, set[NodeKind]] = {}
    for mark in sorted(marks):
        near = [kept for kept in merged if abs(kept - mark) <= MOVE_RESOLUTION]
        if near:
            merged[near[0]] |= marks[mark]
            if mark in holds:
                holds.setdefault(near[0], holds[mark])
        else:
            merged[mark] = set(marks[mark])
    return merged


def _with_spacing(marks: dict[float, set[NodeKind]], spacing: float | None) -> dict[float, set[NodeKind]]:
    if spacing is None:
        return marks
    travels = sorted(marks)
    for a, b in itertools.pairwise(travels):
        count = math.ceil((b - a) / spacing - 1e-9)
        for n in range(1, count):
            marks[a + (b - a) * n / count] = {NodeKind.RELEASE}
    return dict(sorted(marks.items()))


def _times(schedule: GraphSchedule, vehicle: int, travel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """When the vehicle first reaches and last leaves each travel value (its travel never decreases)."""
    duration = schedule.duration
    results = []
    for target, reach in ((travel - MOVE_RESOLUTION, True), (travel + MOVE_RESOLUTION, False)):
        low, high = np.zeros(travel.size), np.full(travel.size, duration)
        for _ in range(60):
            middle = 0.5 * (low + high)
            driven = schedule.travel(middle)[vehicle, 0]
            beyond = driven >= target if reach else driven > target
            high = np.where(beyond, middle, high)
            low = np.where(beyond, low, middle)
        results.append(high if reach else low)
    arrival = np.where(travel <= MOVE_RESOLUTION, 0.0, results[0])
    departure = np.where(travel >= schedule.paths[vehicle].length - MOVE_RESOLUTION, duration, results[1])
    return arrival, np.maximum(departure, arrival)


def _max_speeds(schedule: GraphSchedule, vehicle: int, begin: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Highest speed of the vehicle in each ``[begin, end]``, m/s (closed form, piece by piece)."""
    starts, lengths, travel = [], [], []
    for section in schedule.sections:
        times, polynomials, _ = kinematics_polynomials(section.kinematics)
        starts.append(section.start_time + times[:-1])
        lengths.append(np.diff(times))
        travel.append(polynomials[vehicle])
    start, length, c = np.concatenate(starts), np.concatenate(lengths), np.concatenate(travel)
    peaks = []
    for t0, t1 in zip(begin, end, strict=True):
        mask = (start < t1) & (start + length > t0)
        if not mask.any():
            peaks.append(0.0)
            continue
        low = np.maximum(t0 - start[mask], 0.0)
        high = np.minimum(t1 - start[mask], length[mask])
        v_low, _, v_high, _ = extrema(derivative(shift(c[mask], low)), np.maximum(high - low, 0.0))
        peaks.append(float(np.max(np.maximum(np.abs(v_low), np.abs(v_high)))))
    return np.array(peaks)


def _stretches(path: GraphPath, a: float, b: float) -> tuple[tuple[int, float, float], ...]:
    """The track edges the path runs along between travel ``a`` and ``b``, ``(edge, low, high)`` each."""
    if path.edges.size == 0:
        return ((path.home.edge, path.home.s, path.home.s),)
    stretches = []
    directions = path.directions
    for k in range(path.edges.size):
        lo, hi = max(a, float(path.starts[k])), min(b, float(path.starts[k + 1]))
        if hi - lo < MOVE_RESOLUTION and (stretches or (k + 1 < path.edges.size and b > lo)):
            continue  # only touches this segment at one of its ends
        s = path.s_from[k] + directions[k] * (np.array([lo, hi]) - path.starts[k])
        stretches.append((int(path.edges[k]), float(s.min()), float(s.max())))
    return tuple(stretches)


def graph_vehicle_path(
    schedule: GraphSchedule, vehicle: int, *, spacing: float | None = None
) -> GraphOrderPath:
    """The nodes and edges of ``vehicle``'s (0 or 1) VDA 5050 path on a track graph.

    Parameters
    ----------
    schedule : GraphSchedule
        A verified schedule.
    vehicle : int
        0 or 1.
    spacing : float, optional
        Longest edge, metres: longer ones get release nodes between (``None``: none).

    Returns
    -------
    GraphOrderPath
    """
    path = schedule.paths[vehicle]
    holds: dict[float, str] = {}
    marks = _with_spacing(_marks(schedule, path, vehicle, holds), spacing)
    travel = np.array(sorted(marks))
    arrival, departure = _times(schedule, vehicle, travel)
    axis = path.axis(travel)
    edges, s = path.locate(travel)
    nodes = []
    for k, p in enumerate(travel):
        point = schedule.track.canonical(EdgePoint(int(edges[k]), float(s[k])))
        kinds = marks[float(p)]
        if len(kinds) > 1:  # a stop is named only where nothing else names the node
            kinds = kinds - {NodeKind.STOP}
        ordered = tuple(kind for kind in NodeKind if kind in kinds)
        junction = holds.get(float(p)) if NodeKind.HOLD in kinds else None
        nodes.append(
            GraphPathNode(
                float(p), point, float(axis[k]), float(arrival[k]), float(departure[k]), ordered, junction
            )
        )
    limit = schedule.limits.vehicles[vehicle].max_velocity
    peaks = _max_speeds(schedule, vehicle, departure[:-1], arrival[1:])
    order_edges = []
    for index, (a, b) in enumerate(itertools.pairwise(nodes)):
        middle = 0.5 * (a.travel + b.travel)
        order_edges.append(
            GraphPathEdge(
                index=index,
                stretches=_stretches(path, a.travel, b.travel),
                length=b.travel - a.travel,
                max_speed=min(math.ceil(peaks[index] * 1e6) / 1e6, limit),
                backward=bool(path.edges.size and path.heading(middle)[0] < 0),
            )
        )
    return GraphOrderPath(schedule.track, tuple(nodes), tuple(order_edges))


def point_id(track: TrackGraph, point: EdgePoint, *, decimals: int = 6) -> str:
    """The VDA 5050 node id of ``point``: a track node's name, or ``"<edge>:<metres>"``.

    The metres to ``decimals`` places (1 µm by default), trailing zeros dropped; parsed back by
    :meth:`~topology.TrackGraph.point`. On a track whose legs are numbered (a junction's,
    :meth:`~topology.StarGraph.track_graph`) a leg's end is named by its leg and metres, as the
    junction's places are written (``"A:10"``), and only the junction by its name.

    Examples
    --------
    >>> track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.5)})
    >>> point_id(track, EdgePoint(1, 6.5)), point_id(track, EdgePoint(0, 3.25))
    ('B', 'a:3.25')
    """
    node = track.node_at(point)
    if node is not None:
        if not track.numbered_legs or node == track.ends(0)[0]:
            return track.nodes[node]
        point = track.node_point(node)  # a leg's end: on its one leg, at its length
    return f"{track.edges[point.edge].name}:{metres_text(point.s, decimals)}"
