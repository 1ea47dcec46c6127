"""A vehicle's path on a track graph as the online executor reads it, and the graph's track distance.

:class:`GraphVehiclePath` answers, for one travel value at a time, what
:class:`~trajgen.model.paths.VehiclePath` answers on a junction: where the vehicle is (edge and
metres from the edge's ``from`` node), its heading and signed axis, the next place it must stop,
the travel at which it passes a measured position, and the track it sweeps over a range of travel.
:class:`GraphMetric` measures the track distance between points and between the swept stretches.
Plain floats and tuples, no arrays: these run every control cycle, where numpy's per-call cost
would dominate. The vectorised forms for whole schedules are
:class:`~trajgen.model.graph_paths.GraphPath` and :meth:`topology.TrackGraph.distances`.
"""

from __future__ import annotations

import bisect
import itertools
import math
from dataclasses import dataclass

from topology import TrackGraph
from trajgen.model.graph_paths import GraphPath
from trajgen.model.paths import TravelAxis, travel_within_segment

__all__ = ["GraphMetric", "GraphVehiclePath", "Stretch"]

#: One stretch of track: (edge index, smallest s, largest s), metres from the edge's ``from`` node.
Stretch = tuple[int, float, float]


class GraphMetric:
    """Track distances on a track graph, metres, one pair at a time.

    Parameters
    ----------
    track : TrackGraph
    """

    __slots__ = ("_ends", "_lengths", "_nodes")

    def __init__(self, track: TrackGraph) -> None:
        self._ends = tuple(track.ends(k) for k in range(track.edge_count))
        self._lengths = tuple(track.length(k) for k in range(track.edge_count))
        self._nodes = tuple(tuple(float(d) for d in row) for row in track.node_distances)

    @property
    def lengths(self) -> tuple[float, ...]:
        """Each edge's length, metres."""
        return self._lengths

    def distance(self, edge_a: int, s_a: float, edge_b: int, s_b: float) -> float:
        """Track distance between ``(edge_a, s_a)`` and ``(edge_b, s_b)``, metres.

        The shortest way leaves each point through one end of its edge, or, on one edge, runs
        along it (as :meth:`topology.TrackGraph.distances`).
        """
        (u_a, v_a), (u_b, v_b) = self._ends[edge_a], self._ends[edge_b]
        r_a, r_b = self._lengths[edge_a] - s_a, self._lengths[edge_b] - s_b
        nodes = self._nodes
        best = min(
            nodes[u_a][u_b] + s_a + s_b,
            nodes[u_a][v_b] + s_a + r_b,
            nodes[v_a][u_b] + r_a + s_b,
            nodes[v_a][v_b] + r_a + r_b,
        )
        return min(best, abs(s_a - s_b)) if edge_a == edge_b else best

    def stretch_distance(self, first: Stretch, second: Stretch) -> float:
        """Track distance between two stretches of track, metres: 0 where they share track.

        Each way between two points is affine in each point's position, so the least over two
        stretches that do not overlap is at a pair of their ends.
        """
        edge_a, low_a, high_a = first
        edge_b, low_b, high_b = second
        if edge_a == edge_b and low_a <= high_b and low_b <= high_a:
            return 0.0
        return min(
            self.distance(edge_a, s_a, edge_b, s_b)
            for s_a, s_b in itertools.product((low_a, high_a), (low_b, high_b))
        )

    def set_distance(self, first: tuple[Stretch, ...], second: tuple[Stretch, ...]) -> float:
        """Track distance between two unions of stretches, metres."""
        best = math.inf
        for a in first:
            for b in second:
                gap = self.stretch_distance(a, b)
                if gap < best:
                    best = gap
                    if best == 0.0:
                        return 0.0
        return best


