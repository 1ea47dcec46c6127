"""The exact two-vehicle planner on a track graph: A* over a roadmap of critical points.

docs/graphs.md, 'The planner'. A *move* takes one vehicle along the track while the other stands;
it is safe iff the standing vehicle stays at least ``d`` (the minimum separation) away, in track
distance, from every point the moving one passes. A vehicle stops only at a *critical point*: a
node, a start or goal, a point at track distance ``d`` from one of those (an *anchor*), or a point
at distance ``d`` from where the other vehicle stands (generated as the search reaches it, so
the ratchet of two vehicles edging round a short ring is found too). A step moves one vehicle to
the next critical point along its edge, the other standing; it is allowed iff safe, which is
decided at its two ends: along an edge the track distance from a fixed point is the minimum of
affine functions, or ``|s - s_q|`` on the fixed point's own edge, checked apart.

A* runs over pairs of critical points with the sum of both vehicles' travel as the cost (and the
number of moves to break ties), and the sum of their track distances to their goals as the
heuristic (admissible and consistent). It returns the shortest one-at-a-time route, or, once
every reachable pair is searched, says why none exists.

Examples
--------
>>> from topology.track_graph import TrackGraph
>>> track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
>>> route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
>>> route.travel
(15.0, 12.0)
>>> [(m.vehicle, [track.name(p) for p in m.points]) for m in route.moves]
[(0, ['A', 'J', 'c:1.5']), (1, ['B', 'J', 'A']), (0, ['c:1.5', 'J', 'B'])]
"""

from __future__ import annotations

import bisect
import heapq
import itertools
from collections.abc import Sequence

import numpy as np

from topology.errors import InfeasibleError, SeparationError
from topology.graph_route import GraphMove, GraphRoute, class_signature
from topology.track_graph import EdgePoint, TrackGraph
from topology.validation import check_vehicle_count, finite_real, short_repr

__all__ = ["CLASS_WEIGHT", "plan_graph", "plan_graph_classes"]

#: Weight of the yielding-free vehicle's metres in the alternative classes of :func:`plan_graph_classes`.
CLASS_WEIGHT = 4.0

#: Metres by which a distance may fall short of the separation and still count as apart (round-off),
#: and within which two critical points of an edge are one.
TOLERANCE = 1e-9
#: Pairs of critical points searched at most (a safety stop against a track too large to plan).
MAX_STATES = 2_000_000


def plan_graph(
    track: TrackGraph,
    start: Sequence[str | EdgePoint],
    goal: Sequence[str | EdgePoint],
    *,
    min_separation: float,
    names: Sequence[str] = ("vehicle 1", "vehicle 2"),
    weights: tuple[float, float] = (1.0, 1.0),
) -> GraphRoute:
    """The shortest collision-free route of two vehicles on ``track``, one moving at a time.

    Parameters
    ----------
    track : TrackGraph
    start, goal : sequence of 2 str or EdgePoint
        Each vehicle's start and goal, as ``"EDGE:s"`` (metres from the edge's ``from`` node) or a
        node's name.
    min_separation : float
        Metres of track distance the vehicles keep at all times, positive.
    names : sequence of 2 str
        The vehicles' names, for messages.
    weights : tuple of 2 float
        What a metre of each vehicle's travel costs (default ``(1, 1)``: the sum of both travels is
        minimised). A larger weight makes that vehicle's detours dearer, so the other one yields:
        :func:`plan_graph_classes` plans the alternative classes so.

    Returns
    -------
    GraphRoute
        The route that minimises the (weighted) sum of both vehicles' travel (of those, the fewest moves).

    Raises
    ------
    PositionError
        A start or goal is not on the track.
    SeparationError
        ``min_separation`` is not positive, or the vehicles start or end closer than it.
    InfeasibleError
        No collision-free route exists (the message says ``no collision-free route``, names the
        vehicle that cannot get through and where the other blocks it), or the track is too large.
    """
    separation = finite_real(min_separation, "minimum separation (m)", SeparationError)
    if separation <= 0.0:
        raise SeparationError(f"minimum separation is {separation!r} m: expected a positive distance")
    if not len(start) == len(goal) == len(names):
        raise SeparationError(
            f"expected a start, a goal and a name for each vehicle, got {short_repr(start)}, "
            f"{short_repr(goal)}, {short_repr(names)}"
        )
    check_vehicle_count(len(start), "the track-graph planner")
    if len(weights) != 2 or not all(finite_real(w, "route weight", SeparationError) > 0.0 for w in weights):
        raise SeparationError(f"route weights {short_repr(weights)}: expected two positive numbers")
    starts = (track.point(start[0]), track.point(start[1]))
    goals = (track.point(goal[0]), track.point(goal[1]))
    for what, pair in (("start", starts), ("goal", goals)):
        gap = track.distance(*pair)
        if gap < separation - TOLERANCE:
            raise SeparationError(
                f"the vehicles' {what} positions {track.name(pair[0])} and {track.name(pair[1])} are "
                f"{gap:.6g} m apart along the track: expected at least the minimum separation "
                f"{separation:g} m"
            )
    search = _Search(track, separation, starts, goals, tuple(names))
    search.weights = (float(weights[0]), float(weights[1]))
    return search.run()


