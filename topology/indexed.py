"""The indexed form of configurations and regions, and helpers over it.

The planner's hot path, the schedules and the verifier work on plain numbers
rather than named positions: a configuration is the tuple ``(leg1, s1, leg2,
s2)`` of leg indices (0, 1, 2 in the track's counterclockwise order, or
:data:`JUNCTION_INDEX` at the junction) and distances from the junction in
metres; a region is a :class:`RegionKey`. The definitions are those of
docs/planner.md.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import NamedTuple

import numpy as np

__all__ = [
    "JUNCTION_INDEX",
    "IndexedConfiguration",
    "RegionKey",
    "leg_travel",
    "reduce_regions",
    "reduce_regions_indexed",
    "region_key",
    "region_keys",
    "segment_region_key",
    "separation",
    "step",
    "track_distance",
]

#: Leg index of a vehicle at the junction.
JUNCTION_INDEX = -1

#: ``(leg1, s1, leg2, s2)``: leg indices (:data:`JUNCTION_INDEX` at the junction) and metres.
IndexedConfiguration = tuple[int, float, int, float]


class RegionKey(NamedTuple):
    """A region of docs/planner.md, 'Homotopy classes' by leg indices.

    ``Q(i, j)`` is ``RegionKey(i, j, 0)``; ``T(k, r)`` (both on leg ``k``,
    vehicle ``r`` nearer the junction) is ``RegionKey(k, k, r)``.

    Attributes
    ----------
    first_leg, second_leg : int
        Leg index of vehicle 1 and vehicle 2.
    nearer : int
        0 on different legs; on a shared leg the vehicle (1 or 2) nearer the junction.
    """

    first_leg: int
    second_leg: int
    nearer: int


def step(a: IndexedConfiguration, b: IndexedConfiguration) -> float:
    """Travel ``|ds1| + |ds2|`` of a segment in which each vehicle stays on one leg, metres."""
    first = abs(a[1] - b[1]) if a[0] == b[0] else a[1] + b[1]
    return first + (abs(a[3] - b[3]) if a[2] == b[2] else a[3] + b[3])


def leg_travel(leg_a: int, s_a: float, leg_b: int, s_b: float) -> float:
    """Track distance between two positions of one vehicle, metres (``s == 0`` at the junction)."""
    return abs(s_a - s_b) if leg_a == leg_b else s_a + s_b


def separation(c: IndexedConfiguration) -> float:
    """Track distance between the two vehicles of an indexed configuration, metres."""
    if c[0] == c[2] and c[0] != JUNCTION_INDEX:
        return abs(c[1] - c[3])
    return c[1] + c[3]


def region_key(leg1: int, s1: float, leg2: int, s2: float) -> RegionKey | None:
    """Region of a configuration; ``None`` on a ray (a vehicle at the junction)."""
    if leg1 == JUNCTION_INDEX or leg2 == JUNCTION_INDEX:
        return None
    if leg1 != leg2:
        return RegionKey(leg1, leg2, 0)
    return RegionKey(leg1, leg2, 1 if s1 < s2 else 2)


def segment_region_key(a: IndexedConfiguration, b: IndexedConfiguration) -> RegionKey | None:
    """Region of the interior of a route segment from ``a`` to ``b`` (each vehicle on one leg)."""
    leg1 = a[0] if a[0] != JUNCTION_INDEX else b[0]
    leg2 = a[2] if a[2] != JUNCTION_INDEX else b[2]
    return region_key(leg1, a[1] + b[1], leg2, a[3] + b[3])


def reduce_regions_indexed(sequence: Iterable) -> tuple:
    """Reduce a region sequence to its homotopy class, with the index where each kept region was entered.

    Merges repeats and cancels immediate back-and-forth ``R1, R2, R1`` (two
    adjacent regions share exactly one ray, so that excursion is null-homotopic).

    Parameters
    ----------
    sequence : iterable of hashable
        Regions in visiting order; ``None`` entries (on a ray) are skipped.

    Returns
    -------
    tuple of (region, int)

    Examples
    --------
    >>> reduce_regions_indexed(["a", None, "a", "b", "a", "c"])
    (('a', 0), ('c', 5))
    """
    stack: list = []
    for index, region in enumerate(sequence):
        if region is None or (stack and stack[-1][0] == region):
            continue
        if len(stack) >= 2 and stack[-2][0] == region:
            stack.pop()
            continue
        stack.append((region, index))
    return tuple(stack)


def reduce_regions(sequence: Iterable) -> tuple:
    """Reduce a region sequence to its homotopy class representative (see :func:`reduce_regions_indexed`).

    Examples
    --------
    >>> reduce_regions(["a", "b", "b", "c"])
    ('a', 'b', 'c')
    """
    return tuple(region for region, _ in reduce_regions_indexed(sequence))


def track_distance(leg_a, s_a, leg_b, s_b) -> np.ndarray:
    """Track distance between positions a and b, metres (arrays broadcast).

    Same leg: ``|s_a - s_b|``; different legs or either at the junction: ``s_a + s_b``.

    Parameters
    ----------
    leg_a, leg_b : array_like of int
        Leg indices, :data:`JUNCTION_INDEX` at the junction.
    s_a, s_b : array_like of float
        Distances from the junction, metres.
    """
    leg_a, s_a, leg_b, s_b = (np.asarray(x) for x in (leg_a, s_a, leg_b, s_b))
    same = (leg_a == leg_b) & (leg_a != JUNCTION_INDEX)
    return np.where(same, np.abs(s_a - s_b), s_a + s_b)


def region_keys(leg1, s1, leg2, s2) -> list[RegionKey | None]:
    """Region of each sampled configuration; ``None`` on a ray (vectorized :func:`region_key`).

    Parameters
    ----------
    leg1, s1, leg2, s2 : array_like, shape (n,)
        Leg indices and distances (metres) of vehicle 1 and vehicle 2.

    Examples
    --------
    >>> region_keys([0, 0, -1], [1.0, 1.0, 0.0], [1, 0, 2], [2.0, 2.0, 3.0])
    [RegionKey(first_leg=0, second_leg=1, nearer=0), RegionKey(first_leg=0, second_leg=0, nearer=1), None]
    """
    leg1, s1, leg2, s2 = (np.atleast_1d(np.asarray(x)) for x in (leg1, s1, leg2, s2))
    ray = (leg1 == JUNCTION_INDEX) | (leg2 == JUNCTION_INDEX)
    nearer = np.where(leg1 != leg2, 0, np.where(s1 < s2, 1, 2))
    legs = int(max(leg1.max(initial=0), leg2.max(initial=0))) + 1
    codes = np.where(ray, -1, (leg1 * legs + leg2) * 3 + nearer)
    # one RegionKey object per distinct region, not per sample
    unique, inverse = np.unique(codes, return_inverse=True)
    keys = [
        None if code < 0 else RegionKey(int(code) // 3 // legs, int(code) // 3 % legs, int(code) % 3)
        for code in unique.tolist()
    ]
    return [keys[k] for k in inverse.ravel().tolist()]
