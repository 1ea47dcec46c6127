"""Where a track graph and a route on it are drawn, seen from above: pure geometry, no drawing.

The nodes are where the scenario puts them (``[track] nodes``), or, without coordinates, laid out
by classical multidimensional scaling of their track distances (the two main axes of the doubly
centred squared distances), so nearby nodes stay near. An edge is drawn straight between its nodes
when its length is their distance; a longer edge, or a second edge between the same two nodes (a
passing loop), bulges out as a parabola whose length is the edge's (or, for a parallel edge drawn
as straight as its length allows, enough to be told apart). A point ``EDGE:s`` lies at the fraction
``s / length`` of its edge's drawn length. The drawing is :func:`trajgen.plots.graph_route.plot_graph_route`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from topology import EdgePoint, GraphRoute, TrackGraph
from trajgen.model.values import readonly

__all__ = ["TrackLayout"]

#: Points sampled along each drawn edge.
EDGE_SAMPLES = 41
#: A parallel edge's smallest bulge, as a fraction of its nodes' distance.
PARALLEL_BULGE = 0.3


@dataclass(frozen=True, slots=True, eq=False)
class TrackLayout:
    """The drawn track: each node's x/y and each edge's polyline, metres.

    Attributes
    ----------
    track : TrackGraph
    nodes : ndarray, shape (n, 2)
        Each node's x/y.
    edges : tuple of ndarray, each shape (EDGE_SAMPLES, 2)
        Each edge's drawn polyline, from its ``from`` node to its ``to`` node.
    given : bool
        Whether the node coordinates are the scenario's (else laid out here).
    """

    track: TrackGraph
    nodes: np.ndarray
    edges: tuple[np.ndarray, ...]
    given: bool

    @classmethod
    def of(cls, track: TrackGraph) -> TrackLayout:
        """The layout of ``track``: its coordinates, or its track distances scaled onto a plane."""
        given = track.coordinates is not None
        nodes = np.array(track.coordinates) if given else _scaled(track.node_distances)
        seen: dict[tuple[int, int], int] = {}
        edges = []
        for number in range(track.edge_count):
            start, end = track.ends(number)
            pair = (min(start, end), max(start, end))
            rank = seen.get(pair, 0)
            seen[pair] = rank + 1
            edges.append(readonly(_edge_line(nodes[start], nodes[end], track.length(number), rank)))
        return cls(track, readonly(nodes), tuple(edges), given)

    def points(self, edges, s) -> np.ndarray:
        """The x/y where the points ``(edges[i], s[i])`` are drawn, shape (n, 2)."""
        return np.array([self.point(EdgePoint(int(e), float(x))) for e, x in zip(edges, s, strict=True)])

    def point(self, point: EdgePoint) -> np.ndarray:
        """The x/y where ``point`` is drawn, shape (2,)."""
        return self.along(point.edge, point.s, point.s)[-1]

    def along(self, edge: int, s_from: float, s_to: float) -> np.ndarray:
        """The drawn polyline of ``edge`` from ``s_from`` to ``s_to`` metres (either way), shape (m, 2)."""
        line = self.edges[edge]
        length = self.track.length(edge)
        steps = np.linalg.norm(np.diff(line, axis=0), axis=1)
        drawn = np.concatenate([[0.0], np.cumsum(steps)]) / max(float(steps.sum()), 1e-12) * length
        low, high = sorted((s_from, s_to))
        inside = (drawn > low) & (drawn < high)
        ends = (
            [np.interp(low, drawn, line[:, k]) for k in (0, 1)],
            [np.interp(high, drawn, line[:, k]) for k in (0, 1)],
        )
        piece = np.vstack([ends[0], line[inside], ends[1]])
        return piece if s_from <= s_to else piece[::-1]

    def tangents(self, edges, s) -> np.ndarray:
        """The unit direction of each edge as drawn at ``s`` metres, toward its ``to`` node, shape (n, 2)."""
        out = np.zeros((len(edges), 2))
        for k, (edge, at) in enumerate(zip(edges, s, strict=True)):
            line = self.edges[int(edge)]
            steps = np.diff(line, axis=0)
            lengths = np.linalg.norm(steps, axis=1)
            drawn = np.concatenate([[0.0], np.cumsum(lengths)]) / max(float(lengths.sum()), 1e-12)
            piece = int(
                np.clip(
                    np.searchsorted(drawn, float(at) / self.track.length(int(edge))) - 1, 0, len(steps) - 1
                )
            )
            step = steps[piece] if lengths[piece] > 0.0 else line[-1] - line[0]
            norm = float(np.hypot(*step))
            out[k] = step / norm if norm > 0.0 else (1.0, 0.0)
        return out

    def move(self, route: GraphRoute, number: int) -> np.ndarray:
        """The drawn path of move ``number`` of ``route``, shape (m, 2)."""
        move = route.moves[number]
        pieces = []
        for (a, b), edge in zip(zip(move.points, move.points[1:], strict=False), move.edges, strict=True):
            pieces.append(self.along(edge, self.track.position_on(a, edge), self.track.position_on(b, edge)))
        return np.vstack(pieces)

    @property
    def extent(self) -> float:
        """The larger side of the drawing's bounding box, metres (at least 1)."""
        every = np.vstack([self.nodes, *self.edges])
        return max(float(np.ptp(every[:, 0])), float(np.ptp(every[:, 1])), 1.0)


def _scaled(distances: np.ndarray) -> np.ndarray:
    """Classical multidimensional scaling of a distance matrix onto the plane, shape (n, 2)."""
    count = distances.shape[0]
    if count == 1:
        return np.zeros((1, 2))
    centring = np.eye(count) - 1.0 / count
    gram = -0.5 * centring @ (distances**2) @ centring
    values, vectors = np.linalg.eigh(gram)
    order = np.argsort(values)[::-1][:2]
    plane = vectors[:, order] * np.sqrt(np.clip(values[order], 0.0, None))
    # a sign convention, so the same track is always drawn the same way round
    signs = np.where(plane[np.argmax(np.abs(plane), axis=0), [0, 1]] < 0, -1.0, 1.0)
    return plane * signs


def _edge_line(start: np.ndarray, end: np.ndarray, length: float, rank: int) -> np.ndarray:
    """An edge's drawn polyline: straight, or a parabola as long as the edge (parallel ones apart)."""
    chord = end - start
    distance = float(np.hypot(*chord))
    t = np.linspace(0.0, 1.0, EDGE_SAMPLES)[:, None]
    if distance < 1e-9:  # nodes drawn at one place: a loop-shaped bulge of the edge's length
        normal, distance = np.array([0.0, 1.0]), 0.0
    else:
        normal = np.array([-chord[1], chord[0]]) / distance
    # a parabola of height h over a chord c is about c + 8 h^2 / (3 c) long
    height = math.sqrt(max(0.0, 3.0 * max(distance, 1e-9) * (length - distance) / 8.0))
    if rank:
        height = max(height, PARALLEL_BULGE * max(distance, length / 3.0) * ((rank + 1) // 2))
        height *= 1.0 if rank % 2 else -1.0
    return start + t * chord + (4.0 * height * t * (1.0 - t)) * normal
