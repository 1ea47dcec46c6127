"""From the NLP's solution to a :class:`~trajgen.schedule.Schedule` on the vehicles' signed axes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import Route
from trajgen.methods.optimal.phases import NO_SWITCH, STATE_SIZE, NlpShape, Phase, stages
from trajgen.profiles import PiecewiseCubic
from trajgen.schedule import AxisMap, CubicKinematics, Section

__all__ = ["PhaseSolution", "sections", "unpack"]


@dataclass(frozen=True, slots=True)
class PhaseSolution:
    """One phase of the solution in leg coordinates.

    Attributes
    ----------
    times : ndarray, shape (m + 1,)
        Breakpoints from 0 at the phase start, seconds.
    states : ndarray, shape (m + 1, 6)
        ``s, v, a`` of vehicle 1 then vehicle 2 at each breakpoint (metres, m/s, m/s²).
    controls : ndarray, shape (m, 2)
        Jerk / max jerk of each vehicle on each interval.
    """

    times: np.ndarray
    states: np.ndarray
    controls: np.ndarray


def unpack(
    solution: np.ndarray, phases: tuple[Phase, ...], shape: NlpShape, fractions: np.ndarray
) -> list[PhaseSolution]:
    """Breakpoint times, node states and controls of each phase, from the stage layout.

    ``fractions`` (phase_count, intervals) is the grid the solution was solved on.

    The last node of a phase is the junction crossing, rebuilt from the next
    phase's first node by undoing the sign change of the vehicle that changed leg.
    """
    intervals = shape.intervals
    out = []
    times = states = controls = None
    cursor = STATE_SIZE
    x = solution[:STATE_SIZE]
    for stage in stages(shape):
        if stage.interval == 0:
            times, states, controls = (
                np.zeros(intervals + 1),
                np.zeros((intervals + 1, 6)),
                np.zeros((intervals, 2)),
            )
            states[0] = x[:6]
        k = stage.interval
        times[k + 1] = times[k] + x[STATE_SIZE - 1] * fractions[stage.phase, k]
        controls[k] = solution[cursor : cursor + 2]
        cursor += stage.control_size
        x = solution[cursor : cursor + STATE_SIZE]
        cursor += STATE_SIZE
        states[k + 1] = x[:6]
        if k == intervals - 1:
            if stage.phase_end:
                switching = phases[stage.phase].switching
                states[-1, 3 * switching + 1 : 3 * switching + 3] *= -1.0
            out.append(PhaseSolution(times, states, controls))
    return out


def _spread(initial: np.ndarray, times: np.ndarray, drift: float, *, towards_end: bool) -> np.ndarray:
    """``initial`` with a position residual ``drift`` spread linearly over the phase (adds drift/T to v)."""
    corrected = initial.copy()
    weight = times[:-1] / times[-1]
    corrected[:, 0] += drift * (weight if towards_end else 1.0 - weight)
    corrected[:, 1] += drift / times[-1] if towards_end else -drift / times[-1]
    return corrected


def _phase_section(
    route: Route, limits: Limits, phases: tuple[Phase, ...], p: int, solved: PhaseSolution, outward, axis
):
    """Profiles and axis maps of both vehicles in phase ``p``; advances ``axis`` (per vehicle) in place."""
    phase = phases[p]
    profiles, maps = [], []
    for vehicle in range(2):
        sign = outward[vehicle]
        node = solved.states[:-1, 3 * vehicle : 3 * vehicle + 3].copy()
        moving = not phase.parked(vehicle)
        if p == 0 and moving:
            # the solver meets the start to ~1e-8 m: spread the residual over the first phase (~1e-9 m/s)
            node = _spread(node, solved.times, route.start[vehicle].s - node[0, 0], towards_end=False)
        s0 = node[0, 0]
        initial = np.column_stack(
            [axis[vehicle] + sign * (node[:, 0] - s0), sign * node[:, 1], sign * node[:, 2]]
        )
        jerk = sign * limits.vehicles[vehicle].max_jerk * solved.controls[:, vehicle]
        profile = PiecewiseCubic(solved.times, initial, jerk)
        if p == len(phases) - 1 and moving:
            # likewise the goal: spread the residual (~1e-8 m) over the last phase
            end_s = s0 + sign * (profile.end_state()[0] - axis[vehicle])
            drift = sign * (route.goal[vehicle].s - end_s)
            profile = PiecewiseCubic(
                solved.times, _spread(initial, solved.times, drift, towards_end=True), jerk
            )
        end_axis = profile.end_state()[0]
        leg = phase.legs[vehicle]
        maps.append(
            AxisMap(
                np.array([axis[vehicle]]),
                np.array([end_axis]),
                np.array([leg]),
                np.array([s0 if moving else 0.0]),
                np.array([sign if moving else 0]),
            )
        )
        profiles.append(profile)
        axis[vehicle] = end_axis
    return profiles, maps


def sections(
    route: Route, limits: Limits, phases: tuple[Phase, ...], solution: list[PhaseSolution]
) -> tuple[Section, ...]:
    """The schedule's sections, one per phase, on axes positive in each vehicle's first direction."""
    outward = [1, 1]  # ds/daxis of each vehicle in the current phase; flips when it changes leg
    axis = [0.0, 0.0]
    pieces = []
    for p, solved in enumerate(solution):
        pieces.append(_phase_section(route, limits, phases, p, solved, outward, axis))
        if phases[p].switching != NO_SWITCH:
            outward[phases[p].switching] *= -1
    # the signed axis is positive in the direction of each vehicle's first move
    flip = [False, False]
    for vehicle in range(2):
        velocities = np.concatenate([profiles[vehicle].initial[:, 1] for profiles, _ in pieces])
        moving = np.nonzero(np.abs(velocities) > 1e-9)[0]
        flip[vehicle] = bool(moving.size and velocities[moving[0]] < 0)
    out = []
    clock = 0.0
    for profiles, maps in pieces:
        oriented = tuple(
            PiecewiseCubic(profile.times, -profile.initial, -profile.jerk) if flip[v] else profile
            for v, profile in enumerate(profiles)
        )
        oriented_maps = tuple(m.flipped() if flip[v] else m for v, m in enumerate(maps))
        kinematics = CubicKinematics(oriented)  # type: ignore[arg-type]
        out.append(Section(clock, kinematics, oriented_maps))  # type: ignore[arg-type]
        clock += kinematics.duration
    return tuple(out)
