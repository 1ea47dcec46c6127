"""The initial guess of the optimal-control NLP: the ``exact`` schedule in the stage layout."""

from __future__ import annotations

import numpy as np

from trajgen.errors import SolverError
from trajgen.methods.optimal.phases import STATE_SIZE, NlpShape, Phase, stages
from trajgen.schedule import Schedule

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


def _phase_states(
    exact: Schedule, phase: Phase, window: tuple[float, float], shape: NlpShape, fractions: np.ndarray
) -> np.ndarray:
    """Node states of one phase sampled from the exact schedule, shape (intervals + 1, 7), leg coordinates.

    ``fractions`` (intervals,) is the phase's grid; each segment gets an equal share of the window.
    """
    begin, end = window
    intervals = shape.intervals
    times = begin + (end - begin) * np.concatenate([[0.0], np.cumsum(fractions / shape.segments)])
    state = exact.state(times)
    columns = []
    for vehicle in range(2):
        if phase.parked(vehicle):
            columns += [np.zeros(intervals + 1)] * 3
            continue
        s = np.where(state.leg[vehicle] == phase.legs[vehicle], state.s[vehicle], 0.0)
        v = np.gradient(s, times)
        columns += [s, v, np.gradient(v, times)]
    return np.column_stack([*columns, np.full(intervals + 1, (end - begin) / shape.segments)])


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
    states = [
        _phase_states(exact, phase, window, shape, fractions[p])
        for p, (phase, window) in enumerate(zip(phases, windows, strict=True))
    ]
    return assemble(states, shape, size)


def assemble(states: list[np.ndarray], shape: NlpShape, size: int) -> np.ndarray:
    """The stage-ordered variable vector from per-phase node states, shape (size,).

    ``states[p]`` (intervals + 1, 7) are phase ``p``'s nodes in leg coordinates
    with the segment duration last; controls start at 0.

    Raises
    ------
    SolverError
        The vector does not fit the NLP's layout (a bug: the caller falls back to ``exact``).
    """
    guess = list(states[0][0])
    for stage in stages(shape):
        node = states[stage.phase + 1][0] if stage.phase_end else states[stage.phase][stage.interval + 1]
        guess += [0.0, 0.0] + ([float(node[STATE_SIZE - 1])] if stage.new_segment else [])
        guess += list(node)
    vector = np.array(guess, dtype=float)
    if vector.size != size:
        raise SolverError(f"initial guess has {vector.size} values, the NLP {size}")
    return vector
