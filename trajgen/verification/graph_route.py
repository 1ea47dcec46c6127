"""The verifier's check of a route on a track graph: every move keeps the separation, in closed form.

Independent of the planner's code: the node-to-node track distances come from this module's own
Dijkstra over the track's edges, and the distance from a standing vehicle to a moving one is taken
per edge the mover runs along. Along an edge, the track distance from a fixed point ``q`` is the
minimum of two affine functions of the position (through either end of the edge), and, on ``q``'s
own edge, of ``|s - s_q|``; so its minimum over a stretch is at the stretch's ends, or 0 where the
stretch passes ``q``. Nothing is sampled.

The vehicles of a joint move (a junction's route) drive at once, each reaching its end together
(:class:`~topology.GraphMove`): between the instants either passes a node, both are on fixed
edges, so their distance is again a minimum of affine functions of the joint move's progress (and
``|s_1 - s_2|`` on one edge): checked at those instants, and for a crossing on a shared edge.

Also checked: each vehicle starts and ends where the route says, each move starts where its vehicle
is, each standing vehicle is where it is said to be, the travel adds up, every number is finite. Every
pair of vehicles is checked: a route may move any number.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass

from topology import EdgePoint, GraphMove, GraphRoute, TrackGraph
from trajgen.errors import InputError

__all__ = ["GraphRouteReport", "TrackDistances", "verify_graph_route"]

#: Metres of round-off allowed: below the separation, off a point, in the travel's sum.
ROUTE_TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True)
class GraphRouteReport:
    """What the verifier found on a route on a track graph.

    Attributes
    ----------
    passed : bool
    closest : float
        The least track distance between any two vehicles over the whole route, metres.
    closest_move : int or None
        The move (0-based) where it is least; ``None`` for a route without moves.
    failures : tuple of str
        Each failed check, naming the move and the quantity.
    """

    passed: bool
    closest: float
    closest_move: int | None
    failures: tuple[str, ...]


def _node_distances(track: TrackGraph) -> list[list[float]]:
    """Shortest track distance between every two nodes: a Dijkstra from each node over the edges."""
    index = {name: number for number, name in enumerate(track.nodes)}
    links: list[list[tuple[int, float]]] = [[] for _ in track.nodes]
    for edge in track.edges:
        a, b = index[edge.start], index[edge.end]
        links[a].append((b, float(edge.length)))
        links[b].append((a, float(edge.length)))
    table = []
    for origin in range(len(track.nodes)):
        best = [math.inf] * len(track.nodes)
        best[origin] = 0.0
        heap = [(0.0, origin)]
        while heap:
            here_distance, here = heapq.heappop(heap)
            if here_distance > best[here]:
                continue
            for there, length in links[here]:
                if here_distance + length < best[there]:
                    best[there] = here_distance + length
                    heapq.heappush(heap, (best[there], there))
        table.append(best)
    return table


class TrackDistances:
    """Track distances of the verifier's own, between points ``(edge, s)`` of one track."""

    def __init__(self, track: TrackGraph) -> None:
        index = {name: number for number, name in enumerate(track.nodes)}
        self.ends = [(index[e.start], index[e.end]) for e in track.edges]
        self.lengths = [float(e.length) for e in track.edges]
        self.nodes = _node_distances(track)

    def to_node(self, edge: int, s: float, node: int) -> float:
        """The track distance from the point ``(edge, s)`` to node number ``node``."""
        start, end = self.ends[edge]
        return min(self.nodes[start][node] + s, self.nodes[end][node] + self.lengths[edge] - s)

    def along(self, point: EdgePoint, edge: int) -> float:
        """``point``'s metres from the ``from`` node of ``edge`` (a node at its ends: 0 or its length)."""
        if point.edge == edge:
            return point.s
        start, end = self.ends[edge]
        if self.to_node(point.edge, point.s, start) <= ROUTE_TOLERANCE:
            return 0.0
        if self.to_node(point.edge, point.s, end) <= ROUTE_TOLERANCE:
            return self.lengths[edge]
        return math.nan

    def between(self, a: EdgePoint, b: EdgePoint) -> float:
        """The track distance between two points."""
        return self.least_along(a, b.edge, b.s, b.s)

    def least_along(self, fixed: EdgePoint, edge: int, low: float, high: float) -> float:
        """The least track distance from ``fixed`` to the points of ``edge`` from ``low`` to ``high`` m."""
        start, end = self.ends[edge]
        through_start = self.to_node(fixed.edge, fixed.s, start)
        through_end = self.to_node(fixed.edge, fixed.s, end)
        rest = self.lengths[edge]
        least = min(through_start + low, through_end + rest - high)  # each affine: least at an end
        if fixed.edge == edge:
            least = min(
                least, 0.0 if low <= fixed.s <= high else min(abs(fixed.s - low), abs(fixed.s - high))
            )
        return least


