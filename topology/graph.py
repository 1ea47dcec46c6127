"""The Y-shaped track: three legs of given lengths meeting at one junction.

Conventions follow ``ALGORITHM.md`` section 1: three legs listed in
counterclockwise order around the junction ``O``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from topology.boundary import BoundaryCycle
from topology.errors import PositionError, TrackError
from topology.positions import JUNCTION, JUNCTION_NAME, Configuration, Position
from topology.validation import finite_real, short_repr

__all__ = ["YGraph"]

_DEFAULT_ANGLES_DEG = (90.0, 210.0, 330.0)


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


@dataclass(frozen=True, slots=True, init=False)
class YGraph:
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

    Attributes
    ----------
    names : tuple of 3 str
        Leg names in counterclockwise order.
    lengths : tuple of 3 float
        Leg lengths, metres.
    angles_deg : tuple of 3 float
        Leg directions, degrees.
    cycle : BoundaryCycle
        The oriented boundary cycle of the configuration space (ALGORITHM.md section 4).
    """

    names: tuple[str, str, str]
    lengths: tuple[float, float, float]
    angles_deg: tuple[float, float, float]
    cycle: BoundaryCycle = field(repr=False, compare=False, hash=False)
    _index: Mapping[str, int] = field(repr=False, compare=False, hash=False)

    def __init__(self, legs, *, angles_deg: Mapping[str, float] | None = None) -> None:
        pairs = _leg_pairs(legs)
        if len(pairs) != 3:
            raise TrackError(f"a Y-track has exactly 3 legs, got {len(pairs)}: {[p[0] for p in pairs]!r}")
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
        angles = self._check_angles(names, angles_deg)
        object.__setattr__(self, "names", tuple(names))
        object.__setattr__(self, "lengths", tuple(lengths))
        object.__setattr__(self, "angles_deg", angles)
        object.__setattr__(self, "_index", MappingProxyType({n: k for k, n in enumerate(names)}))
        object.__setattr__(self, "cycle", BoundaryCycle(self.names, self.lengths))

    @staticmethod
    def _check_angles(names: list[str], angles_deg) -> tuple[float, float, float]:
        if angles_deg is None:
            return _DEFAULT_ANGLES_DEG
        if not isinstance(angles_deg, Mapping):
            raise TrackError(f"angles_deg must map leg name -> degrees, got {short_repr(angles_deg)}")
        if set(angles_deg) != set(names):
            raise TrackError(
                f"angles_deg must give exactly the legs {names!r}, got {sorted(map(str, angles_deg))!r}"
            )
        angles = tuple(finite_real(angles_deg[n], f"angle of leg {n!r} (degrees)", TrackError) for n in names)
        turn = [(a - angles[0]) % 360.0 for a in angles]
        if not 0.0 < turn[1] < turn[2] < 360.0:
            raise TrackError(
                f"leg angles {dict(zip(names, angles, strict=True))!r} degrees are not distinct and "
                f"counterclockwise in the order of the legs {names!r}"
            )
        return angles  # type: ignore[return-value]

    # -- lookups ---------------------------------------------------------
    @property
    def legs(self) -> Mapping[str, float]:
        """Leg name -> length in metres, counterclockwise order (read-only)."""
        return MappingProxyType(dict(zip(self.names, self.lengths, strict=True)))

    @property
    def shortest_leg(self) -> float:
        """Length of the shortest leg, metres."""
        return min(self.lengths)

    def index(self, leg: str) -> int:
        """Counterclockwise index 0, 1 or 2 of a leg.

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
        return self.cycle.endpoints[self.index(leg)]

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

    # -- boundary cycle (ALGORITHM.md section 4) --------------------------
    @property
    def perimeter(self) -> float:
        """Length of the boundary cycle, ``4 (L_0 + L_1 + L_2)`` metres."""
        return self.cycle.perimeter

    @property
    def boundary_vertices(self) -> tuple[Configuration, ...]:
        """The 12 cycle vertices, counterclockwise from ``P(first leg, second leg)``, shape (12,)."""
        return self.cycle.vertices

    @property
    def boundary_vertex_angles(self) -> tuple[float, ...]:
        """Arc length ``theta`` of each cycle vertex from ``P(A, B)``, metres, shape (12,)."""
        return self.cycle.vertex_theta
