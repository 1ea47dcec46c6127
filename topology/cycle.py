"""Cells of the configuration space, the retraction and the boundary cycle.

ALGORITHM.md sections 2 to 4. The public functions take and return
:class:`~topology.graph.Configuration`; the planner's hot path works on plain
tuples ``(leg1, s1, leg2, s2)`` with leg index ``-1`` at the junction.
"""

from __future__ import annotations

from topology.errors import PositionError, SeparationError
from topology.graph import (
    JUNCTION,
    Configuration,
    Position,
    YGraph,
    _configuration_unchecked,
    _position_unchecked,
)
from topology.options import Option

__all__ = [
    "ANTIPODAL_TOLERANCE",
    "Cell",
    "boundary_angle",
    "classify",
    "is_antipodal",
    "retract",
]

#: Relative tolerance (of the perimeter) of the antipodal test, ALGORITHM.md section 5.
ANTIPODAL_TOLERANCE = 1e-9

_AT_JUNCTION = -1


class Cell(Option):
    """Cell of the configuration space holding a configuration (paper section 5.2)."""

    TRIANGLE = "triangle"
    RAY = "ray"
    QUADRANGLE = "quadrangle"
    BOUNDARY = "boundary"  #: interior of a boundary edge ("intermediate" in the paper)
    PEAK = "peak"
    VALLEY = "valley"

    @property
    def on_boundary(self) -> bool:
        """Whether the cell is part of the boundary circle (edge, peak or valley)."""
        return self in (Cell.BOUNDARY, Cell.PEAK, Cell.VALLEY)


class _BoundaryCycle:
    """Per-track tables of the oriented 12-cycle (built once with the track)."""

    __slots__ = (
        "endpoints",
        "lengths",
        "names",
        "peak",
        "perimeter",
        "valley_first_at_junction",
        "valley_second_at_junction",
        "vertex_configuration",
        "vertex_theta",
        "vertex_tuples",
        "vertices",
    )

    def __init__(self, graph: YGraph) -> None:
        lengths = graph.lengths
        self.names = graph.names
        self.lengths = lengths
        self.endpoints = tuple(
            Position(name, length) for name, length in zip(graph.names, lengths, strict=True)
        )
        # Counterclockwise successors (ALGORITHM.md section 4), starting at P(0, 1):
        # P(i, i+1) -> V2(i) -> P(i, i-1) -> V1(i-1) -> P(i+1, i-1).
        tuples: list[tuple[int, float, int, float]] = []
        first, second = 0, 1
        for _ in range(6):
            tuples.append((first, lengths[first], second, lengths[second]))
            if second == (first + 1) % 3:  # P(i, i+1): vehicle 2 passes through O
                tuples.append((first, lengths[first], _AT_JUNCTION, 0.0))
                second = (first - 1) % 3
            else:  # P(i, i-1): vehicle 1 passes through O
                tuples.append((_AT_JUNCTION, 0.0, second, lengths[second]))
                first = (first + 1) % 3
        assert (first, second) == (0, 1), "the boundary cycle must close after 12 vertices"
        self.vertex_tuples = tuple(tuples)
        self.vertices = tuple(self.configuration(t) for t in tuples)
        self.vertex_configuration = dict(zip(tuples, self.vertices, strict=True))
        theta = [0.0]
        for k in range(11):
            theta.append(theta[-1] + _step(tuples[k], tuples[k + 1]))
        self.vertex_theta = tuple(theta)
        self.perimeter = theta[-1] + _step(tuples[11], tuples[0])
        self.peak: dict[tuple[int, int], int] = {}
        self.valley_first_at_junction: dict[int, int] = {}
        self.valley_second_at_junction: dict[int, int] = {}
        for k, (l1, _, l2, _) in enumerate(tuples):
            if l1 == _AT_JUNCTION:
                self.valley_first_at_junction[l2] = k
            elif l2 == _AT_JUNCTION:
                self.valley_second_at_junction[l1] = k
            else:
                self.peak[(l1, l2)] = k

    # -- conversions -----------------------------------------------------
    def position(self, leg: int, s: float) -> Position:
        if leg == _AT_JUNCTION:
            return JUNCTION
        if s == self.lengths[leg]:
            return self.endpoints[leg]
        return _position_unchecked(self.names[leg], s)

    def configuration(self, c: tuple[int, float, int, float]) -> Configuration:
        return _configuration_unchecked(self.position(c[0], c[1]), self.position(c[2], c[3]))

    # -- location on the cycle --------------------------------------------
    def locate(self, c: tuple[int, float, int, float]) -> tuple[int, float]:
        """Edge index ``k`` and offset ``u`` (metres, ``0 <= u`` < edge length) of a boundary point.

        The point lies on the edge from vertex ``k`` to vertex ``k + 1``, ``u``
        metres after vertex ``k``; ``u == 0`` exactly at a vertex.
        """
        l1, s1, l2, s2 = c
        lengths = self.lengths
        if l1 != _AT_JUNCTION and s1 == lengths[l1]:  # vehicle 1 at E_l1
            if l2 == _AT_JUNCTION:
                return self.valley_second_at_junction[l1], 0.0
            if s2 == lengths[l2]:
                return self.peak[(l1, l2)], 0.0
            if l2 == (l1 + 1) % 3:  # edge P(i, i+1) -> V2(i): vehicle 2 heads for O
                return self.peak[(l1, l2)], lengths[l2] - s2
            return self.valley_second_at_junction[l1], s2  # edge V2(i) -> P(i, i-1)
        if l1 == _AT_JUNCTION:  # vehicle 2 at E_l2 from here on
            return self.valley_first_at_junction[l2], 0.0
        if l1 == (l2 + 1) % 3:  # edge P(j+1, j) -> V1(j): vehicle 1 heads for O
            return self.peak[(l1, l2)], lengths[l1] - s1
        return self.valley_first_at_junction[l2], s1  # edge V1(j) -> P(j-1, j)

    def theta(self, location: tuple[int, float]) -> float:
        """Arc length from P(0, 1) of a located boundary point, metres in [0, perimeter)."""
        value = self.vertex_theta[location[0]] + location[1]
        return value if value < self.perimeter else value - self.perimeter

    def counterclockwise_distance(self, origin: tuple[int, float], target: tuple[int, float]) -> float:
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
        self, origin: tuple[int, float], target: tuple[int, float], counterclockwise: bool
    ) -> list[tuple[int, float, int, float]]:
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