def _segments(distances: TrackDistances, move: GraphMove) -> list[tuple[int, float, float, float]]:
    """``(edge, s at its start, s at its end, travel at its start)`` of each edge ``move`` runs along."""
    out, travel = [], 0.0
    for (a, b), edge in zip(itertools.pairwise(move.points), move.edges, strict=True):
        s_a, s_b = distances.along(a, edge), distances.along(b, edge)
        out.append((edge, s_a, s_b, travel))
        travel += abs(s_b - s_a)
    return out


def _segment_at(segments: list[tuple[int, float, float, float]], travel: float) -> int:
    """Index of the segment a move is on after ``travel`` metres (the later one at a node)."""
    found = 0
    for k, (_, _, _, begin) in enumerate(segments):
        if travel >= begin:
            found = k
    return found


def _on(segment: tuple[int, float, float, float], travel: float) -> tuple[int, float]:
    """``(edge, s)`` after ``travel`` metres of a move, on one of its segments (clamped to it)."""
    edge, s_a, s_b, begin = segment
    step = min(max(travel - begin, 0.0), abs(s_b - s_a))
    return edge, s_a + math.copysign(step, s_b - s_a)


def _joint_least(distances: TrackDistances, a: GraphMove, b: GraphMove) -> float:
    """The least track distance of two vehicles driving moves ``a`` and ``b`` at once, metres.

    Both progress in proportion (a straight line in their travel plane). Between two instants at
    which either passes a node the distance is the least of affine functions of the progress, and on
    a shared edge also ``|s_a - s_b|``: its least value is at those instants, or 0 where the two
    cross on a shared edge.
    """
    moves = (a, b)
    segments = tuple(_segments(distances, move) for move in moves)
    fractions = {0.0, 1.0}
    for found, move in zip(segments, moves, strict=True):
        if move.length > 0.0:
            fractions |= {begin / move.length for _, _, _, begin in found if 0.0 < begin < move.length}
    least = math.inf
    ordered = sorted(fractions)
    for u0, u1 in itertools.pairwise(ordered):
        ends = []
        for found, move in zip(segments, moves, strict=True):
            if not found:  # it runs no edge: it stands where it starts
                ends.append(((move.points[0].edge, move.points[0].s),) * 2)
                continue
            segment = found[_segment_at(found, 0.5 * (u0 + u1) * move.length)]
            ends.append((_on(segment, u0 * move.length), _on(segment, u1 * move.length)))
        (a0, a1), (b0, b1) = ends
        for (edge_a, s_a), (edge_b, s_b) in ((a0, b0), (a1, b1)):
            least = min(least, distances.between(EdgePoint(edge_a, s_a), EdgePoint(edge_b, s_b)))
        if a0[0] == b0[0] and (a0[1] - b0[1]) * (a1[1] - b1[1]) < 0.0:  # they cross on one edge
            least = 0.0
    return least


