"""Phases of the optimal-control problem and the stage layout of its transcription.

Phase ``p`` keeps the vehicles in region ``R_p`` of the route's homotopy class
(ALGORITHM.md section 6), taken from the route's own segment regions. Each
phase has ``segments`` segments of free duration, each of ``nodes`` control
intervals at fixed fractions of it (:func:`grid_fractions`). The stage
sequence (:func:`stages`) is the one definition of the variable layout that
the transcription, the initial guess and the decoding all walk.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from topology import JUNCTION_INDEX, Route

__all__ = [
    "NO_SWITCH",
    "STATE_SIZE",
    "NlpShape",
    "Phase",
    "PhaseKind",
    "Stage",
    "default_fractions",
    "grid_fractions",
    "route_phases",
    "stages",
]

#: ``Phase.switching`` of the last phase: nobody changes leg after it.
NO_SWITCH = -1
#: Node state: s1, v1, a1, s2, v2, a2 and T (the current segment's duration, carried as a state).
STATE_SIZE = 7
#: Weight of cosine (end-dense) spacing in the grid, 0 for uniform.
_END_DENSITY = 0.35


@dataclass(frozen=True, slots=True)
class Phase:
    """One region of the homotopy class, as the optimal-control problem sees it.

    Attributes
    ----------
    legs : tuple of 2 int
        Leg index of each vehicle (``JUNCTION_INDEX``: parked at the junction all phase).
    nearer : int
        0 on different legs; on a shared leg the vehicle (1 or 2) nearer the junction.
    switching : int
        Vehicle (0 or 1) that changes leg at the end of the phase; ``NO_SWITCH`` for the last.
    entry_waypoint : int
        Route waypoint at which the phase's region is entered (0 for the first phase).
    """

    legs: tuple[int, int]
    nearer: int
    switching: int
    entry_waypoint: int

    def parked(self, vehicle: int) -> bool:
        """Whether ``vehicle`` stays at the junction for the whole phase."""
        return self.legs[vehicle] == JUNCTION_INDEX


def route_phases(route: Route) -> tuple[Phase, ...]:
    """The phases of a route that moves: one per region of its homotopy class.

    A route whose every segment lies on one ray (a vehicle parked at the
    junction while the other moves on one leg) has one phase.
    """
    entries = route.region_entries
    if not entries:
        start = route.indexed_waypoints[0]
        parked = 0 if start[0] == JUNCTION_INDEX else 1
        moving_leg = start[2 * (1 - parked)]
        legs = (JUNCTION_INDEX, moving_leg) if parked == 0 else (moving_leg, JUNCTION_INDEX)
        return (Phase(legs, 0, NO_SWITCH, 0),)
    phases = []
    for p, (key, segment) in enumerate(entries):
        following = entries[p + 1][0] if p + 1 < len(entries) else None
        # the vehicle whose leg differs in the next region changes leg at the end of this phase
        switching = NO_SWITCH if following is None else (0 if following.first_leg != key.first_leg else 1)
        phases.append(Phase((key.first_leg, key.second_leg), key.nearer, switching, 0 if p == 0 else segment))
    return tuple(phases)


class PhaseKind(NamedTuple):
    """What of a phase fixes the NLP's structure (leg lengths and positions are parameters).

    Attributes
    ----------
    parked : tuple of 2 bool
        Whether vehicle 1, vehicle 2 stays at the junction all phase.
    nearer : int
        0 on different legs; on a shared leg the vehicle (1 or 2) nearer the junction.
    switching : int
        Vehicle (0 or 1) that changes leg at the end of the phase; ``NO_SWITCH`` for the last.
    """

    parked: tuple[bool, bool]
    nearer: int
    switching: int


@dataclass(frozen=True, slots=True)
class NlpShape:
    """What fixes the structure of the NLP: built once per shape, reused with new parameters.

    Attributes
    ----------
    kinds : tuple of PhaseKind
        Per phase, what fixes its structure.
    nodes : int
        Control intervals per segment.
    segments : int
        Segments of free duration per phase.
    max_iterations : int
        Iteration limit of Ipopt.
    fatrop_iterations : int
        Iteration limit of fatrop.
    time_budget : float
        Wall time of the whole solve, seconds (each Ipopt attempt may take half of it).
    slot : int
        Which compiled copy: concurrent solves of one shape (two classes) use two copies.
    """

    kinds: tuple[PhaseKind, ...]
    nodes: int
    segments: int
    max_iterations: int
    fatrop_iterations: int
    time_budget: float = 2.0
    slot: int = 0

    @classmethod
    def of(
        cls,
        phases: tuple[Phase, ...],
        *,
        nodes: int,
        segments: int,
        max_iterations: int,
        fatrop_iterations: int,
        time_budget: float = 2.0,
    ) -> NlpShape:
        """The shape of the problem for ``phases`` with these options."""
        kinds = tuple(PhaseKind((p.parked(0), p.parked(1)), p.nearer, p.switching) for p in phases)
        return cls(kinds, nodes, segments, max_iterations, fatrop_iterations, time_budget)

    @property
    def phase_count(self) -> int:
        """Number of phases."""
        return len(self.kinds)

    @property
    def intervals(self) -> int:
        """Control intervals per phase."""
        return self.nodes * self.segments


@dataclass(frozen=True, slots=True)
class Stage:
    """One control interval of the transcription, in variable order.

    Attributes
    ----------
    phase, interval : int
        Phase index and interval index within the phase.
    first, last : bool
        The first interval of the problem (from rest at the start) or the last (to rest at the goal).
    new_segment : bool
        A new segment starts after this interval: its control carries the next duration.
    phase_end : bool
        The last interval of a phase that is not the last: a vehicle changes leg after it.
    """

    phase: int
    interval: int
    first: bool
    last: bool
    new_segment: bool
    phase_end: bool

    @property
    def control_size(self) -> int:
        """Controls of the stage: two jerks, plus the next segment's duration at a segment boundary."""
        return 3 if self.new_segment else 2


def grid_fractions(nodes: int) -> np.ndarray:
    """Interval lengths of a segment as fractions of its duration, shape (nodes,), summing to 1.

    A fixed blend of uniform and cosine spacing: denser at the ends, where the
    vehicles start, stop and pass the junction, so the short jerk ramps there
    are resolved without making the grid itself a variable.
    """
    i = np.arange(nodes + 1) / nodes
    grid = (1.0 - _END_DENSITY) * i + _END_DENSITY * 0.5 * (1.0 - np.cos(np.pi * i))
    return np.diff(grid)


def default_fractions(shape: NlpShape) -> np.ndarray:
    """The starting grid: :func:`grid_fractions` in every segment, shape (phase_count, intervals)."""
    return np.tile(grid_fractions(shape.nodes), (shape.phase_count, shape.segments))


def stages(shape: NlpShape) -> Iterator[Stage]:
    """The stages in variable order: ``x_0, u_0, x_1, u_1, ...`` phase by phase."""
    count, intervals = shape.phase_count, shape.intervals
    for p in range(count):
        for k in range(intervals):
            last = p == count - 1 and k == intervals - 1
            yield Stage(
                phase=p,
                interval=k,
                first=p == 0 and k == 0,
                last=last,
                new_segment=(k + 1) % shape.nodes == 0 and not last,
                phase_end=k == intervals - 1 and p < count - 1,
            )
