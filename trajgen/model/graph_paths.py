"""Each vehicle's path on a track graph as a function of the distance it has travelled.

A route on a track graph (:class:`topology.GraphRoute`) moves one vehicle at a time, or several in a
joint move; each vehicle's moves (its parts of joint moves too), taken in order, make its path: a
sequence of segments, each on one edge and monotone in the metres ``s`` from the edge's ``from``
node. The path is parameterised by the vehicle's *travel*
``p`` (metres driven, ``0 <= p <= length``), which never decreases, so a schedule is a monotone
curve in the ``(p1, p2)`` plane. The vehicle's signed axis (its odometer, exported beside ``s``)
changes by ``heading * dp``; the heading flips at a *cusp*, where the path turns back on its edge
and the vehicle must be at rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from topology import EdgePoint, GraphRoute, TrackGraph
from trajgen.model.paths import MOVE_RESOLUTION
from trajgen.model.values import ArrayValue, readonly

__all__ = ["GraphPath", "graph_paths", "path_through"]


@dataclass(frozen=True, slots=True, eq=False)
class GraphPath(ArrayValue):
    """One vehicle's path on a track graph, parameterised by its travel ``p`` (metres).

    Attributes
    ----------
    edges : ndarray of int, shape (m,)
        Edge number (in the track's order) of each segment.
    s_from, s_to : ndarray, shape (m,)
        Metres from the edge's ``from`` node at each segment's ends.
    starts : ndarray, shape (m + 1,)
        Travel at each segment's start, and the path's length last, metres.
    headings : ndarray of int, shape (m,)
        ``d axis / dp`` on each segment: +1, then flipping at each cusp.
    home : EdgePoint
        Where the vehicle is at ``p = 0`` (all of a path with no segments).
    """

    edges: np.ndarray
    s_from: np.ndarray
    s_to: np.ndarray
    starts: np.ndarray
    headings: np.ndarray
    home: EdgePoint

    def __post_init__(self) -> None:
        for name, dtype in (("edges", int), ("s_from", float), ("s_to", float), ("starts", float)):
            object.__setattr__(self, name, readonly(getattr(self, name), dtype))
        object.__setattr__(self, "headings", readonly(self.headings, int))

    @property
    def length(self) -> float:
        """Total travel, metres."""
        return float(self.starts[-1])

    @property
    def directions(self) -> np.ndarray:
        """``ds / dp`` on each segment: +1 away from the edge's ``from`` node, -1 towards it, shape (m,)."""
        return readonly(np.sign(self.s_to - self.s_from), int)

    @property
    def cusps(self) -> np.ndarray:
        """Travel at each point where the path turns back (the vehicle is at rest there), metres."""
        turns = np.nonzero(self.headings[1:] != self.headings[:-1])[0] + 1
        return readonly(self.starts[turns], float)

    @property
    def stops(self) -> tuple[float, ...]:
        """Travel at each cusp (:attr:`cusps`), as the star's paths name them, metres."""
        return tuple(float(p) for p in self.cusps)

    def segment(self, p) -> np.ndarray:
        """The segment each travel value lies in, shape (n,) (clipped to the path)."""
        p = np.atleast_1d(np.asarray(p, dtype=float))
        if self.edges.size == 0:
            return np.zeros(p.shape, dtype=int)
        return np.clip(np.searchsorted(self.starts, p, side="right") - 1, 0, self.edges.size - 1)

    def locate(self, p, *, extend: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Edge number and metres from its ``from`` node at travel values ``p``, shape (n,) each.

        Travel outside ``[0, length]`` (round-off at the ends) is clipped to it; with ``extend``,
        it runs on along the first and last segment's edge instead (within the edge), as a
        vehicle that creeps past its start or goal does.
        """
        p = np.atleast_1d(np.asarray(p, dtype=float))
        if self.edges.size == 0:
            return np.full(p.shape, self.home.edge, dtype=int), np.full(p.shape, self.home.s)
        k = self.segment(p)
        low = np.full(p.shape, -np.inf) if extend else np.zeros(p.shape)
        high = self.starts[k + 1] - self.starts[k]
        if extend:
            low = np.where(k == 0, -np.inf, 0.0)
            high = np.where(k == self.edges.size - 1, np.inf, high)
        along = np.clip(p - self.starts[k], low, high)
        s = self.s_from[k] + self.directions[k] * along
        return self.edges[k], s

    def axis(self, p) -> np.ndarray:
        """The signed axis (odometer) at travel values ``p``, metres, shape (n,): 0 at the start."""
        p = np.atleast_1d(np.asarray(p, dtype=float))
        if self.edges.size == 0:
            return np.zeros(p.shape)
        lengths = np.diff(self.starts)
        axis_starts = np.concatenate([[0.0], np.cumsum(self.headings * lengths)])
        k = self.segment(p)
        return axis_starts[k] + self.headings[k] * np.clip(p - self.starts[k], 0.0, lengths[k])

    def heading(self, p) -> np.ndarray:
        """``d axis / dp`` at travel values ``p`` (at a cusp: the segment after it), shape (n,)."""
        if self.edges.size == 0:
            return np.ones(np.atleast_1d(p).shape, dtype=int)
        return self.headings[self.segment(p)]


def _segments(track: TrackGraph, route: GraphRoute, vehicle: int) -> list[list]:
    """The vehicle's ``[edge, s_from, s_to]`` in order, a segment on one edge one way merged."""
    segments: list[list] = []
    for move in route.moves:
        if move.vehicle != vehicle:
            continue
        for a, b, edge in zip(move.points[:-1], move.points[1:], move.edges, strict=True):
            s_a, s_b = track.position_on(a, edge), track.position_on(b, edge)
            if abs(s_b - s_a) <= MOVE_RESOLUTION:
                continue
            last = segments[-1] if segments else None
            if last is not None and last[0] == edge and (last[2] - last[1]) * (s_b - s_a) > 0.0:
                last[2] = s_b  # the same edge the same way: the move resumes after the other's
            else:
                segments.append([edge, s_a, s_b])
    return segments


def graph_paths(route: GraphRoute) -> tuple[GraphPath, ...]:
    """Every vehicle's path along ``route``, in travel coordinates, in the route's vehicle order.

    Examples
    --------
    >>> from topology import TrackGraph, plan_graph
    >>> track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    >>> route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    >>> first, second = graph_paths(route)
    >>> first.length + second.length == route.length
    True
    """
    return tuple(
        _path_of(_segments(route.track, route, vehicle), route.start[vehicle])
        for vehicle in range(len(route.start))
    )


def _path_of(segments: list[list], home: EdgePoint) -> GraphPath:
    """The path of ``[edge, s_from, s_to]`` segments in order: its heading flips where it turns back."""
    lengths = [abs(s_to - s_from) for _, s_from, s_to in segments]
    headings = []
    heading = 1
    for k, (edge, s_from, s_to) in enumerate(segments):
        if (
            k
            and edge == segments[k - 1][0]
            and (s_to - s_from) * (segments[k - 1][2] - segments[k - 1][1]) < 0.0
        ):
            heading = -heading  # turns back on its edge: a cusp
        headings.append(heading)
    return GraphPath(
        edges=np.array([edge for edge, _, _ in segments], dtype=int),
        s_from=np.array([s for _, s, _ in segments]),
        s_to=np.array([s for _, _, s in segments]),
        starts=np.concatenate([[0.0], np.cumsum(lengths)]),
        headings=np.array(headings, dtype=int),
        home=home,
    )


def path_through(track: TrackGraph, edges, s) -> GraphPath:
    """The path through the places ``(edges[i], s[i])`` in order, between two of them not turning back.

    Between places on two edges the vehicle passes the node they share (a junction's ``O``); a
    segment on one edge one way is merged. The places of a junction's schedule at its own instants
    (:func:`~trajgen.model.coordination.schedule_times`) give the path the schedule drives.

    Raises
    ------
    ValueError
        Two consecutive places on edges that share no node.
    """
    edges = [int(e) for e in edges]
    s = [float(x) for x in s]
    segments: list[list] = []

    def add(edge: int, s_a: float, s_b: float) -> None:
        if abs(s_b - s_a) <= MOVE_RESOLUTION:
            return
        last = segments[-1] if segments else None
        if last is not None and last[0] == edge and (last[2] - last[1]) * (s_b - s_a) > 0.0:
            last[2] = s_b
        else:
            segments.append([edge, s_a, s_b])

    for (e_a, s_a), (e_b, s_b) in zip(
        zip(edges, s, strict=True), zip(edges[1:], s[1:], strict=True), strict=False
    ):
        if e_a == e_b:
            add(e_a, s_a, s_b)
            continue
        shared = sorted(set(track.ends(e_a)) & set(track.ends(e_b)))
        if not shared:
            raise ValueError(
                f"places on edges {e_a} and {e_b} share no node: expected a path along the track"
            )
        node = shared[0]
        add(e_a, s_a, 0.0 if track.ends(e_a)[0] == node else track.length(e_a))
        add(e_b, 0.0 if track.ends(e_b)[0] == node else track.length(e_b), s_b)
    return _path_of(segments, EdgePoint(edges[0], s[0]) if edges else EdgePoint(0, 0.0))