def _step(a: tuple[int, float, int, float], b: tuple[int, float, int, float]) -> float:
    """Travel ``|ds1| + |ds2|`` of a segment in which each vehicle stays on one leg, metres."""
    first = abs(a[1] - b[1]) if a[0] == b[0] else a[1] + b[1]
    return first + (abs(a[3] - b[3]) if a[2] == b[2] else a[3] + b[3])


def _leg_travel(leg_a: int, s_a: float, leg_b: int, s_b: float) -> float:
    """Track distance between two positions of one vehicle (``s == 0`` at the junction)."""
    return abs(s_a - s_b) if leg_a == leg_b else s_a + s_b


def _separation(c: tuple[int, float, int, float]) -> float:
    if c[0] == c[2] and c[0] != _AT_JUNCTION:
        return abs(c[1] - c[3])
    return c[1] + c[3]


def _classify(c: tuple[int, float, int, float], lengths: tuple[float, ...]) -> Cell:
    l1, s1, l2, s2 = c
    if l1 == l2:  # same leg (both at the junction is never valid)
        return Cell.TRIANGLE
    if l1 == _AT_JUNCTION:
        return Cell.VALLEY if s2 == lengths[l2] else Cell.RAY
    if l2 == _AT_JUNCTION:
        return Cell.VALLEY if s1 == lengths[l1] else Cell.RAY
    end1 = s1 == lengths[l1]
    end2 = s2 == lengths[l2]
    if end1 and end2:
        return Cell.PEAK
    if end1 or end2:
        return Cell.BOUNDARY
    return Cell.QUADRANGLE


