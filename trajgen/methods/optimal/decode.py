"""From the NLP's solution to a :class:`~trajgen.model.schedule.Schedule` on the vehicles' signed axes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import Route
from trajgen.methods.optimal.phases import DEPTH, DURATION, NO_SWITCH, STATE_SIZE, NlpShape, Phase, stages
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import AxisMap, CubicKinematics, Section

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
    depth : float, optional
        The state ``c``: where the phase's reversing vehicle turns, metres from the junction
        (0 if no vehicle reverses in it, or the value carried from an earlier phase).
    """

    times: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    depth: float = 0.0


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
    depth = 0.0
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
        times[k + 1] = times[k] + x[DURATION] * fractions[stage.phase, k]
        depth = float(x[DEPTH])
        controls[k] = solution[cursor : cursor + 2]
        cursor += stage.control_size
        x = solution[cursor : cursor + STATE_SIZE]
        cursor += STATE_SIZE
        states[k + 1] = x[:6]
        if k == intervals - 1:
            if stage.phase_end:
                switching = phases[stage.phase].switching
                states[-1, 3 * switching + 1 : 3 * switching + 3] *= -1.0
            out.append(PhaseSolution(times, states, controls, depth))
    return out


def _integrate(start: np.ndarray, times: np.ndarray, jerk: np.ndarray) -> np.ndarray:
    """States ``s, v, a`` at each breakpoint, shape (m + 1, 3), from ``start`` under constant jerks."""
    states = np.empty((times.size, 3))
    states[0] = start
    for k, (h, j) in enumerate(zip(np.diff(times), jerk, strict=True)):
        s, v, a = states[k]
        states[k + 1] = (s + h * (v + h * (a / 2.0 + h * j / 6.0)), v + h * (a + h * j / 2.0), a + h * j)
    return states


def _consistent(start: np.ndarray, end: np.ndarray, times: np.ndarray, jerk: np.ndarray) -> np.ndarray:
    """Jerks closest to ``jerk`` (least squares) that drive ``start`` exactly to ``end`` (states s, v, a).

    The solver meets its dynamics, start and goal to ~1e-10; integrating its jerks instead of
    taking its node states makes every knot of the profile agree with its intervals to round-off,
    so the verifier can hold continuity to round-off. The end state is linear in the jerks: one
    jerk ``j`` over an interval of ``h`` followed by ``r`` seconds adds ``j h`` to ``a``,
    ``j (h^2 / 2 + h r)`` to ``v`` and ``j (h^3 / 6 + h^2 r / 2 + h r^2 / 2)`` to ``s``.
    """
    h = np.diff(times)
    rest = times[-1] - times[1:]
    effect = np.vstack([h**3 / 6.0 + h * h * rest / 2.0 + h * rest * rest / 2.0, h * h / 2.0 + h * rest, h])
    residual = end - _integrate(start, times, jerk)[-1]
    return jerk + np.linalg.lstsq(effect, residual, rcond=None)[0]


def _phase_section(
    route: Route, limits: Limits, phases: tuple[Phase, ...], p: int, solved: PhaseSolution, outward, axis
):
    """Profiles and axis maps of both vehicles in phase ``p``; advances ``axis`` (per vehicle) in place.

    Each moving vehicle's profile runs from the solver's state at the phase start (the route's
    start, at rest, in the first phase) exactly to its state at the phase end (the route's goal,
    at rest, in the last), every knot integrated from the one before. A vehicle that passes the
    junction between two phases is there exactly (the solver meets that equality to ~1e-10 m):
    its track position is continuous across the sections to round-off.
    """
    phase = phases[p]
    profiles, maps = [], []
    for vehicle in range(2):
        sign = outward[vehicle]
        columns = slice(3 * vehicle, 3 * vehicle + 3)
        moving = not phase.parked(vehicle)
        jerk = limits.vehicles[vehicle].max_jerk * solved.controls[:, vehicle]
        start, end = solved.states[0, columns].copy(), solved.states[-1, columns].copy()
        if moving:
            if p == 0:
                start = np.array([route.start[vehicle].s, 0.0, 0.0])
            elif phases[p - 1].switching == vehicle:  # it has just entered its leg at the junction
                start[0] = 0.0
            if p == len(phases) - 1:
                end = np.array([route.goal[vehicle].s, 0.0, 0.0])
            elif phase.switching == vehicle:  # it leaves its leg at the junction
                end[0] = 0.0
            jerk = _consistent(start, end, solved.times, jerk)
        node = _integrate(start, solved.times, jerk)[:-1] if moving else solved.states[:-1, columns]
        s0 = node[0, 0]
        initial = np.column_stack(
            [axis[vehicle] + sign * (node[:, 0] - s0), sign * node[:, 1], sign * node[:, 2]]
        )
        profile = PiecewiseCubic(solved.times, initial, sign * jerk)
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