@dataclass(frozen=True, slots=True)
class GraphVehiclePath(TravelAxis):
    """One vehicle's path on a track graph, parameterised by its travel ``p`` (metres), for execution.

    Its segment, heading, axis, travel at an axis value and next stop are :class:`TravelAxis`'s,
    as a junction's :class:`~trajgen.model.paths.VehiclePath`.

    Attributes
    ----------
    edges : tuple of int, shape (m,)
        Edge of each segment.
    s_from, s_to : tuple of float, shape (m,)
        Metres from the edge's ``from`` node at each segment's ends.
    starts : tuple of float, shape (m,)
        Travel at each segment's start, metres (``starts[0] == 0``).
    headings : tuple of int, shape (m,)
        ``d axis / dp`` on each segment: +1 or -1, flipping at each reversal.
    axis_starts : tuple of float, shape (m,)
        Axis value at each segment's start, metres (one value, the axis, if ``m == 0``).
    length : float
        Total travel, metres.
    stops : tuple of float
        Travel at each reversal, ascending, metres (the vehicle is at rest there).
    home : tuple of (int, float)
        ``(edge, s)`` where the vehicle starts (all of a path that does not move).
    edge_lengths : tuple of float
        Every edge's length, metres: a sweep past either end of the path stays on its edge.
    home_orientation : int
        ``ds / d axis`` of a path that does not move: the ``orientation`` it was built with (+1 if
        none). A vehicle that stays put keeps the way its axis runs, so its next plan continues it.
    """

    edges: tuple[int, ...]
    s_from: tuple[float, ...]
    s_to: tuple[float, ...]
    starts: tuple[float, ...]
    headings: tuple[int, ...]
    axis_starts: tuple[float, ...]
    length: float
    stops: tuple[float, ...]
    home: tuple[int, float]
    edge_lengths: tuple[float, ...]
    home_orientation: int = 1

    @classmethod
    def from_path(
        cls, path: GraphPath, track: TrackGraph, *, axis_start: float = 0.0, orientation: int | None = None
    ) -> GraphVehiclePath:
        """The execution form of ``path`` on ``track``.

        Parameters
        ----------
        path : GraphPath
        track : TrackGraph
        axis_start : float, optional
            Axis value at the start, metres.
        orientation : int, optional
            ``ds / d axis`` at the start (+1 if the axis grows away from the start edge's ``from``
            node). ``None``: the axis grows along the first move (the convention of the schedules).
        """
        directions = [1 if b > a else -1 for a, b in zip(path.s_from, path.s_to, strict=True)]
        flip = 1
        if directions and orientation is not None:
            flip = directions[0] * (1 if orientation >= 0 else -1)
        headings = tuple(flip * int(h) for h in path.headings)
        starts = tuple(float(p) for p in path.starts[:-1])
        axis_starts, axis = [], float(axis_start)
        for k, heading in enumerate(headings):
            axis_starts.append(axis)
            axis += heading * (float(path.starts[k + 1]) - starts[k])
        if not headings:
            axis_starts.append(axis)
        return cls(
            tuple(int(e) for e in path.edges),
            tuple(float(s) for s in path.s_from),
            tuple(float(s) for s in path.s_to),
            starts,
            headings,
            tuple(axis_starts),
            path.length,
            tuple(float(c) for c in path.cusps),
            (path.home.edge, path.home.s),
            tuple(track.length(k) for k in range(track.edge_count)),
            -1 if orientation is not None and orientation < 0 else 1,
        )

    def _along(self, k: int, p: float) -> float:
        """Metres from segment ``k``'s edge's ``from`` node at travel ``p`` (clipped to the segment)."""
        end = self.starts[k + 1] if k + 1 < len(self.starts) else self.length
        local = min(max(p - self.starts[k], 0.0), end - self.starts[k])
        return self.s_from[k] + (local if self.s_to[k] > self.s_from[k] else -local)

    def place(self, p: float) -> tuple[int, float, int, float, int]:
        """Everything about travel ``p`` at once: ``(edge, s, heading, axis, branch)``.

        ``branch`` is the edge the vehicle takes at the end of its segment: the next segment's
        edge where it passes a node of the track there, else its own. One segment lookup: this
        runs every control cycle.
        """
        if not self.edges:
            edge, s = self.home
            return edge, s, 1, self.axis(p), edge
        k = self.segment(p)
        heading = self.headings[k]
        axis = self.axis_starts[k] + heading * (p - self.starts[k])
        branch = self.edges[k + 1] if k + 1 < len(self.edges) else self.edges[k]
        return self.edges[k], self._along(k, p), heading, axis, branch

    def locate(self, p: float) -> tuple[int, float]:
        """``(edge, s)`` at travel ``p`` (clipped to ``[0, length]``)."""
        if not self.edges:
            return self.home
        k = self.segment(p)
        return self.edges[k], self._along(k, p)

    def project(self, edge: int, s: float, near: float, metric: GraphMetric, slack: float = 1e-9):
        """The travel at which the path passes ``(edge, s)``, nearest ``near``; ``None`` if it never does.

        A position within ``slack`` metres of the path counts as on it (the track distance to the
        closest place of a segment, measured by ``metric``: a node of the track given on another
        of its edges is the same node). Before the start or past the end of the path on the end
        segments' edges, the travel is below 0 or above :attr:`length`. A place that holds the
        position exactly is preferred to one within ``slack`` of it; among those, the one nearest
        ``near`` (within ``slack`` of it counting as near).
        """
        if not self.edges:
            home_edge, home_s = self.home
            return 0.0 if metric.distance(edge, s, home_edge, home_s) <= slack else None
        own = self._on_own_segment(edge, s, near)
        if own is not None:
            return own
        best, best_key = None, (math.inf, math.inf)
        last = len(self.edges) - 1
        for k, seg_edge in enumerate(self.edges):
            s_from, s_to = self.s_from[k], self.s_to[k]
            sign = 1.0 if s_to > s_from else -1.0
            end = self.starts[k + 1] if k < last else self.length
            if seg_edge == edge:
                low, high = min(s_from, s_to), max(s_from, s_to)
                # the end segments run on along their edge
                if k == 0:
                    low, high = (0.0, high) if sign > 0 else (low, self.edge_lengths[edge])
                if k == last:
                    low, high = (low, self.edge_lengths[edge]) if sign > 0 else (0.0, high)
                clamped = min(max(s, low), high)
                off = abs(clamped - s)
                p = self.starts[k] + (clamped - s_from) * sign
            else:  # the segment's ends, one of which may be the same node as the point
                candidates = [(self.starts[k], s_from), (end, s_to)]
                top = self.edge_lengths[seg_edge]
                # the end segments run on to their edge's end node, which may be the point
                if k == 0:
                    candidates.append((-s_from, 0.0) if sign > 0 else (-(top - s_from), top))
                if k == last:
                    candidates.append((end + top - s_to, top) if sign > 0 else (end + s_to, 0.0))
                off, p = min((metric.distance(edge, s, seg_edge, at), q) for q, at in candidates)
            if off > slack:
                continue
            # how far off plus how far outside the window of ``slack`` about ``near``: a place that
            # holds the point exactly beats a segment's end within ``slack`` of it (as on a junction)
            key = ((off if off > 1e-9 else 0.0) + max(abs(p - near) - slack, 0.0), abs(p - near))
            if key < best_key:
                best, best_key = p, key
        return best

    def _on_own_segment(self, edge: int, s: float, near: float) -> float | None:
        """:meth:`project`'s answer on ``near``'s own segment, nearer than its ends (the usual case)."""
        k = self.segment(near)
        if self.edges[k] != edge:
            return None
        end = self.starts[k + 1] if k + 1 < len(self.starts) else self.length
        return travel_within_segment((self.starts[k], end), (self.s_from[k], self.s_to[k]), s, near)

    def overrun(self, p_low: float, p_high: float) -> float:
        """Metres travel over ``[p_low, p_high]`` may run beyond :meth:`sweep` (:meth:`run_on_overrun`).

        Past a track node where :meth:`sweep` stops at its edge's end, the vehicle is on another
        edge of the node; a track distance to the sweep less this overrun is sound.
        """
        if not self.edges:
            return self.run_on_overrun(p_low, p_high, (0.0, 0.0))
        lengths = self.edge_lengths
        return self.run_on_overrun(p_low, p_high, (lengths[self.edges[0]], lengths[self.edges[-1]]))

    def sweep(self, p_low: float, p_high: float) -> tuple[Stretch, ...]:
        """The track covered while travel runs over ``[p_low, p_high]``, as stretches per edge.

        Travel before 0 or past :attr:`length` runs on along the first or last segment's edge,
        clipped to the edge: what runs beyond the edge's end is :meth:`overrun`.
        """
        if not self.edges:
            edge, s = self.home
            return ((edge, s, s),)
        out = []
        starts, last = self.starts, len(self.edges) - 1
        first = max(bisect.bisect_left(starts, p_low) - 1, 0)
        for k in range(first, self.segment(p_high) + 1):
            start = starts[k]
            a = p_low if k == 0 or p_low > start else start
            b = p_high if k == last else min(p_high, starts[k + 1])
            if a > b:
                continue
            s_from = self.s_from[k]
            if self.s_to[k] > s_from:
                low, high = s_from + (a - start), s_from + (b - start)
            else:
                low, high = s_from - (b - start), s_from - (a - start)
            top = self.edge_lengths[self.edges[k]]
            out.append((self.edges[k], min(max(low, 0.0), top), min(max(high, 0.0), top)))
        if not out:  # an empty or reversed range: the point itself
            edge, s = self.locate(p_low)
            return ((edge, s, s),)
        return tuple(out)
