"""Phases of the optimal-control problem and the stage layout of its transcription.

Phase ``p`` keeps the vehicles in region ``R_p`` of the route's homotopy class
(docs/planner.md, 'Homotopy classes'), taken from the route's own segment regions. Each
phase has ``segments`` segments of free duration, each of ``nodes`` control
intervals at fixed fractions of it (:func:`grid_fractions`). The stage
sequence (:func:`stages`) is the one definition of the variable layout that
the transcription, the initial guess and the decoding all walk.

For the braking rule (:mod:`~.braking`) each phase also fixes which way each
vehicle may move in it (:class:`Motion`, from the route's structure), and its
segments form two **parts** of equal count: a vehicle whose motion is
:attr:`Motion.REVERSING` moves outward in the first part and inward in the
second, so that its one reversal is the boundary between the parts.
"""

from __future__ import annotations

import enum
from collections.abc import Iterator
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from topology import JUNCTION_INDEX, Route

__all__ = [
    "DEPTH",
    "DURATION",
    "NO_SWITCH",
    "STATE_SIZE",
    "Motion",
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
#: Node state: s1, v1, a1, s2, v2, a2, T (the current segment's duration) and c (where the phase's
#: reversing vehicle turns, metres from the junction), the last two carried as states.
STATE_SIZE = 8
#: Index of T in the node state.
DURATION = 6
#: Index of c in the node state.
DEPTH = 7
#: A vehicle that starts at rest within this share of the separation beyond it may first have to back
#: off from the junction before the other passes it: its first phase is :attr:`Motion.REVERSING`.
_BACK_OFF = 1.05
#: Weight of cosine (end-dense) spacing in the grid, 0 for uniform.
_END_DENSITY = 0.35


class Motion(enum.IntEnum):
    """Which way a vehicle moves along its leg in a phase (``s`` grows outward): its braking-rule role."""

    FREE = 0  #: either way: the braking rule is stated for both
    OUTWARD = 1  #: ``v >= 0`` all phase
    INWARD = 2  #: ``v <= 0`` all phase
    REVERSING = 3  #: ``v >= 0`` in the first part, ``v <= 0`` in the second: it turns at most once


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
    motion : tuple of 2 Motion
        Which way each vehicle may move in the phase (:func:`phase_motions`).
    """

    legs: tuple[int, int]
    nearer: int
    switching: int
    entry_waypoint: int
    motion: tuple[Motion, Motion] = (Motion.FREE, Motion.FREE)

    def parked(self, vehicle: int) -> bool:
        """Whether ``vehicle`` stays at the junction for the whole phase."""
        return self.legs[vehicle] == JUNCTION_INDEX


def route_phases(route: Route) -> tuple[Phase, ...]:
    """The phases of a route that moves: one per region of its homotopy class.

    A route whose every segment lies on one ray (a vehicle parked at the
    junction while the other moves on one leg) has one phase.
    """
    entries = route.region_entries
    start, goal = route.indexed_waypoints[0], route.indexed_waypoints[-1]
    if not entries:
        parked = 0 if start[0] == JUNCTION_INDEX else 1
        mover = 1 - parked
        moving_leg = start[2 * mover]
        legs = (JUNCTION_INDEX, moving_leg) if parked == 0 else (moving_leg, JUNCTION_INDEX)
        motion = [Motion.FREE, Motion.FREE]
        motion[mover] = Motion.OUTWARD if goal[2 * mover + 1] >= start[2 * mover + 1] else Motion.INWARD
        return (Phase(legs, 0, NO_SWITCH, 0, (motion[0], motion[1])),)
    phases = []
    for p, (key, segment) in enumerate(entries):
        following = entries[p + 1][0] if p + 1 < len(entries) else None
        # the vehicle whose leg differs in the next region changes leg at the end of this phase
        switching = NO_SWITCH if following is None else (0 if following.first_leg != key.first_leg else 1)
        phases.append(Phase((key.first_leg, key.second_leg), key.nearer, switching, 0 if p == 0 else segment))
    return phase_motions(tuple(phases), start, goal, route.min_separation)


def phase_motions(
    phases: tuple[Phase, ...], start: tuple, goal: tuple, separation: float
) -> tuple[Phase, ...]:
    """``phases`` with the way each vehicle may move in each, for the braking rule (:mod:`~.braking`).

    In a phase on two legs at whose end a vehicle ``w`` passes the junction, ``w`` moves
    inward; the other, ``o``:

    * if it has just passed the junction itself (or starts at it), moves outward: it leads, and
      ``w`` follows it. If it comes back at the end of the next phase (it makes room for ``w`` on
      its leg), it is :attr:`Motion.REVERSING`: it turns back in this phase, before ``w`` passes.
    * otherwise (the route's first phase) it makes for the junction (if it passes it later) or
      for its goal: outward if that lies outward, else inward; :attr:`Motion.REVERSING` if it
      starts within about the separation of the junction and so may have to back off first.

    Shared legs, the last phase and later phases that a vehicle starts on its leg are
    :attr:`Motion.FREE`.

    Parameters
    ----------
    phases : tuple of Phase
    start, goal : tuple
        The route's first and last indexed waypoints ``(leg1, s1, leg2, s2)``.
    separation : float
        The route's minimum separation, metres.
    """
    out = []
    for p, phase in enumerate(phases):
        motion = [Motion.FREE, Motion.FREE]
        w = phase.switching
        if phase.nearer == 0 and w != NO_SWITCH and not (phase.parked(0) or phase.parked(1)):
            o = 1 - w
            motion[w] = Motion.INWARD
            returns_next = p + 1 < len(phases) and phases[p + 1].switching == o
            passes_later = any(q.switching == o for q in phases[p + 1 :])
            entered = (p > 0 and phases[p - 1].switching == o) or (p == 0 and start[2 * o] == JUNCTION_INDEX)
            if entered:
                motion[o] = Motion.REVERSING if returns_next else Motion.OUTWARD
            elif p == 0:
                here = start[2 * o + 1]
                target = 0.0 if passes_later else (goal[2 * o + 1] if goal[2 * o] == phase.legs[o] else 0.0)
                if target > here:
                    motion[o] = Motion.OUTWARD
                elif here < _BACK_OFF * separation:
                    motion[o] = Motion.REVERSING
                else:
                    motion[o] = Motion.INWARD
        out.append(
            Phase(phase.legs, phase.nearer, phase.switching, phase.entry_waypoint, (motion[0], motion[1]))
        )
    return tuple(out)


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
    motion : tuple of 2 Motion
        Which way each vehicle may move in the phase.
    joins : bool
        The vehicle that changes leg at the phase end enters the other's leg (the next phase
        is on a shared leg).
    """

    parked: tuple[bool, bool]
    nearer: int
    switching: int
    motion: tuple[Motion, Motion] = (Motion.FREE, Motion.FREE)
    joins: bool = False

    @property
    def reversing(self) -> int:
        """The vehicle (0 or 1) that turns back between the phase's two parts, or -1."""
        return next((v for v in (0, 1) if self.motion[v] is Motion.REVERSING), -1)


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
        Segments of free duration per phase (with ``braking``, an even number: half of them form
        each of the phase's two parts).
    max_iterations : int
        Iteration limit of Ipopt.
    fatrop_iterations : int
        Iteration limit of fatrop.
    slot : int
        Which compiled copy: concurrent solves of one shape (two classes) use two copies.
    braking : bool
        Whether the NLP carries the braking rule (:mod:`~.braking`); off only to show what it costs.
    """

    kinds: tuple[PhaseKind, ...]
    nodes: int
    segments: int
    max_iterations: int
    fatrop_iterations: int
    slot: int = 0
    braking: bool = True

    @classmethod
    def of(
        cls,
        phases: tuple[Phase, ...],
        *,
        nodes: int,
        segments: int,
        max_iterations: int,
        fatrop_iterations: int,
        braking: bool = True,
    ) -> NlpShape:
        """The shape of the problem for ``phases`` with these options.

        With ``braking``, each phase has two parts of ``segments`` segments of ``ceil(nodes / 2)``
        intervals (about as many intervals as without it): the layout :mod:`~.braking` needs.
        """
        kinds = tuple(
            PhaseKind(
                (p.parked(0), p.parked(1)),
                p.nearer,
                p.switching,
                p.motion if braking else (Motion.FREE, Motion.FREE),
                braking and k + 1 < len(phases) and phases[k + 1].nearer != 0,
            )
            for k, p in enumerate(phases)
        )
        if braking:
            nodes, segments = max(1, (nodes + 1) // 2), 2 * segments
        return cls(kinds, nodes, segments, max_iterations, fatrop_iterations, braking=braking)

    @property
    def phase_count(self) -> int:
        """Number of phases."""
        return len(self.kinds)

    @property
    def intervals(self) -> int:
        """Control intervals per phase."""
        return self.nodes * self.segments

    @property
    def part_intervals(self) -> int:
        """Control intervals in the first part of a phase (all of them without ``braking``)."""
        return self.intervals // 2 if self.braking else self.intervals

    def reset_depth(self, phase: int) -> bool:
        """Whether ``phase`` has a reversing vehicle, whose turning point ``c`` is a new state value."""
        return self.braking and self.kinds[phase].reversing >= 0


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
    part : int
        0 in the first part of the phase, 1 in the second (:attr:`NlpShape.part_intervals`).
    part_end : bool
        The last interval of a phase's first part (with ``braking``): a reversing vehicle turns after it.
    new_depth : bool
        The next phase has a reversing vehicle: its control carries that phase's turning point ``c``.
    """

    phase: int
    interval: int
    first: bool
    last: bool
    new_segment: bool
    phase_end: bool
    part: int = 0
    part_end: bool = False
    new_depth: bool = False

    @property
    def control_size(self) -> int:
        """Controls: two jerks, the next segment's duration at a segment boundary, the next ``c``."""
        return 2 + int(self.new_segment) + int(self.new_depth)


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
    count, intervals, half = shape.phase_count, shape.intervals, shape.part_intervals
    for p in range(count):
        for k in range(intervals):
            last = p == count - 1 and k == intervals - 1
            phase_end = k == intervals - 1 and p < count - 1
            yield Stage(
                phase=p,
                interval=k,
                first=p == 0 and k == 0,
                last=last,
                new_segment=(k + 1) % shape.nodes == 0 and not last,
                phase_end=phase_end,
                part=int(k >= half),
                part_end=shape.braking and k == half - 1,
                new_depth=phase_end and shape.reset_depth(p + 1),
            )
