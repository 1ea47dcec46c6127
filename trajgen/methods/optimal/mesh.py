"""Mesh refinement: move the grid's nodes to where the jerk switches, and re-solve the same NLP.

A solution on a fixed grid can switch the jerk only at nodes; an S-curve's
switch that falls inside an interval is smeared over it, which costs time in
proportion to the interval's length. The grid is a parameter of the compiled
NLP, so refinement needs no rebuild: the nodes of each phase are
equidistributed over a monitor that gives a quarter of them evenly in time and
the rest to the neighbourhoods of the previous solution's jerk switches (the two
intervals around each, weighted by the size of the switch). Each pass narrows
the neighbourhoods; the previous solution, evaluated in closed form on the new
grid, is the next initial guess.
"""

from __future__ import annotations

import numpy as np

from trajgen.methods.optimal.decode import PhaseSolution
from trajgen.methods.optimal.phases import NlpShape

__all__ = ["refine"]

#: Share of the nodes spread evenly in time; the rest go to the jerk switches. A quarter: with half,
#: a long phase has too few nodes for the switches of both vehicles, and refinement stalls 0.01-0.05 %
#: above a vehicle's own S-curve (1000/800/1200 m: 1049.475 s against 1049.341 s with a quarter).
_EVEN_SHARE = 0.25
#: Jerk changes (in units of the max jerk, summed over both vehicles) below this are not switches.
_SWITCH_FLOOR = 1e-3


def _switch_strength(controls: np.ndarray) -> np.ndarray:
    """Size of the jerk change at each node, shape (m + 1,); 0 at the phase's ends."""
    change = np.abs(np.diff(controls, axis=0)).sum(axis=1)
    change[change < _SWITCH_FLOOR] = 0.0
    return np.concatenate([[0.0], change, [0.0]])


def _segment_nodes(times: np.ndarray, controls: np.ndarray, intervals: int) -> np.ndarray:
    """New node times of one segment, shape (intervals + 1,), from its first time to its last."""
    start, duration = times[0], times[-1] - times[0]
    if duration <= 0.0:
        return np.full(intervals + 1, start)
    times = times - start
    strength = _switch_strength(controls)
    around = 0.5 * (strength[:-1] + strength[1:])  # each switch spread over its two intervals
    mass = _EVEN_SHARE * np.diff(times) / duration
    total = around.sum()
    mass = mass + (1.0 - _EVEN_SHARE) * around / total if total > 0.0 else mass / _EVEN_SHARE
    cumulative = np.concatenate([[0.0], np.cumsum(mass)])
    cumulative /= cumulative[-1]
    nodes = np.interp(np.linspace(0.0, 1.0, intervals + 1), cumulative, times)
    nodes[0], nodes[-1] = 0.0, duration
    return start + nodes


def _phase_nodes(phase: PhaseSolution, segments: int, nodes: int) -> np.ndarray:
    """New node times of one phase, shape (segments * nodes + 1,), segment by segment.

    Each segment keeps its start and end (a part boundary, where a vehicle turns back, stays
    one) and its nodes move within it.
    """
    out = [np.zeros(1)]
    for j in range(segments):
        span = slice(j * nodes, (j + 1) * nodes + 1)
        out.append(_segment_nodes(phase.times[span], phase.controls[j * nodes : (j + 1) * nodes], nodes)[1:])
    return np.concatenate(out)


def refine(
    solution: list[PhaseSolution], shape: NlpShape, max_jerk: tuple[float, float]
) -> tuple[np.ndarray, list[np.ndarray]]:
    """The refined grid and the solution evaluated on it.

    Parameters
    ----------
    solution : list of PhaseSolution
        The previous pass, one per phase.
    shape : NlpShape
    max_jerk : tuple of 2 float
        The vehicles' max jerk, m/s³ (the stored controls are jerk / max jerk).

    Returns
    -------
    fractions : ndarray, shape (phase_count, intervals)
        The new grid; each segment's shares sum to 1.
    states : list of ndarray, shape (intervals + 1, 8) each
        Per phase, the previous solution at the new nodes in closed form, with
        the new segment durations and the state ``c`` last (the segment durations are kept).
    """
    rows, states = [], []
    for phase in solution:
        nodes = _phase_nodes(phase, shape.segments, shape.nodes)
        h = np.diff(nodes).reshape(shape.segments, shape.nodes)
        durations = h.sum(axis=1)
        rows.append((h / durations[:, None]).ravel())
        index = np.clip(np.searchsorted(phase.times, nodes, side="right") - 1, 0, len(phase.controls) - 1)
        dt = nodes - phase.times[index]
        columns = []
        for vehicle in range(2):
            s, v, a = (phase.states[index, 3 * vehicle + k] for k in range(3))
            jerk = max_jerk[vehicle] * phase.controls[index, vehicle]
            columns += [
                s + dt * (v + dt * (a / 2.0 + dt * jerk / 6.0)),
                v + dt * (a + dt * jerk / 2.0),
                a + dt * jerk,
            ]
        segment = np.repeat(durations, shape.nodes)
        columns += [np.concatenate([segment, segment[-1:]]), np.full(len(nodes), phase.depth)]
        states.append(np.column_stack(columns))
    return np.array(rows), states
