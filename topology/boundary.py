"""The oriented boundary cycle of the configuration space (docs/planner.md, 'The boundary 12-cycle').

Twelve vertices alternating peaks (both vehicles at leg ends) and valleys (one
at a leg end, the other at the junction); each edge moves one vehicle along
one whole leg. Built once per track, from the leg names and lengths.
"""

from __future__ import annotations

from topology.indexed import JUNCTION_INDEX, IndexedConfiguration, step
from topology.legs import LegTable
from topology.positions import Configuration, Position

__all__ = ["BoundaryCycle", "CycleLocation"]

#: Where a boundary point lies: edge index ``k`` (vertex ``k`` to ``k + 1``) and offset in metres.
CycleLocation = tuple[int, float]


class BoundaryCycle:
    """Per-track tables of the oriented 12-cycle.

    Parameters
    ----------
    names : tuple of 3 str
        Leg names in counterclockwise order.
    lengths : tuple of 3 float
        Leg lengths, metres.

    Attributes
    ----------
    endpoints : tuple of 3 Position
        The far end ``E_k`` of each leg.
    vertex_tuples : tuple of 12 IndexedConfiguration
        The vertices counterclockwise from ``P(first leg, second leg)``.
    vertices : tuple of 12 Configuration
        The same vertices as configurations.
    vertex_theta : tuple of 12 float
        Arc length of each vertex from the first, metres.
    perimeter : float
        ``4 (L_0 + L_1 + L_2)``, metres.
    """

    __slots__ = (
        "_peak",
        "_valley_first_at_junction",
        "_valley_second_at_junction",
        "endpoints",
        "legs",
        "lengths",
        "names",
        "perimeter",
        "vertex_configuration",
        "vertex_theta",
        "vertex_tuples",
        "vertices",
    )

    def __init__(self, names: tuple[str, ...], lengths: tuple[float, ...]) -> None:
        self.legs = LegTable(names, lengths)
        self.names = names
        self.lengths = lengths
        self.endpoints = self.legs.endpoints
        # Counterclockwise successors (docs/planner.md, 'The boundary 12-cycle'), starting at P(0, 1):
        # P(i, i+1) -> V2(i) -> P(i, i-1) -> V1(i-1) -> P(i+1, i-1).
        tuples: list[IndexedConfiguration] = []
        first, second = 0, 1
        for _ in range(6):
            tuples.append((first, lengths[first], second, lengths[second]))
            if second == (first + 1) % 3:  # P(i, i+1): vehicle 2 passes through O
                tuples.append((first, lengths[first], JUNCTION_INDEX, 0.0))
                second = (first - 1) % 3
            else:  # P(i, i-1): vehicle 1 passes through O
                tuples.append((JUNCTION_INDEX, 0.0, second, lengths[second]))
                first = (first + 1) % 3
        if (first, second) != (0, 1):
            raise AssertionError("the boundary cycle must close after 12 vertices")
        self.vertex_tuples = tuple(tuples)
        self.vertices = tuple(self.configuration(t) for t in tuples)
        #: Vertex tuple -> its Configuration, so route waypoints at vertices share one object.
        self.vertex_configuration = dict(zip(tuples, self.vertices, strict=True))
        theta = [0.0]
        for k in range(11):
            theta.append(theta[-1] + step(tuples[k], tuples[k + 1]))
        self.vertex_theta = tuple(theta)
        self.perimeter = theta[-1] + step(tuples[11], tuples[0])
        self._peak: dict[tuple[int, int], int] = {}
        self._valley_first_at_junction: dict[int, int] = {}
        self._valley_second_at_junction: dict[int, int] = {}
        for k, (l1, _, l2, _) in enumerate(tuples):
            if l1 == JUNCTION_INDEX:
                self._valley_first_at_junction[l2] = k
            elif l2 == JUNCTION_INDEX:
                self._valley_second_at_junction[l1] = k
            else:
                self._peak[(l1, l2)] = k

    # -- conversions -----------------------------------------------------
    def position(self, leg: int, s: float) -> Position:
        """The position at leg index ``leg``, ``s`` metres from the junction (no checks)."""
        return self.legs.position(leg, s)

    def configuration(self, c: IndexedConfiguration) -> Configuration:
        """The configuration of an indexed configuration (no checks)."""
        return self.legs.configuration(c)

    # -- location on the cycle --------------------------------------------
    def locate(self, c: IndexedConfiguration) -> CycleLocation:
        """Edge index ``k`` and offset ``u`` (metres, ``0 <= u`` < edge length) of a boundary point.

        The point lies on the edge from vertex ``k`` to vertex ``k + 1``, ``u``
        metres after vertex ``k``; ``u == 0`` exactly at a vertex.
        """
        l1, s1, l2, s2 = c
        lengths = self.lengths
        if l1 != JUNCTION_INDEX and s1 == lengths[l1]:  # vehicle 1 at E_l1
            if l2 == JUNCTION_INDEX:
                return self._valley_second_at_junction[l1], 0.0
            if s2 == lengths[l2]:
                return self._peak[(l1, l2)], 0.0
            if l2 == (l1 + 1) % 3:  # edge P(i, i+1) -> V2(i): vehicle 2 heads for O
                return self._peak[(l1, l2)], lengths[l2] - s2
            return self._valley_second_at_junction[l1], s2  # edge V2(i) -> P(i, i-1)
        if l1 == JUNCTION_INDEX:  # vehicle 2 at E_l2 from here on
            return self._valley_first_at_junction[l2], 0.0
        if l1 == (l2 + 1) % 3:  # edge P(j+1, j) -> V1(j): vehicle 1 heads for O
            return self._peak[(l1, l2)], lengths[l1] - s1
        return self._valley_first_at_junction[l2], s1  # edge V1(j) -> P(j-1, j)

    def theta(self, location: CycleLocation) -> float:
        """Arc length from P(0, 1) of a located boundary point, metres in [0, perimeter)."""
        value = self.vertex_theta[location[0]] + location[1]
        return value if value < self.perimeter else value - self.perimeter

    def counterclockwise_distance(self, origin: CycleLocation, target: CycleLocation) -> float:
        """Arc length going counterclockwise from ``origin`` to ``target``, metres in [0, perimeter).

        A sum of non-negative terms taken from the edge locations, so it is
        consistent with :meth:`arc` even for points a hair apart across a vertex.
        """
        (k0, u0), (k1, u1) = origin, target
        if k0 == k1:
            return u1 - u0 if u1 >= u0 else self.perimeter - (u0 - u1)
        cumulative = self.vertex_theta
        after = cumulative[k0 + 1] if k0 < 11 else self.perimeter
        between = cumulative[k1] - after if k1 > k0 else (self.perimeter - after) + cumulative[k1]
        return (after - cumulative[k0] - u0) + between + u1

    def arc(
        self, origin: CycleLocation, target: CycleLocation, counterclockwise: bool
    ) -> list[IndexedConfiguration]:
        """Cycle vertices passed going from ``origin`` to ``target`` (both from :meth:`locate`).

        Chosen combinatorially from the edges, not from rounded angles, so a
        point a hair off a vertex still passes that vertex in the right order.
        """
        (k0, u0), (k1, u1) = origin, target
        if counterclockwise:  # vertices k0+1, ..., k1
            count = (k1 - k0) % 12 or (12 if u1 < u0 else 0)
            indices = [(k0 + n) % 12 for n in range(1, count + 1)]
        else:  # vertices k0, k0-1, ..., k1+1
            count = (k0 - k1) % 12 or (12 if u1 > u0 else 0)
            indices = [(k0 - n) % 12 for n in range(count)]
        return [self.vertex_tuples[i] for i in indices]
