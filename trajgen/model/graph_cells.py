"""The plane of both vehicles' travel on a track graph, cut into cells (docs/graphs.md).

A pair of path segments, one per vehicle, each on one edge, is a rectangle of the travel plane: a
**cell**. On a cell the track distance is the least of at most five affine functions of the two
travels: through each pair of the two edges' ends, and, when both are on one edge, along it
(``|s1 - s2|``). So the part of a cell closer than the separation is a union of at most five
convex polygons (one per way), and the safe part, on the side of the along-the-edge strip the
route keeps, is convex. The timing methods (``optimal``) and the coordination diagram take their
ways from here; the verifier computes its own.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from topology import TrackGraph
from trajgen.model.graph_paths import GraphPath

__all__ = ["TooClose", "Way", "cell_ways", "too_close_polygons"]

#: An affine way of the track distance on a cell: ``c1 * p1 + c2 * p2 + c0`` (metres).
Way = tuple[float, float, float]


def _on_segment(path: GraphPath, segment: int) -> tuple[int, float, float]:
    """Edge, ``sign``, ``offset`` of ``s = offset + sign * p`` on a segment (never moving: its home)."""
    if path.edges.size == 0:
        return path.home.edge, 0.0, path.home.s
    sign = float(np.sign(path.s_to[segment] - path.s_from[segment]))
    return int(path.edges[segment]), sign, float(path.s_from[segment]) - sign * float(path.starts[segment])


def cell_ways(
    track: TrackGraph, paths: tuple[GraphPath, GraphPath], segments: tuple[int, int]
) -> tuple[list[Way], Way | None]:
    """The ways of the track distance on a cell.

    Returns
    -------
    through_ends : list of Way
        The four ways through the edges' ends.
    along : Way or None
        ``s1 - s2`` when both segments are on one edge (the distance along it is its absolute value).
    """
    nodes = track.node_distances
    placed = [_on_segment(paths[v], segments[v]) for v in range(2)]
    edges = [edge for edge, _, _ in placed]
    sign = [s for _, s, _ in placed]
    offset = [o for _, _, o in placed]
    lengths = [track.length(e) for e in edges]
    ends = [track.ends(e) for e in edges]
    ways: list[Way] = []
    for end_1, end_2 in itertools.product((0, 1), (0, 1)):
        f1, f2 = (-1.0 if end_1 else 1.0), (-1.0 if end_2 else 1.0)
        constant = float(nodes[ends[0][end_1], ends[1][end_2]])
        constant += (lengths[0] if end_1 else 0.0) + (lengths[1] if end_2 else 0.0)
        ways.append((f1 * sign[0], f2 * sign[1], constant + f1 * offset[0] + f2 * offset[1]))
    along = (sign[0], -sign[1], offset[0] - offset[1]) if edges[0] == edges[1] else None
    return ways, along


def _clip(polygon: list, a: float, b: float, c: float) -> list:
    """The part of a convex polygon where ``a x + b y <= c`` (Sutherland–Hodgman, one half-plane)."""
    out = []
    for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        f0, f1 = a * x0 + b * y0 - c, a * x1 + b * y1 - c
        if f0 <= 0.0:
            out.append((x0, y0))
        if (f0 < 0.0 < f1) or (f1 < 0.0 < f0):
            r = f0 / (f0 - f1)
            out.append((x0 + r * (x1 - x0), y0 + r * (y1 - y0)))
    return out


def _area(polygon: list) -> float:
    return 0.5 * abs(
        sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1], strict=True))
    )


@dataclass(frozen=True, slots=True)
class TooClose:
    """A convex part of the region closer than the separation, in the travel plane.

    Attributes
    ----------
    polygon : tuple of (float, float)
        Its corners, metres of travel of vehicle 1 and vehicle 2.
    segments : tuple of 2 int
        The cell it lies in.
    """

    polygon: tuple[tuple[float, float], ...]
    segments: tuple[int, int]


def too_close_polygons(
    track: TrackGraph, paths: tuple[GraphPath, GraphPath], separation: float
) -> list[TooClose]:
    """Every convex part of the region where the vehicles would be closer than ``separation``.

    Cost: one clip per way and cell, so it grows with the product of both paths' segment counts.
    """
    parts: list[TooClose] = []
    counts = [max(path.edges.size, 1) for path in paths]
    for k1, k2 in itertools.product(range(counts[0]), range(counts[1])):
        bounds = [
            (float(p.starts[k]), float(p.starts[k + 1])) if p.edges.size else (0.0, 0.0)
            for p, k in zip(paths, (k1, k2), strict=True)
        ]
        rectangle = [
            (bounds[0][0], bounds[1][0]),
            (bounds[0][1], bounds[1][0]),
            (bounds[0][1], bounds[1][1]),
            (bounds[0][0], bounds[1][1]),
        ]
        ways, along = cell_ways(track, paths, (k1, k2))
        polygons = [_clip(rectangle, a, b, separation - c) for a, b, c in ways]  # way < d
        if along is not None:  # |s1 - s2| < d: between two parallel lines
            a, b, c = along
            polygons.append(_clip(_clip(rectangle, a, b, separation - c), -a, -b, separation + c))
        for polygon in polygons:
            if len(polygon) >= 3 and _area(polygon) > 1e-12:
                parts.append(TooClose(tuple(polygon), (k1, k2)))
    return parts
