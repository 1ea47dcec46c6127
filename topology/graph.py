"""Tracks: k legs of given lengths meeting at one junction (a star); the Y is k = 3.

Conventions follow docs/planner.md, 'The track and positions' and docs/star.md: the
legs are listed in counterclockwise order around the junction ``O``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from topology.boundary import BoundaryCycle
from topology.errors import PositionError, TrackError
from topology.indexed import IndexedConfiguration
from topology.legs import LegTable
from topology.positions import JUNCTION, JUNCTION_NAME, Configuration, Position
from topology.retract_graph import RetractGraph
from topology.track_graph import EdgePoint, TrackGraph
from topology.validation import finite_real, short_repr

__all__ = ["MAX_LEGS", "MIN_LEGS", "StarGraph", "YGraph"]

#: Fewest legs of a track.
MIN_LEGS = 3
#: Most legs of a track.
MAX_LEGS = 8


def _leg_pairs(legs: object) -> list[tuple[object, object]]:
    if isinstance(legs, Mapping):
        return list(legs.items())
    if isinstance(legs, (str, bytes)) or not isinstance(legs, Iterable):
        raise TrackError(
            f"legs must map leg name -> length in metres, got {short_repr(legs)} ({type(legs).__name__})"
        )
    pairs = []
    for item in legs:
        if not isinstance(item, tuple) or len(item) != 2:
            raise TrackError(f"legs must be (name, length) pairs, got item {short_repr(item)}")
        pairs.append(item)
    return pairs


def _checked_legs(pairs: list[tuple[object, object]]) -> tuple[tuple[str, ...], tuple[float, ...]]:
    names: list[str] = []
    lengths: list[float] = []
    for name, length in pairs:
        if not isinstance(name, str) or not name.strip():
            raise TrackError(f"leg name must be a non-empty string, got {short_repr(name)}")
        if name != name.strip() or name == JUNCTION_NAME or ":" in name:
            raise TrackError(
                f"leg name {short_repr(name)} is not allowed: expected no surrounding spaces, "
                f"no ':' and not {JUNCTION_NAME!r} (the junction)"
            )
        if name in names:
            raise TrackError(f"leg names must be distinct, got {short_repr(name)} twice")
        value = finite_real(length, f"length of leg {short_repr(name)} (metres)", TrackError)
        if value <= 0.0:
            raise TrackError(f"length of leg {short_repr(name)} must be > 0 m, got {value!r}")
        names.append(name)
        lengths.append(value)
    return tuple(names), tuple(lengths)


def _checked_angles(names: tuple[str, ...], angles_deg: object) -> tuple[float, ...]:
    count = len(names)
    if angles_deg is None:
        return tuple(math.fmod(90.0 + 360.0 * j / count, 360.0) for j in range(count))
    if not isinstance(angles_deg, Mapping):
        raise TrackError(f"angles_deg must map leg name -> degrees, got {short_repr(angles_deg)}")
    if set(angles_deg) != set(names):
        raise TrackError(
            f"angles_deg must give exactly the legs {list(names)!r}, got {sorted(map(str, angles_deg))!r}"
        )
    angles = tuple(finite_real(angles_deg[n], f"angle of leg {n!r} (degrees)", TrackError) for n in names)
    turn = [(a - angles[0]) % 360.0 for a in angles]
    if not turn[1] > 0.0 or not all(a < b for a, b in zip(turn[1:], [*turn[2:], 360.0], strict=True)):
        raise TrackError(
            f"leg angles {dict(zip(names, angles, strict=True))!r} degrees are not distinct and "
            f"counterclockwise in the order of the legs {list(names)!r}"
        )
    return angles


@dataclass(frozen=True, slots=True, init=False)
class StarGraph:
    """A junction of k legs (3 <= k <= 8) of given lengths: a star-shaped track.

    Parameters
    ----------
    legs : Mapping[str, float] or iterable of (str, float)
        Leg name -> length in metres, in counterclockwise order around the
        junction as seen from above. 3 to 8 legs, distinct non-empty names
        (not ``"O"``, no ``":"``), finite positive lengths.
    angles_deg : Mapping[str, float], optional
        Planar direction of each leg in degrees, for drawing and x/y export.
        Default: spread evenly, ``90 + 360 j / k`` for the ``j``-th leg (90,
        210, 330 for three legs). The angles must be distinct and in
        counterclockwise order, like the legs.

    Attributes
    ----------
    names : tuple of str, shape (k,)
        Leg names in counterclockwise order.
    lengths : tuple of float, shape (k,)
        Leg lengths, metres.
    angles_deg : tuple of float, shape (k,)
        Leg directions, degrees.
    cycle : BoundaryCycle or None
        For three legs, the oriented boundary cycle of the configuration space
        (docs/planner.md, 'The boundary 12-cycle'); ``None`` for four or more.

    Notes
    -----
    With three legs the configuration space deforms onto a circle and
    :func:`~topology.plan` is the paper's planner (two instructions); with
    four or more it deforms onto the graph ``G_k`` (:attr:`retract_graph`)
    and the planner takes one of three instructions (docs/star.md).

    Examples
    --------
    >>> crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    >>> crossing.angles_deg
    (90.0, 180.0, 270.0, 0.0)
    >>> len(crossing.retract_graph.vertices), len(crossing.retract_graph.edges)
    (20, 24)
    """

    names: tuple[str, ...]
    lengths: tuple[float, ...]
    angles_deg: tuple[float, ...]
    cycle: BoundaryCycle | None = field(repr=False, compare=False, hash=False)
    _index: Mapping[str, int] = field(repr=False, compare=False, hash=False)
    _legs: LegTable = field(repr=False, compare=False, hash=False)
    _retract_graph: list = field(repr=False, compare=False, hash=False)
    _track_graph: list = field(repr=False, compare=False, hash=False)

    def __init__(self, legs, *, angles_deg: Mapping[str, float] | None = None) -> None:
        pairs = _leg_pairs(legs)
        if not MIN_LEGS <= len(pairs) <= MAX_LEGS:
            raise TrackError(
                f"a track has {MIN_LEGS} to {MAX_LEGS} legs, got {len(pairs)}: "
                f"{short_repr([p[0] for p in pairs], 200)}"
            )
        self._initialize(pairs, angles_deg)

    def _initialize(self, pairs: list[tuple[object, object]], angles_deg: object) -> None:
        names, lengths = _checked_legs(pairs)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "lengths", lengths)
        object.__setattr__(self, "angles_deg", _checked_angles(names, angles_deg))
        object.__setattr__(self, "_index", MappingProxyType({n: k for k, n in enumerate(names)}))
        object.__setattr__(self, "_legs", LegTable(names, lengths))
        object.__setattr__(self, "cycle", BoundaryCycle(names, lengths) if len(names) == 3 else None)
        object.__setattr__(self, "_retract_graph", [])  # filled on first use
        object.__setattr__(self, "_track_graph", [])  # filled on first use

    # -- lookups ---------------------------------------------------------
    @property
    def leg_count(self) -> int:
        """The number k of legs."""
        return len(self.names)

    @property
    def legs(self) -> Mapping[str, float]:
        """Leg name -> length in metres, counterclockwise order (read-only)."""
        return MappingProxyType(dict(zip(self.names, self.lengths, strict=True)))

    @property
    def shortest_leg(self) -> float:
        """Length of the shortest leg, metres."""
        return min(self.lengths)

    def index(self, leg: str) -> int:
        """Counterclockwise index ``0 .. k-1`` of a leg.

        Raises
        ------
        PositionError
            If there is no leg of that name.
        """
        try:
            return self._index[leg]
        except (KeyError, TypeError):
            raise PositionError(
                f"unknown leg {short_repr(leg)}: expected one of {short_repr(list(self.names), 200)}"
            ) from None

    def length(self, leg: str) -> float:
        """Length of a leg, metres."""
        return self.lengths[self.index(leg)]

    def endpoint(self, leg: str) -> Position:
        """The far endpoint ``E_leg`` of a leg."""
        return self._legs.endpoints[self.index(leg)]

    @property
    def junction(self) -> Position:
        """The junction ``O``."""
        return JUNCTION

    def check(self, position: Position) -> Position:
        """Return ``position`` if it lies on this track, else raise.

        Raises
        ------
        PositionError
            Unknown leg, or ``s`` larger than the leg's length.
        """
        if not isinstance(position, Position):
            raise PositionError(f"expected a Position, got {position!r} ({type(position).__name__})")
        if position.leg is None:
            return position
        length = self.lengths[self.index(position.leg)]
        if position.s > length:
            raise PositionError(
                f"position s={position.s!r} m is beyond the end of leg {position.leg!r}: "
                f"expected 0 <= s <= {length!r} m"
            )
        return position

    def distance(self, p: Position, q: Position) -> float:
        """Track distance between two positions, metres.

        Same leg: ``|s_p - s_q|``; different legs or either at the junction:
        ``s_p + s_q``.
        """
        self.check(p)
        self.check(q)
        if p.leg is not None and p.leg == q.leg:
            return abs(p.s - q.s)
        return p.s + q.s

    def separation(self, configuration: Configuration) -> float:
        """Track distance between the two vehicles of a configuration, metres."""
        return self.distance(configuration.first, configuration.second)

    def xy(self, position: Position) -> tuple[float, float]:
        """Planar coordinates ``(x, y)`` in metres, junction at the origin."""
        self.check(position)
        if position.leg is None:
            return (0.0, 0.0)
        angle = math.radians(self.angles_deg[self.index(position.leg)])
        return (position.s * math.cos(angle), position.s * math.sin(angle))

    @property
    def total_length(self) -> float:
        """Every leg's length added up, metres."""
        return float(sum(self.lengths))

    def track_graph(self) -> TrackGraph:
        """The junction as a track graph: the same track, the same points.

        The junction is the node ``O``; each leg an edge named as the leg, from ``O`` to its end node
        ``<leg>-end`` (``-end`` once more where a leg has that name), placed by the leg's angle (its
        direction the angle's cosine and sine). ``A:s`` names the same point on both (``O`` too). Its
        legs are numbered (``numbered_legs``): rows name them 1, 2, ... and the junction 0.

        Examples
        --------
        >>> track = StarGraph({"A": 10.0, "B": 8.0, "C": 6.0}).track_graph()
        >>> [(e.name, e.start, e.end, e.length) for e in track.edges]
        [('A', 'O', 'A-end', 10.0), ('B', 'O', 'B-end', 8.0), ('C', 'O', 'C-end', 6.0)]
        >>> track.name(track.point("B:3"))
        'B:3'
        """
        built = self._track_graph
        if not built:
            coordinates = {JUNCTION_NAME: (0.0, 0.0)}
            edges = {}
            taken = {JUNCTION_NAME, *self.names}
            for name, length, angle in zip(self.names, self.lengths, self.angles_deg, strict=True):
                end = f"{name}-end"
                while end in taken:  # a leg named like another's end node ('A' and 'A-end')
                    end += "-end"
                taken.add(end)
                radians = math.radians(angle)
                coordinates[end] = (length * math.cos(radians), length * math.sin(radians))
                edges[name] = (JUNCTION_NAME, end, length)
            # as the star's rows always placed a leg's points: s times its angle's cosine and sine
            radians = np.radians(np.array(self.angles_deg, dtype=float))
            directions = dict(
                zip(
                    self.names,
                    zip(np.cos(radians).tolist(), np.sin(radians).tolist(), strict=True),
                    strict=True,
                )
            )
            built.append(
                TrackGraph.from_edges(
                    edges, coordinates=coordinates, directions=directions, numbered_legs=True
                )
            )
        return built[0]

    def point(self, text: str | Position) -> Position:
        """The position written ``"LEG:s"`` or ``"O"``, checked on this track (as a track graph's ``point``).

        Raises
        ------
        PositionError
            Not of that form, an unknown leg, or ``s`` off the leg.

        Examples
        --------
        >>> StarGraph({"A": 10.0, "B": 8.0, "C": 6.0}).point("B:3")
        Position(leg='B', s=3.0)
        """
        if isinstance(text, Position):
            return self.check(text)
        if not isinstance(text, str):
            raise PositionError(f"position {short_repr(text)} is not 'LEG:s' or 'O'")
        return self.check(Position.parse(text))

    def edge_point(self, position: Position) -> EdgePoint:
        """``position`` as the point of :meth:`track_graph` (the junction: the start of the first edge).

        Examples
        --------
        >>> StarGraph({"A": 10.0, "B": 8.0, "C": 6.0}).edge_point(Position("B", 3.0))
        EdgePoint(edge=1, s=3.0)
        """
        self.check(position)
        if position.leg is None:
            return EdgePoint(0, 0.0)
        return EdgePoint(self.index(position.leg), position.s)

    def configuration(self, c: IndexedConfiguration) -> Configuration:
        """The configuration of an indexed configuration ``(leg1, s1, leg2, s2)``, unchecked (hot paths)."""
        return self._legs.configuration(c)

    # -- the graph the configuration space deforms onto -------------------
    @property
    def retract_graph(self) -> RetractGraph:
        """The retract graph ``G_k`` with its per-track tables, built on first use (docs/star.md)."""
        built = self._retract_graph
        if not built:
            built.append(RetractGraph(self.names, self.lengths))
        return built[0]

    @property
    def boundary_length(self) -> float:
        """Total length of ``G_k``, ``2 (k - 1) (L_0 + ... + L_{k-1})`` metres (the perimeter for k = 3)."""
        return 2.0 * (len(self.lengths) - 1) * math.fsum(self.lengths)

    def _boundary_cycle(self) -> BoundaryCycle:
        if self.cycle is None:
            raise TrackError(
                f"a track with {len(self.names)} legs has no boundary circle (only a Y has one): "
                "expected three legs; use retract_graph for four or more"
            )
        return self.cycle

    @property
    def perimeter(self) -> float:
        """Length of the boundary circle of a Y, ``4 (L_0 + L_1 + L_2)`` metres.

        Raises
        ------
        TrackError
            For four or more legs (no circle; see :attr:`boundary_length`).
        """
        return self._boundary_cycle().perimeter

    @property
    def boundary_vertices(self) -> tuple[Configuration, ...]:
        """The vertices of the boundary (12 for a Y, counterclockwise from ``P(first leg, second leg)``).

        For four or more legs, the ``k (k + 1)`` vertices of ``G_k``: peaks, then valleys.
        """
        if self.cycle is not None:
            return self.cycle.vertices
        return self.retract_graph.vertex_configurations

    @property
    def boundary_vertex_angles(self) -> tuple[float, ...]:
        """Arc length ``theta`` of each cycle vertex from ``P(A, B)``, metres, shape (12,); three legs."""
        return self._boundary_cycle().vertex_theta


@dataclass(frozen=True, slots=True, init=False)
class YGraph(StarGraph):
    """A Y-shaped track: three legs of given lengths meeting at one junction.

    Parameters
    ----------
    legs : Mapping[str, float] or iterable of (str, float)
        Leg name -> length in metres, in counterclockwise order around the
        junction as seen from above. Exactly three legs, distinct non-empty
        names (not ``"O"``, no ``":"``), finite positive lengths.
    angles_deg : Mapping[str, float], optional
        Planar direction of each leg in degrees, for drawing and x/y export.
        Default 90, 210, 330 in the order of ``legs``. The angles must be
        distinct and in counterclockwise order, like the legs.

    Notes
    -----
    A :class:`StarGraph` of three legs; :attr:`cycle` is the oriented boundary
    cycle of the configuration space (docs/planner.md, 'The boundary 12-cycle').
    """

    def __init__(self, legs, *, angles_deg: Mapping[str, float] | None = None) -> None:
        pairs = _leg_pairs(legs)
        if len(pairs) != 3:
            raise TrackError(f"a Y-track has exactly 3 legs, got {len(pairs)}: {[p[0] for p in pairs]!r}")
        self._initialize(pairs, angles_deg)
