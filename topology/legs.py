"""Conversions between the planner's indexed form and named positions, per track."""

from __future__ import annotations

from topology.indexed import JUNCTION_INDEX, IndexedConfiguration
from topology.positions import JUNCTION, Configuration, Position

__all__ = ["LegTable"]


class LegTable:
    """Leg names, lengths and endpoints of one track, with unchecked conversions (hot paths).

    Parameters
    ----------
    names : tuple of str, shape (k,)
        Leg names in counterclockwise order.
    lengths : tuple of float, shape (k,)
        Leg lengths, metres.

    Attributes
    ----------
    endpoints : tuple of Position, shape (k,)
        The far end ``E_i`` of each leg.
    """

    __slots__ = ("endpoints", "lengths", "names")

    def __init__(self, names: tuple[str, ...], lengths: tuple[float, ...]) -> None:
        self.names = names
        self.lengths = lengths
        self.endpoints = tuple(Position(name, length) for name, length in zip(names, lengths, strict=True))

    def position(self, leg: int, s: float) -> Position:
        """The position at leg index ``leg``, ``s`` metres from the junction (no checks)."""
        if leg == JUNCTION_INDEX:
            return JUNCTION
        if s == self.lengths[leg]:
            return self.endpoints[leg]
        return Position.unchecked(self.names[leg], s)

    def configuration(self, c: IndexedConfiguration) -> Configuration:
        """The configuration of an indexed configuration (no checks)."""
        return Configuration.unchecked(self.position(c[0], c[1]), self.position(c[2], c[3]))