def plan_graph_classes(
    track: TrackGraph,
    start: Sequence[str | EdgePoint],
    goal: Sequence[str | EdgePoint],
    *,
    min_separation: float,
    names: Sequence[str] = ("vehicle 1", "vehicle 2"),
) -> tuple[GraphRoute, ...]:
    """The shortest route and up to two more of other classes: where either vehicle yields instead.

    The alternatives are the shortest routes when one vehicle's metres cost :data:`CLASS_WEIGHT`
    times the other's (so the other one makes the detours: parks, or takes the other side of a
    loop). Distinct classes (:func:`class_signature`) only, the shortest (``plan_graph``'s) first,
    then by the sum of both travels.

    Raises
    ------
    InfeasibleError, PositionError, SeparationError
        As :func:`plan_graph`.
    """
    shortest = plan_graph(track, start, goal, min_separation=min_separation, names=names)
    routes = {class_signature(shortest): shortest}
    for weights in ((1.0, CLASS_WEIGHT), (CLASS_WEIGHT, 1.0)):
        other = plan_graph(track, start, goal, min_separation=min_separation, names=names, weights=weights)
        routes.setdefault(class_signature(other), other)
    alternatives = sorted(list(routes.values())[1:], key=lambda r: (round(r.length, 9), len(r.moves)))
    return (shortest, *alternatives)


