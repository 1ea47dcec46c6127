"""Map x/y of track positions and back: where the live vehicles say they are (``agvPosition``).

Each leg is drawn as a straight line from the junction at (0, 0), at its angle
(:attr:`~topology.StarGraph.angles_deg`).
"""

from __future__ import annotations

import math

from topology import Position, StarGraph

__all__ = ["position_xy", "track_position"]


def position_xy(graph: StarGraph, position: Position) -> tuple[float, float]:
    """Map x/y of a track position, metres (leg drawn at its angle from the junction at 0, 0)."""
    if position.leg is None or position.s == 0.0:
        return (0.0, 0.0)
    angle = math.radians(graph.angles_deg[graph.index(position.leg)])
    return (position.s * math.cos(angle), position.s * math.sin(angle))


def track_position(graph: StarGraph, x: float, y: float) -> Position:
    """The track position at map x/y (the nearest leg by angle; at the junction within 1 µm)."""
    s = math.hypot(x, y)
    if s < 1e-6:
        return Position(None, 0.0)
    angle = math.degrees(math.atan2(y, x))
    leg = min(
        range(len(graph.names)), key=lambda k: abs((graph.angles_deg[k] - angle + 180.0) % 360.0 - 180.0)
    )
    return Position(graph.names[leg], min(s, graph.lengths[leg]))
