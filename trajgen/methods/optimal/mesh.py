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


def _phase_nodes(phase: PhaseSolution, intervals: int) -> np.ndarray:
    """New node times of one phase, shape (intervals + 1,), from 0 to the phase's duration."""
    times = phase.times
    duration = times[-1]
    strength = _switch_strength(phase.controls)
    around = 0.5 * (strength[:-1] + strength[1:])  # each switch spread over its two intervals
    mass = _EVEN_SHARE * np.diff(times) / duration
    total = around.sum()
    mass = mass + (1.0 - _EVEN_SHARE) * around / total if total > 0.0 else mass / _EVEN_SHARE
    cumulative = np.concatenate([[0.0], np.cumsum(mass)])
    cumulative /= cumulative[-1]
    nodes = np.interp(np.linspace(0.0, 1.0, intervals + 1), cumulative, times)
    nodes[0], nodes[-1] = 0.0, duration
    return nodes


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
    states : list of ndarray, shape (intervals + 1, 7) each
        Per phase, the previous solution at the new nodes in closed form, with
        the new segment durations last (the phase durations are kept).
    """
    rows, states = [], []
    for phase in solution:
        nodes = _phase_nodes(phase, shape.intervals)
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
        columns.append(np.concatenate([segment, segment[-1:]]))
        states.append(np.column_stack(columns))
    return np.array(rows), states