class _Search:
    """The A* of :func:`plan_graph`: pure Python over lists, since each step is a handful of numbers."""

    def __init__(self, track: TrackGraph, separation: float, starts, goals, names) -> None:
        self.track, self.separation, self.starts, self.goals, self.names = (
            track,
            separation,
            starts,
            goals,
            names,
        )
        self.ends = [track.ends(e) for e in range(track.edge_count)]
        self.lengths = [track.length(e) for e in range(track.edge_count)]
        self.nodes = track.node_distances.tolist()
        self.incident: list[list[tuple[int, float, int]]] = [[] for _ in track.nodes]
        for edge, (start, end) in enumerate(self.ends):
            self.incident[start].append((edge, 0.0, 1))
            self.incident[end].append((edge, self.lengths[edge], -1))
        self.node_points = [track.node_point(n) for n in range(len(track.nodes))]
        self.cuts = self._static_cuts()
        self.keys: dict[EdgePoint, tuple[int, float]] = {}
        self.weights = (1.0, 1.0)

    # -- geometry ---------------------------------------------------------------------------------

    def _to_node(self, point: EdgePoint, node: int) -> float:
        start, end = self.ends[point.edge]
        return min(
            self.nodes[start][node] + point.s, self.nodes[end][node] + self.lengths[point.edge] - point.s
        )

    def _distance(self, a: EdgePoint, b: EdgePoint) -> float:
        start, end = self.ends[b.edge]
        rest = self.lengths[b.edge] - b.s
        best = min(self._to_node(a, start) + b.s, self._to_node(a, end) + rest)
        return min(best, abs(a.s - b.s)) if a.edge == b.edge else best

    def _at_separation(self, point: EdgePoint, edge: int) -> list[float]:
        """The places of ``edge`` at track distance ``separation`` from ``point`` along some way."""
        start, end = self.ends[edge]
        length, d = self.lengths[edge], self.separation
        found = [d - self._to_node(point, start), length - (d - self._to_node(point, end))]
        if point.edge == edge:
            found += [point.s - d, point.s + d]
        return [s for s in found if 0.0 <= s <= length]

    def _static_cuts(self) -> list[list[float]]:
        """Each edge's critical points before the search, sorted.

        Its ends, the starts and goals on it, and the points at the separation from a node, a
        start or a goal (vectorized: one row of node distances per anchor).
        """
        track, d = self.track, self.separation
        extra = [*self.starts, *self.goals]
        ends = np.array(self.ends, dtype=np.intp).reshape(-1, 2)
        lengths = np.array(self.lengths)
        nodes = track.node_distances
        edges = np.array([p.edge for p in extra], dtype=np.intp)
        places = np.array([p.s for p in extra])
        to_nodes = np.vstack(
            [
                nodes,
                np.minimum(
                    nodes[ends[edges, 0]] + places[:, None],
                    nodes[ends[edges, 1]] + (lengths[edges] - places)[:, None],
                ),
            ]
        )
        cuts: list[set[float]] = [{0.0, length} for length in self.lengths]
        for point in extra:
            cuts[point.edge].add(point.s)
            for other in (point.s - d, point.s + d):
                if 0.0 <= other <= self.lengths[point.edge]:
                    cuts[point.edge].add(other)
        for found in (d - to_nodes[:, ends[:, 0]], lengths - (d - to_nodes[:, ends[:, 1]])):
            rows, hit = np.nonzero((found >= 0.0) & (found <= lengths))
            for edge, value in zip(hit.tolist(), found[rows, hit].tolist(), strict=True):
                cuts[edge].add(value)
        merged = []
        for edge, values in enumerate(cuts):
            ordered: list[float] = []
            for value in sorted(values):
                if not ordered or value - ordered[-1] > TOLERANCE:
                    ordered.append(value)
            ordered[-1] = self.lengths[edge]  # the edge's end exactly, also after a merge near it
            merged.append(ordered)
        return merged

    def _node_at(self, point: EdgePoint) -> int | None:
        """As :meth:`TrackGraph.node_at`, over the search's lists (it is called for every step)."""
        if point.s <= TOLERANCE:
            return self.ends[point.edge][0]
        if point.s >= self.lengths[point.edge] - TOLERANCE:
            return self.ends[point.edge][1]
        return None

    def _key(self, point: EdgePoint) -> tuple[int, float]:
        key = self.keys.get(point)
        if key is None:
            node = self._node_at(point)
            key = (-1 - node, 0.0) if node is not None else (point.edge, round(point.s, 9))
            self.keys[point] = key
        return key

    def _steps(self, moving: EdgePoint, standing: EdgePoint):
        """Each allowed step of the vehicle at ``moving``: (where it ends, metres, along which edge)."""
        node = self._node_at(moving)
        ways = (
            self.incident[node]
            if node is not None
            else ((moving.edge, moving.s, 1), (moving.edge, moving.s, -1))
        )
        for edge, s, sign in ways:
            cuts = self.cuts[edge]
            dynamic = self._at_separation(standing, edge)
            if sign > 0:
                at = bisect.bisect_right(cuts, s + TOLERANCE)
                ahead = [v for v in dynamic if v > s + TOLERANCE]
                if at < len(cuts):
                    ahead.append(cuts[at])
                if not ahead:
                    continue
                there = min(ahead)
            else:
                at = bisect.bisect_left(cuts, s - TOLERANCE) - 1
                ahead = [v for v in dynamic if v < s - TOLERANCE]
                if at >= 0:
                    ahead.append(cuts[at])
                if not ahead:
                    continue
                there = max(ahead)
            if standing.edge == edge and min(s, there) < standing.s < max(s, there):
                continue  # it would pass through the standing vehicle
            node = self._node_at(EdgePoint(edge, there))
            point = EdgePoint(edge, there) if node is None else self.node_points[node]
            if self._distance(standing, point) >= self.separation - TOLERANCE:
                yield point, abs(there - s), edge

    # -- search -----------------------------------------------------------------------------------

    def run(self) -> GraphRoute:
        goals = self.goals
        target = (self._key(goals[0]), self._key(goals[1]))

        to_goal: tuple[dict, dict] = ({}, {})

        def estimate(pair) -> float:
            total = 0.0
            for vehicle in (0, 1):
                known = to_goal[vehicle].get(pair[vehicle])
                if known is None:
                    known = to_goal[vehicle][pair[vehicle]] = self._distance(pair[vehicle], goals[vehicle])
                total += self.weights[vehicle] * known
            return total

        start = (self._key(self.starts[0]), self._key(self.starts[1]), 2)
        best: dict[tuple, tuple[float, int]] = {start: (0.0, 0)}
        came: dict[tuple, tuple[tuple, tuple[EdgePoint, EdgePoint], int]] = {}
        where: dict[tuple, tuple[EdgePoint, EdgePoint]] = {start: self.starts}
        done: set[tuple] = set()
        heap = [(round(estimate(self.starts), 9), 0, 0.0, start)]
        while heap:
            _, moves, cost, state = heapq.heappop(heap)
            if state in done:
                continue
            done.add(state)
            if (state[0], state[1]) == target:
                return self._route(state, came, where, len(done))
            if len(done) > MAX_STATES:
                raise InfeasibleError(
                    f"the track is too large to plan: more than {MAX_STATES:,} pairs of critical points "
                    "searched (a safety stop): expected a smaller track or fewer, longer edges"
                )
            pair = where[state]
            for vehicle in (0, 1):
                more = moves + (vehicle != state[2])
                for point, step, edge in self._steps(pair[vehicle], pair[1 - vehicle]):
                    following = (point, pair[1]) if vehicle == 0 else (pair[0], point)
                    key = (self._key(following[0]), self._key(following[1]), vehicle)
                    if key in done:
                        continue
                    total = cost + self.weights[vehicle] * step
                    known = best.get(key)
                    if known is None or (round(total, 9), more) < (round(known[0], 9), known[1]):
                        best[key] = (total, more)
                        came[key] = (state, pair, edge)
                        where[key] = following
                        heapq.heappush(heap, (round(total + estimate(following), 9), more, total, key))
        raise InfeasibleError(self._why(done, where))

    def _route(self, state, came, where, searched: int) -> GraphRoute:
        pairs = [where[state]]
        edges: list[int] = []
        while state in came:
            state, pair, edge = came[state]
            pairs.append(pair)
            edges.append(edge)
        pairs.reverse()
        edges.reverse()
        moves: list[GraphMove] = []
        travel = [0.0, 0.0]
        current: list[EdgePoint] = []
        along: list[int] = []
        mover = -1
        began = pairs[0]
        for (before, after), edge in zip(itertools.pairwise(pairs), edges, strict=True):
            vehicle = 0 if self._key(before[0]) != self._key(after[0]) else 1
            step = self._distance(before[vehicle], after[vehicle])
            travel[vehicle] += step
            back = (
                vehicle == mover
                and len(current) >= 2
                and self._turns(current[-2], current[-1], after[vehicle])
            )
            if vehicle != mover or back:
                if current:
                    moves.append(self._move(mover, current, along, began))
                current, along, mover, began = [before[vehicle]], [], vehicle, before
            current.append(after[vehicle])
            along.append(edge)
        if current:
            moves.append(self._move(mover, current, along, began))
        return GraphRoute(
            self.track,
            self.separation,
            self.starts,
            self.goals,
            tuple(moves),
            (travel[0], travel[1]),
            self._critical_points(),
            searched,
            self.names,
        )

    def _critical_points(self) -> int:
        """Distinct static critical points: the nodes once, and the cuts inside the edges."""
        inside = sum(1 for cuts in self.cuts for s in cuts[1:-1])
        return len(self.track.nodes) + inside

    def _turns(self, a: EdgePoint, b: EdgePoint, c: EdgePoint) -> bool:
        """Whether going a -> b -> c turns back at b (c lies back towards a along b's edge)."""
        return self._distance(a, c) < self._distance(a, b) + self._distance(b, c) - TOLERANCE

    def _move(self, vehicle: int, points: list[EdgePoint], along: list[int], began) -> GraphMove:
        """A move through ``points`` along ``along`` (the edge of each step), kept at nodes and ends.

        ``began``: every vehicle's point as the move begins.
        """
        kept = [0] + [k for k in range(1, len(points) - 1) if self.track.node_at(points[k]) is not None]
        kept.append(len(points) - 1)
        length = sum(self._distance(a, b) for a, b in itertools.pairwise(points))
        edges = tuple(along[k] for k in kept[:-1])
        return GraphMove(vehicle, tuple(points[k] for k in kept), edges, length, tuple(began))

    def _why(self, searched: set[tuple], where) -> str:
        """Which vehicle cannot reach its goal, how close it gets, and where the other blocks it."""
        track, goals, names = self.track, self.goals, self.names
        reached = [where[state] for state in searched]
        left = [[self._distance(pair[v], goals[v]) for pair in reached] for v in (0, 1)]
        stuck = 0 if min(left[0]) > min(left[1]) else 1
        if min(left[0]) <= TOLERANCE and min(left[1]) <= TOLERANCE:
            # each goal is reached, never both: the order of the vehicles cannot change
            stuck = 1
        row = min(range(len(reached)), key=lambda k: (left[stuck][k], left[1 - stuck][k]))
        closest, blocker = reached[row][stuck], reached[row][1 - stuck]
        return (
            f"no collision-free route from ({track.name(self.starts[0])}, {track.name(self.starts[1])}) "
            f"to ({track.name(goals[0])}, {track.name(goals[1])}) keeping {self.separation:g} m apart: "
            f"{names[stuck]} cannot reach its goal {track.name(goals[stuck])} while {names[1 - stuck]} "
            f"reaches {track.name(goals[1 - stuck])}. {names[stuck]} gets no closer than "
            f"{left[stuck][row]:.6g} m to it (at {track.name(closest)}): {names[1 - stuck]} "
            f"{self._place(blocker)} blocks it, and no siding or loop of at least "
            f"{self.separation:g} m lets them pass there"
        )

    def _place(self, point: EdgePoint) -> str:
        """Where ``point`` is, for people: ``at node W`` or ``at m:4 (between J1 and J2)``."""
        node = self.track.node_at(point)
        if node is not None:
            return f"at node {self.track.nodes[node]}"
        edge = self.track.edges[point.edge]
        return f"at {self.track.name(point)} (between {edge.start} and {edge.end})"
