"""Cells of the configuration space and the retraction onto the boundary (docs/planner.md).

The public functions take and return :class:`~topology.positions.Configuration`;
the ``*_indexed`` variants work on the planner's indexed form
(:data:`~topology.indexed.IndexedConfiguration`).
"""

from __future__ import annotations

from topology.errors import PositionError, SeparationError, TrackError
from topology.graph import StarGraph
from topology.indexed import JUNCTION_INDEX, IndexedConfiguration, separation
from topology.options import Option
from topology.positions import Configuration

__all__ = [
    "ANTIPODAL_TOLERANCE",
    "Cell",
    "as_indexed",
    "boundary_angle",
    "classify",
    "classify_indexed",
    "is_antipodal",
    "retract",
    "retract_indexed",
]

#: Relative tolerance (of the perimeter) of the antipodal test, docs/planner.md, 'The two instructions'.
ANTIPODAL_TOLERANCE = 1e-9


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


def classify_indexed(c: IndexedConfiguration, lengths: tuple[float, ...]) -> Cell:
    """The cell holding an indexed configuration on legs of the given lengths (metres)."""
    l1, s1, l2, s2 = c
    if l1 == l2:  # same leg (both at the junction is never valid)
        return Cell.TRIANGLE
    if l1 == JUNCTION_INDEX:
        return Cell.VALLEY if s2 == lengths[l2] else Cell.RAY
    if l2 == JUNCTION_INDEX:
        return Cell.VALLEY if s1 == lengths[l1] else Cell.RAY
    end1 = s1 == lengths[l1]
    end2 = s2 == lengths[l2]
    if end1 and end2:
        return Cell.PEAK
    if end1 or end2:
        return Cell.BOUNDARY
    return Cell.QUADRANGLE


def retract_indexed(c: IndexedConfiguration, lengths: tuple[float, ...]) -> list[IndexedConfiguration]:
    """Waypoints from ``c`` to its boundary image ``r(c)``, ``c`` first (docs/planner.md, retraction)."""
    out = [c]
    l1, s1, l2, s2 = c
    if l1 == l2:  # triangle: the vehicle nearer O moves to O alone
        c = (JUNCTION_INDEX, 0.0, l2, s2) if s1 < s2 else (l1, s1, JUNCTION_INDEX, 0.0)
        out.append(c)
        l1, s1, l2, s2 = c
    if l1 == JUNCTION_INDEX:  # ray: the other vehicle moves out to its endpoint
        if s2 < lengths[l2]:
            out.append((l1, s1, l2, lengths[l2]))
        return out
    if l2 == JUNCTION_INDEX:
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


def as_indexed(graph: StarGraph, configuration: Configuration) -> IndexedConfiguration:
    """Validate a configuration against the track and return its indexed form.

    Raises
    ------
    PositionError
        A position is not on the track.
    SeparationError
        Both vehicles are at the same point.
    """
    if not isinstance(configuration, Configuration):
        raise TypeError(f"expected a Configuration, got {configuration!r} ({type(configuration).__name__})")
    first = graph.check(configuration.first)
    second = graph.check(configuration.second)
    l1 = JUNCTION_INDEX if first.leg is None else graph.index(first.leg)
    l2 = JUNCTION_INDEX if second.leg is None else graph.index(second.leg)
    c = (l1, first.s, l2, second.s)
    if separation(c) == 0.0:
        raise SeparationError(
            f"configuration {configuration} puts both vehicles at the same point: "
            "expected a track distance > 0 m"
        )
    return c


def classify(graph: StarGraph, configuration: Configuration) -> Cell:
    """The cell of the configuration space that holds ``configuration``.

    Raises
    ------
    PositionError
        If a position is not on the track.
    SeparationError
        If both vehicles are at the same point.
    """
    return classify_indexed(as_indexed(graph, configuration), graph.lengths)


def retract(graph: StarGraph, configuration: Configuration) -> tuple[Configuration, ...]:
    """Waypoints of the retraction of ``configuration`` onto the boundary.

    Paper Instructions 3 and 4: first waypoint is ``configuration``, last is
    its boundary image ``r(configuration)``; one waypoint only when the
    configuration is already on the boundary.

    Returns
    -------
    tuple of Configuration
        Between 1 and 3 waypoints; every segment increases the separation.
    """
    return tuple(
        graph.configuration(c) for c in retract_indexed(as_indexed(graph, configuration), graph.lengths)
    )


def boundary_angle(graph: StarGraph, configuration: Configuration) -> float:
    """Arc length ``theta`` of a boundary configuration, metres in ``[0, perimeter)``.

    Measured counterclockwise along the boundary cycle from ``P(first leg,
    second leg)``.

    Raises
    ------
    PositionError
        If ``configuration`` is not on the boundary (retract it first).
    TrackError
        For a track of four or more legs, which has no boundary circle.
    """
    cycle = graph.cycle
    if cycle is None:
        raise TrackError(
            f"a track with {graph.leg_count} legs has no boundary circle (only a Y has one): "
            "expected three legs; locate boundary points on retract_graph for four or more"
        )
    c = as_indexed(graph, configuration)
    cell = classify_indexed(c, graph.lengths)
    if not cell.on_boundary:
        raise PositionError(
            f"configuration {configuration} is in a {cell.value}, expected a boundary configuration "
            "(one vehicle at a leg's endpoint, the other on another leg or at the junction)"
        )
    return cycle.theta(cycle.locate(c))


def is_antipodal(graph: StarGraph, first: Configuration, second: Configuration) -> bool:
    """Whether two boundary configurations are half a perimeter apart on the cycle.

    Uses the tolerance ``1e-9 * perimeter`` of docs/planner.md, 'The two instructions'.
    """
    perimeter = graph.perimeter
    delta = (boundary_angle(graph, second) - boundary_angle(graph, first)) % perimeter
    return abs(delta - perimeter / 2.0) <= ANTIPODAL_TOLERANCE * perimeter
