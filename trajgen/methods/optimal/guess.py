"""The initial guess of the optimal-control NLP: the ``exact`` schedule in the stage layout."""

from __future__ import annotations

import numpy as np

from trajgen.errors import SolverError
from trajgen.methods.optimal.phases import DEPTH, DURATION, NlpShape, Phase, stages
from trajgen.model.schedule import Schedule

__all__ = ["assemble", "initial_guess", "phase_windows"]

#: Shortest phase window of the guess, seconds.
_MIN_PHASE = 1e-3


def phase_windows(
    phases: tuple[Phase, ...], waypoint_times: np.ndarray, duration: float
) -> list[tuple[float, float]]:
    """Time window of the exact schedule that each phase covers, seconds.

    A phase starts when the exact schedule passes the waypoint at which its
    region is entered and ends when the next phase starts.
    """
    edges = [float(waypoint_times[phase.entry_waypoint]) for phase in phases] + [duration]
    edges = np.maximum.accumulate(edges)
    return [(float(edges[p]), float(max(edges[p + 1], edges[p] + _MIN_PHASE))) for p in range(len(phases))]


def _split(exact: Schedule, phase: Phase, kind, window: tuple[float, float]) -> float:
    """When the guess's first part of a phase ends: where its reversing vehicle turns, else halfway.

    The reversing vehicle's turning point in the exact schedule is the last instant of the window
    at which it is farthest from the junction (sampled).
    """
    begin, end = window
    vehicle = kind.reversing
    if vehicle < 0:
        return 0.5 * (begin + end)
    times = np.linspace(begin, end, 401)
    state = exact.state(times)
    s = np.where(state.leg[vehicle] == phase.legs[vehicle], state.s[vehicle], 0.0)
    turn = float(times[len(s) - 1 - int(np.argmax(s[::-1]))])
    least = _MIN_PHASE / 2.0
    return min(max(turn, begin + least), end - least)


def _phase_states(
    exact: Schedule,
    phase: Phase,
    window: tuple[float, float],
    shape: NlpShape,
    fractions: np.ndarray,
    kind,
    depth: float,
) -> tuple[np.ndarray, float]:
    """Node states of one phase sampled from the exact schedule, shape (intervals + 1, 8), leg coordinates.

    ``fractions`` (intervals,) is the phase's grid. With two parts (``shape.braking``) the first
    ends where the phase's reversing vehicle turns (:func:`_split`); each segment gets an equal
    share of its part. ``depth`` is the state ``c`` carried from the phase before; returns the
    states and the ``c`` this phase carries on.
    """
    begin, end = window
    intervals, segments = shape.intervals, shape.segments
    parts = 2 if shape.braking else 1
    edges = [begin, _split(exact, phase, kind, window), end] if parts == 2 else [begin, end]
    per_part = segments // parts
    durations = np.concatenate(
        [np.full(per_part, (edges[j + 1] - edges[j]) / per_part) for j in range(parts)]
    )
    steps = fractions * np.repeat(durations, shape.nodes)
    times = begin + np.concatenate([[0.0], np.cumsum(steps)])
    times[-1] = end
    state = exact.state(times)
    columns = []
    for vehicle in range(2):
        if phase.parked(vehicle):
            columns += [np.zeros(intervals + 1)] * 3
            continue
        s = np.where(state.leg[vehicle] == phase.legs[vehicle], state.s[vehicle], 0.0)
        v = np.gradient(s, times)
        columns += [s, v, np.gradient(v, times)]
    if kind.reversing >= 0 and parts == 2:
        depth = float(columns[3 * kind.reversing][shape.part_intervals])
    segment = np.repeat(durations, shape.nodes)
    columns += [np.concatenate([segment, segment[-1:]]), np.full(intervals + 1, depth)]
    return np.column_stack(columns), depth


def initial_guess(
    exact: Schedule,
    waypoint_times: np.ndarray,
    phases: tuple[Phase, ...],
    shape: NlpShape,
    size: int,
    fractions: np.ndarray,
) -> np.ndarray:
    """Stage-ordered initial guess from the exact schedule, shape (size,).

    ``fractions`` (phase_count, intervals) is the grid the NLP is solved on.

    Raises
    ------
    SolverError
        The guess does not fit the NLP's layout (a bug: the caller falls back to ``exact``).
    """
    windows = phase_windows(phases, waypoint_times, exact.duration)
    states, depth = [], 0.0
    for p, (phase, window) in enumerate(zip(phases, windows, strict=True)):
        nodes, depth = _phase_states(exact, phase, window, shape, fractions[p], shape.kinds[p], depth)
        states.append(nodes)
    return assemble(states, shape, size)


def assemble(states: list[np.ndarray], shape: NlpShape, size: int) -> np.ndarray:
    """The stage-ordered variable vector from per-phase node states, shape (size,).

    ``states[p]`` (intervals + 1, 8) are phase ``p``'s nodes in leg coordinates
    with the segment duration (of the segment each node starts) and ``c`` last; controls start at 0.

    Raises
    ------
    SolverError
        The vector does not fit the NLP's layout (a bug: the caller falls back to ``exact``).
    """
    guess = list(states[0][0])
    for stage in stages(shape):
        node = states[stage.phase + 1][0] if stage.phase_end else states[stage.phase][stage.interval + 1]
        guess += [0.0, 0.0] + ([float(node[DURATION])] if stage.new_segment else [])
        guess += [float(node[DEPTH])] if stage.new_depth else []
        guess += list(node)
    vector = np.array(guess, dtype=float)
    if vector.size != size:
        raise SolverError(f"initial guess has {vector.size} values, the NLP {size}")
    return vector
