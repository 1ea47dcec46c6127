"""Positions on the track and configurations of the two vehicles (docs/planner.md).

A position is ``(leg, s)`` with ``s`` metres from the junction ``O``; the
junction itself has ``leg is None``.
"""

from __future__ import annotations

from dataclasses import dataclass

from topology.errors import PositionError
from topology.validation import finite_real, short_repr

__all__ = ["JUNCTION", "JUNCTION_NAME", "Configuration", "Position"]

#: The name of the junction in text positions (``"O"``); no leg may use it.
JUNCTION_NAME = "O"


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
    (:meth:`topology.YGraph.check`), which knows the lengths.
    """

    leg: str | None
    s: float

    def __post_init__(self) -> None:
        s = finite_real(self.s, "position s (metres from the junction)", PositionError)
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
            raise PositionError(f"position leg must be a non-empty string, got {short_repr(self.leg)}")
        object.__setattr__(self, "s", s)

    @classmethod
    def unchecked(cls, leg: str | None, s: float) -> Position:
        """Build a position from values already known to be valid, without checks (hot paths)."""
        position = object.__new__(cls)
        object.__setattr__(position, "leg", leg)
        object.__setattr__(position, "s", s)
        return position

    @classmethod
    def parse(cls, text: str) -> Position:
        """Read ``"LEG:metres"`` (e.g. ``"A:10.0"``) or ``"O"`` for the junction.

        Raises
        ------
        PositionError
            If the text is not of that form.

        Examples
        --------
        >>> Position.parse("A:2.5")
        Position(leg='A', s=2.5)
        """
        if not isinstance(text, str):
            raise PositionError(f"position must be a string like 'A:10.0' or 'O', got {short_repr(text)}")
        stripped = text.strip()
        if stripped == JUNCTION_NAME:
            return JUNCTION
        leg, colon, metres = stripped.partition(":")
        if not colon or not leg.strip() or not metres.strip():
            raise PositionError(
                f"position {short_repr(text)} is malformed: expected 'LEG:metres' (e.g. 'A:10.0') or 'O'"
            )
        try:
            s = float(metres)
        except ValueError:
            raise PositionError(
                f"position {short_repr(text)} has distance {short_repr(metres.strip())}, "
                "expected a number of metres"
            ) from None
        return cls(leg.strip(), s)

    def __str__(self) -> str:
        return JUNCTION_NAME if self.leg is None else f"{self.leg}:{self.s:g}"


#: The junction ``O``.
JUNCTION = Position(None, 0.0)


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

    @classmethod
    def unchecked(cls, first: Position, second: Position) -> Configuration:
        """Build a configuration from positions already known to be valid, without checks."""
        configuration = object.__new__(cls)
        object.__setattr__(configuration, "first", first)
        object.__setattr__(configuration, "second", second)
        return configuration

    def swapped(self) -> Configuration:
        """The same two positions with the vehicles exchanged."""
        return Configuration.unchecked(self.second, self.first)

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