def _retract(
    c: tuple[int, float, int, float], lengths: tuple[float, ...]
) -> list[tuple[int, float, int, float]]:
    """Waypoints from ``c`` to its boundary image ``r(c)``, ``c`` first (ALGORITHM.md section 3)."""
    out = [c]
    l1, s1, l2, s2 = c
    if l1 == l2:  # triangle: the vehicle nearer O moves to O alone
        c = (_AT_JUNCTION, 0.0, l2, s2) if s1 < s2 else (l1, s1, _AT_JUNCTION, 0.0)
        out.append(c)
        l1, s1, l2, s2 = c
    if l1 == _AT_JUNCTION:  # ray: the other vehicle moves out to its endpoint
        if s2 < lengths[l2]:
            out.append((l1, s1, l2, lengths[l2]))
        return out
    if l2 == _AT_JUNCTION:
        if s1 < lengths[l1]:
            out.append((l1, lengths[l1], l2, s2))
        return out
    ratio1 = s1 / lengths[l1]
    ratio2 = s2 / lengths[l2]
    if ratio1 >= 1.0 or ratio2 >= 1.0:  # already on the boundary
        return out
    if ratio1 == ratio2:  # radial motion ends at a peak
        out.append((l1, lengths[l1], l2, lengths[l2]))
    elif ratio1 > ratio2:
        out.append((l1, lengths[l1], l2, min(s2 / ratio1, lengths[l2])))
    else:
        out.append((l1, min(s1 / ratio2, lengths[l1]), l2, lengths[l2]))
    return out


def _as_tuple(graph: YGraph, configuration: Configuration) -> tuple[int, float, int, float]:
    """Validate a configuration against the track and return its internal tuple."""
    if not isinstance(configuration, Configuration):
        raise TypeError(f"expected a Configuration, got {configuration!r} ({type(configuration).__name__})")
    first = graph.check(configuration.first)
    second = graph.check(configuration.second)
    l1 = _AT_JUNCTION if first.leg is None else graph._index[first.leg]
    l2 = _AT_JUNCTION if second.leg is None else graph._index[second.leg]
    c = (l1, first.s, l2, second.s)
    if _separation(c) == 0.0:
        raise SeparationError(
            f"configuration {configuration} puts both vehicles at the same point: "
            "expected a track distance > 0 m"
        )
    return c


def classify(graph: YGraph, configuration: Configuration) -> Cell:
    """The cell of the configuration space that holds ``configuration``.

    Raises
    ------
    PositionError
        If a position is not on the track.
    SeparationError
        If both vehicles are at the same point.
    """
    return _classify(_as_tuple(graph, configuration), graph.lengths)


def retract(graph: YGraph, configuration: Configuration) -> tuple[Configuration, ...]:
    """Waypoints of the retraction of ``configuration`` onto the boundary.

    Paper Instructions 3 and 4: first waypoint is ``configuration``, last is
    its boundary image ``r(configuration)``; one waypoint only when the
    configuration is already on the boundary.

    Returns
    -------
    tuple of Configuration
        Between 1 and 3 waypoints; every segment increases the separation.
    """
    cycle = graph._cycle
    return tuple(cycle.configuration(c) for c in _retract(_as_tuple(graph, configuration), graph.lengths))


def boundary_angle(graph: YGraph, configuration: Configuration) -> float:
    """Arc length ``theta`` of a boundary configuration, metres in ``[0, perimeter)``.

    Measured counterclockwise along the boundary cycle from ``P(first leg,
    second leg)``.

    Raises
    ------
    PositionError
        If ``configuration`` is not on the boundary (retract it first).
    """
    c = _as_tuple(graph, configuration)
    cell = _classify(c, graph.lengths)
    if not cell.on_boundary:
        raise PositionError(
            f"configuration {configuration} is in a {cell.value}, expected a boundary configuration "
            "(one vehicle at a leg's endpoint, the other on another leg or at the junction)"
        )
    cycle = graph._cycle
    return cycle.theta(cycle.locate(c))


def is_antipodal(graph: YGraph, first: Configuration, second: Configuration) -> bool:
    """Whether two boundary configurations are half a perimeter apart on the cycle.

    Uses the tolerance ``1e-9 * perimeter`` of ALGORITHM.md section 5.
    """
    perimeter = graph.perimeter
    delta = (boundary_angle(graph, second) - boundary_angle(graph, first)) % perimeter
    return abs(delta - perimeter / 2.0) <= ANTIPODAL_TOLERANCE * perimeter