def verify_graph_route(route: GraphRoute) -> GraphRouteReport:
    """Check every move of ``route`` against the separation, and that the moves make the route.

    Raises
    ------
    InputError
        ``route`` is not a GraphRoute.
    """
    if not isinstance(route, GraphRoute):
        raise InputError(f"verify_graph_route takes a GraphRoute, got {type(route).__name__}")
    track, separation = route.track, route.min_separation
    distances = TrackDistances(track)
    failures: list[str] = []
    count = len(route.start)
    where = list(route.start)
    travel = [0.0] * count
    names = route.names if len(route.names) == count else tuple(f"vehicle {v + 1}" for v in range(count))
    closest, closest_move, first = math.inf, None, None
    for a, b in itertools.combinations(range(count), 2):
        gap = distances.between(where[a], where[b])
        if gap < closest:
            closest, first = gap, (a, b)

    def apart(least: float, number: int, who: str) -> None:
        """Keep the closest approach; a failure where ``who`` (the move, the two) come too close."""
        nonlocal closest, closest_move
        if least < closest:
            closest, closest_move = least, number
        if least < separation - ROUTE_TOLERANCE:
            failures.append(
                f"{who} come {least:.6g} m apart: expected at least the minimum separation {separation:g} m"
            )

    for number, move in enumerate(route.moves):
        label = f"move {number + 1} ({track.name(move.points[0])} -> {track.name(move.points[-1])})"
        numbers = [move.length, *(p.s for p in move.at_start), *(p.s for p in move.points)]
        if not all(math.isfinite(value) for value in numbers):
            failures.append(f"{label}: a number is not finite: expected finite metres")
            break
        if (
            not 0 <= move.vehicle < count
            or len(move.edges) != len(move.points) - 1
            or len(move.at_start) != count
        ):
            failures.append(
                f"{label}: vehicle {move.vehicle!r}, {len(move.edges)} edges for {len(move.points)} "
                f"points and {len(move.at_start)} places: expected a vehicle from 0 to {count - 1}, one "
                f"edge per step and one place per vehicle"
            )
            break
        if distances.between(where[move.vehicle], move.points[0]) > ROUTE_TOLERANCE:
            failures.append(
                f"{label}: starts at {track.name(move.points[0])}, but the vehicle is at "
                f"{track.name(where[move.vehicle])}"
            )
        if distances.between(move.at_start[move.vehicle], move.points[0]) > ROUTE_TOLERANCE:
            failures.append(
                f"{label}: says {names[move.vehicle]} stands at {track.name(move.at_start[move.vehicle])} "
                f"as it begins, but its points start at {track.name(move.points[0])}"
            )
        for other, said in move.standing():
            if distances.between(where[other], said) > ROUTE_TOLERANCE:
                failures.append(
                    f"{label}: {names[other]} is said to stand at {track.name(said)}, but it is at "
                    f"{track.name(where[other])}"
                )
        length = 0.0
        for (a, b), edge in zip(itertools.pairwise(move.points), move.edges, strict=True):
            s_a, s_b = track.position_on(a, edge), track.position_on(b, edge)
            if s_a is None or s_b is None:
                failures.append(
                    f"{label}: {track.name(a)} -> {track.name(b)} is not along edge "
                    f"{track.edges[edge].name!r}"
                )
                continue
            length += abs(s_b - s_a)
            for other in range(count):
                if other in move.movers:
                    continue
                least = distances.least_along(where[other], edge, min(s_a, s_b), max(s_a, s_b))
                apart(
                    least,
                    number,
                    f"{label}: along {track.edges[edge].name!r} {names[move.vehicle]} and {names[other]}",
                )
        if abs(length - move.length) > ROUTE_TOLERANCE * max(1.0, length):
            failures.append(f"{label}: its length is {move.length!r} m, its edges add up to {length!r} m")
        travel[move.vehicle] += length
        where[move.vehicle] = move.points[-1]
        if move.joint and move.vehicle == move.movers[-1]:  # the joint move's last part: all of it at once
            parts = route.moves[number + 1 - len(move.movers) : number + 1]
            for a, b in itertools.combinations(parts, 2):
                least = _joint_least(distances, a, b)
                apart(least, number, f"{label}: driving at once, {names[a.vehicle]} and {names[b.vehicle]}")
    for vehicle in range(count):
        if distances.between(where[vehicle], route.goal[vehicle]) > ROUTE_TOLERANCE:
            failures.append(
                f"{names[vehicle]} ends at {track.name(where[vehicle])}: expected its goal "
                f"{track.name(route.goal[vehicle])}"
            )
        if abs(travel[vehicle] - route.travel[vehicle]) > ROUTE_TOLERANCE * max(1.0, travel[vehicle]):
            failures.append(
                f"{names[vehicle]} travels {travel[vehicle]!r} m by its moves: the route "
                f"says {route.travel[vehicle]!r} m"
            )
    if closest < separation - ROUTE_TOLERANCE and closest_move is None and first is not None:
        failures.append(
            f"{names[first[0]]} and {names[first[1]]} start {closest:.6g} m apart: expected at least "
            f"{separation:g} m"
        )
    return GraphRouteReport(not failures, closest, closest_move, tuple(failures))
