"""What a simulated vehicle knows of its path: its order's nodes and edges, merged with the updates.

It drives by arc length along them. An edge between two nodes with positions whose ``length`` is
the straight line between them (a junction's legs, a straight track edge) is that line; any other
edge is as long as its ``length`` says (a curved edge, or a node the order gives no position: the
vehicle is line-guided there, as VDA 5050's ``distanceSinceLastNode`` assumes). The path turns back
where two edges meet head-on (by positions), or, without positions, where the edges' ``orientation``
changes (the order drives the edges after a reversal backward: ``orientation`` pi).
"""

from __future__ import annotations

import bisect
import math

__all__ = ["NODE_TOLERANCE", "DrivenPath"]

#: A node is reached within this of its position along the path, metres.
NODE_TOLERANCE = 1e-6
#: Cosine below which the directions of two edges meeting at a node are opposite: a reversal.
_REVERSAL_COSINE = -0.999
#: An edge whose ``length`` exceeds the straight line between its nodes by more than this is curved, metres.
_CURVE = 1e-6


class DrivenPath:
    """The nodes and edges of the current order (merged with its updates), with arc lengths.

    Parameters
    ----------
    nodes, edges : list
        The order's ``vda5050.model.order`` nodes and edges.
    """

    def __init__(self, nodes: list, edges: list) -> None:
        self.nodes: list = []
        self.edges: list = []
        self.arcs = [0.0]
        self.extend(0, nodes, edges, first=True)

    def extend(self, stitch: int, nodes: list, edges: list, *, first: bool = False) -> None:
        """Replace everything after node ``stitch`` by ``nodes[1:]`` and ``edges`` (``first``: all)."""
        self.nodes = list(nodes) if first else self.nodes[: stitch + 1] + list(nodes[1:])
        self.edges = list(edges) if first else self.edges[:stitch] + list(edges)
        self.arcs = self.arcs[: stitch + 1]
        for k in range(stitch, len(self.nodes) - 1):
            chord = self._chord(k)
            self.arcs.append(self.arcs[-1] + (chord if chord is not None else float(self.edges[k].length)))

    def _chord(self, k: int) -> float | None:
        """Edge ``k``'s straight length, if it is straight between two positions, else ``None``."""
        a, b = self.nodes[k].node_position, self.nodes[k + 1].node_position
        if a is None or b is None:
            return None
        chord = math.hypot(b.x - a.x, b.y - a.y)
        length = self.edges[k].length if k < len(self.edges) else None
        if length is not None and length > chord + _CURVE:
            return None
        return chord

    @property
    def base_end(self) -> int:
        """Index of the decision point (the last released node)."""
        return max(k for k, node in enumerate(self.nodes) if node.released)

    def reversal(self, k: int) -> bool:
        """Whether the path turns back at node ``k``."""
        if not 0 < k < len(self.nodes) - 1:
            return False
        incoming = self._direction(k - 1, k)
        outgoing = self._direction(k, k + 1)
        if incoming is None or outgoing is None:
            before, after = self.edges[k - 1].orientation, self.edges[k].orientation
            return before is not None and after is not None and abs(before - after) > 1.0
        return incoming[0] * outgoing[0] + incoming[1] * outgoing[1] < _REVERSAL_COSINE

    def _direction(self, a: int, b: int) -> tuple[float, float] | None:
        # an edge of zero length (at the junction) has the direction of its neighbours
        while a >= 0 and b < len(self.nodes):
            if any(self._chord(k) is None for k in range(a, b)):
                return None  # a curve, or a node without a position: no direction to give
            pa, pb = self.nodes[a].node_position, self.nodes[b].node_position
            length = math.hypot(pb.x - pa.x, pb.y - pa.y)
            if length > NODE_TOLERANCE:
                return ((pb.x - pa.x) / length, (pb.y - pa.y) / length)
            a, b = (a - 1, b) if a > 0 else (a, b + 1)
        return None

    def segment(self, p: float) -> int:
        """Index of the edge holding arc length ``p`` (the last one past the end)."""
        return min(max(bisect.bisect_right(self.arcs, p) - 1, 0), max(len(self.arcs) - 2, 0))

    def point(self, p: float) -> tuple[float, float, float] | None:
        """``(x, y, theta)`` at arc length ``p``; ``None`` where the order gives no straight line."""
        if len(self.nodes) == 1:
            position = self.nodes[0].node_position
            return None if position is None else (position.x, position.y, 0.0)
        k = self.segment(p)
        if self._chord(k) is None:
            return None
        a, b = self.nodes[k].node_position, self.nodes[k + 1].node_position
        length = self.arcs[k + 1] - self.arcs[k]
        f = 0.0 if length <= 0.0 else min(max((p - self.arcs[k]) / length, 0.0), 1.0)
        direction = self._direction(k, k + 1)
        theta = math.atan2(direction[1], direction[0]) if direction is not None else 0.0
        return a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), theta

    def place(self, p: float, last: int) -> tuple[str, str, float]:
        """``(last node id, next node id, metres past the last)`` at arc length ``p``, past node ``last``."""
        following = self.nodes[last + 1].node_id if last + 1 < len(self.nodes) else ""
        return self.nodes[last].node_id, following, max(0.0, p - self.arcs[last])
