"""The Y-shaped track, positions on it and configurations of two vehicles.

Conventions follow ``ALGORITHM.md`` sections 1 and 2: three legs listed in
counterclockwise order around the junction ``O``, a position is ``(leg, s)``
with ``s`` metres from ``O``, and the junction itself has ``leg is None``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from numbers import Real
from types import MappingProxyType

from topology.errors import PositionError, TrackError

__all__ = ["JUNCTION", "JUNCTION_NAME", "Configuration", "Position", "YGraph"]

#: The name of the junction in text positions (``"O"``); no leg may use it.
JUNCTION_NAME = "O"

_DEFAULT_ANGLES_DEG = (90.0, 210.0, 330.0)


def _finite_real(value: object, quantity: str, error: type[Exception]) -> float:
    """Return ``value`` as a float, or raise ``error`` naming ``quantity``."""
    if type(value) is float and math.isfinite(value):
        return value
    if isinstance(value, bool) or not isinstance(value, Real):
        raise error(f"{quantity} must be a real number, got {value!r} ({type(value).__name__})")
    number = float(value)
    if not math.isfinite(number):
        raise error(f"{quantity} must be finite, got {number!r}")
    return number


@dataclass(frozen=True, slots=True)
class Position:
    """A point on the track.

    Parameters
    ----------
    leg : str or None
        Name of the leg; ``None`` only at the junction.
    s : float
        Distance from the junction along the leg, metres, ``s >= 0``.
        ``s == 0`` is the junction, which belongs to every leg: the position
        is normalized to ``leg=None`` there.

    Notes
    -----
    Whether ``s`` fits the leg's length is checked by the track
    (:meth:`YGraph.check`), which knows the lengths.
    """

    leg: str | None
    s: float

    def __post_init__(self) -> None:
        s = _finite_real(self.s, "position s (metres from the junction)", PositionError)
        if s < 0.0:
            raise PositionError(f"position s must be >= 0 m (distance from the junction), got {s!r}")
        if s == 0.0:
            object.__setattr__(self, "leg", None)
            object.__setattr__(self, "s", 0.0)
            return
        if self.leg is None:
            raise PositionError(
                f"position with leg None must be the junction (s == 0), got s={s!r} m; name the leg"
            )
        if not isinstance(self.leg, str) or not self.leg:
            raise PositionError(f"position leg must be a non-empty string, got {self.leg!r}")
        object.__setattr__(self, "s", s)

    @classmethod
    def parse(cls, text: str) -> Position:
        """Read ``"LEG:metres"`` (e.g. ``"A:10.0"``) or ``"O"`` for the junction.

        Raises
        ------
        PositionError
            If the text is not of that form.
        """
        if not isinstance(text, str):
            raise PositionError(f"position must be a string like 'A:10.0' or 'O', got {text!r}")
        stripped = text.strip()
        if stripped == JUNCTION_NAME:
            return JUNCTION
        leg, colon, metres = stripped.partition(":")
        if not colon or not leg.strip() or not metres.strip():
            raise PositionError(
                f"position {text!r} is malformed: expected 'LEG:metres' (e.g. 'A:10.0') or 'O'"
            )
        try:
            s = float(metres)
        except ValueError:
            raise PositionError(
                f"position {text!r} has distance {metres.strip()!r}, expected a number of metres"
            ) from None
        return cls(leg.strip(), s)

    @property
    def at_junction(self) -> bool:
        """Whether this is the junction ``O``."""
        return self.leg is None

    def __str__(self) -> str:
        return JUNCTION_NAME if self.leg is None else f"{self.leg}:{self.s:g}"


#: The junction ``O``.
JUNCTION = Position(None, 0.0)


def _position_unchecked(leg: str | None, s: float) -> Position:
    """Build a Position from values already known to be valid (hot path)."""
    position = object.__new__(Position)
    object.__setattr__(position, "leg", leg)
    object.__setattr__(position, "s", s)
    return position


@dataclass(frozen=True, slots=True)
class Configuration:
    """The positions of the two vehicles: vehicle 1 (``first``) then vehicle 2.

    Parameters
    ----------
    first, second : Position
        Positions of vehicle 1 and vehicle 2.
    """

    first: Position
    second: Position

    def __post_init__(self) -> None:
        for name in ("first", "second"):
            value = getattr(self, name)
            if not isinstance(value, Position):
                raise PositionError(
                    f"configuration {name} must be a Position, got {value!r} ({type(value).__name__})"
                )

    def swapped(self) -> Configuration:
        """The same two positions with the vehicles exchanged."""
        return _configuration_unchecked(self.second, self.first)

    def __iter__(self):
        yield self.first
        yield self.second

    def __getitem__(self, vehicle: int) -> Position:
        """Position of vehicle 0 (``first``) or 1 (``second``)."""
        if vehicle in (0, -2):
            return self.first
        if vehicle in (1, -1):
            return self.second
        raise IndexError(f"a configuration has vehicles 0 and 1, got index {vehicle!r}")

    def __len__(self) -> int:
        return 2

    def __str__(self) -> str:
        return f"({self.first}, {self.second})"


def _configuration_unchecked(first: Position, second: Position) -> Configuration:
    configuration = object.__new__(Configuration)
    object.__setattr__(configuration, "first", first)
    object.__setattr__(configuration, "second", second)
    return configuration


def _leg_pairs(legs: object) -> list[tuple[object, object]]:
    if isinstance(legs, Mapping):
        return list(legs.items())
    if isinstance(legs, (str, bytes)) or not isinstance(legs, Iterable):
        raise TrackError(f"legs must map leg name -> length in metres, got {legs!r} ({type(legs).__name__})")
    pairs = []
    for item in legs:
        if not isinstance(item, tuple) or len(item) != 2:
            raise TrackError(f"legs must be (name, length) pairs, got item {item!r}")
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
    """

    names: tuple[str, str, str]
    lengths: tuple[float, float, float]
    angles_deg: tuple[float, float, float]
    _index: Mapping[str, int] = field(repr=False, compare=False, hash=False)
    _cycle: tuple = field(repr=False, compare=False, hash=False)

    def __init__(self, legs, *, angles_deg: Mapping[str, float] | None = None) -> None:
        pairs = _leg_pairs(legs)
        if len(pairs) != 3:
            raise TrackError(f"a Y-track has exactly 3 legs, got {len(pairs)}: {[p[0] for p in pairs]!r}")
        names: list[str] = []
        lengths: list[float] = []
        for name, length in pairs:
            if not isinstance(name, str) or not name.strip():
                raise TrackError(f"leg name must be a non-empty string, got {name!r}")
            if name != name.strip() or name == JUNCTION_NAME or ":" in name:
                raise TrackError(
                    f"leg name {name!r} is not allowed: expected no surrounding spaces, "
                    f"no ':' and not {JUNCTION_NAME!r} (the junction)"
                )
            if name in names:
                raise TrackError(f"leg names must be distinct, got {name!r} twice")
            value = _finite_real(length, f"length of leg {name!r} (metres)", TrackError)
            if value <= 0.0:
                raise TrackError(f"length of leg {name!r} must be > 0 m, got {value!r}")
            names.append(name)
            lengths.append(value)
        angles = self._check_angles(names, angles_deg)
        object.__setattr__(self, "names", tuple(names))
        object.__setattr__(self, "lengths", tuple(lengths))
        object.__setattr__(self, "angles_deg", angles)
        object.__setattr__(self, "_index", MappingProxyType({n: k for k, n in enumerate(names)}))
        # Imported here: the cycle module needs YGraph's module to be complete.
        from topology.cycle import _BoundaryCycle

        object.__setattr__(self, "_cycle", _BoundaryCycle(self))

    @staticmethod
    def _check_angles(names: list[str], angles_deg) -> tuple[float, float, float]:
        if angles_deg is None:
            return _DEFAULT_ANGLES_DEG
        if not isinstance(angles_deg, Mapping):
            raise TrackError(f"angles_deg must map leg name -> degrees, got {angles_deg!r}")
        if set(angles_deg) != set(names):
            raise TrackError(
                f"angles_deg must give exactly the legs {names!r}, got {sorted(map(str, angles_deg))!r}"
            )
        angles = tuple(
            _finite_real(angles_deg[n], f"angle of leg {n!r} (degrees)", TrackError) for n in names
        )
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
            raise PositionError(f"unknown leg {leg!r}: expected one of {list(self.names)!r}") from None

    def length(self, leg: str) -> float:
        """Length of a leg, metres."""
        return self.lengths[self.index(leg)]

    def endpoint(self, leg: str) -> Position:
        """The far endpoint ``E_leg`` of a leg."""
        return self._cycle.endpoints[self.index(leg)]

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
        return self._cycle.perimeter

    @property
    def boundary_vertices(self) -> tuple[Configuration, ...]:
        """The 12 cycle vertices, counterclockwise from ``P(first leg, second leg)``, shape (12,)."""
        return self._cycle.vertices

    @property
    def boundary_vertex_angles(self) -> tuple[float, ...]:
        """Arc length ``theta`` of each cycle vertex from ``P(A, B)``, metres, shape (12,)."""
        return self._cycle.vertex_theta
