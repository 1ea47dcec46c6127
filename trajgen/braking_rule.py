"""The braking rule a plan meant for execution obeys: what is planned is what executes.

At every instant of a plan, each vehicle that follows at a conflict of the
coordination diagram (:mod:`trajgen.coordination`) can still come to rest,
under its service braking, short of its frontier: short of every position
that meets a position where its leader could still come to rest, from the
leader's earliest rest point (its emergency braking) on. The online executor
keeps exactly this frontier; a plan that obeys the rule is played as it is,
and the executor's braking check never has to hold a vehicle back.

:func:`braking_rule_failures` checks it between any two instants: the margin
``g(t) = F_j(e_i(t)) - r_j(t)`` can only fall as fast as the follower's
service stop point ``r_j`` moves forward (the frontier ``F_j`` never moves
back while the leader brakes no harder than its emergency deceleration), so a
margin of ``L h`` at an instant covers the next ``h`` seconds (``L`` bounds
how fast ``r_j`` can move); the check samples each piece and halves the step
where the margin is thin. Its cost grows with the pieces and the thin
stretches, not with the duration.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from limits import VehicleLimits
from trajgen.coordination import CoordinationDiagram, earliest_rest, plan_paths, stopping_distance
from trajgen.schedule import Schedule

__all__ = ["BRAKING_RULE_TOLERANCE", "braking_rule_failures", "stop_point_rate"]

#: How far a follower's service stop point may pass its frontier (round-off), metres.
BRAKING_RULE_TOLERANCE = 1e-6
#: The shortest step the check halves down to, seconds.
_SHORTEST_STEP = 1e-7


def stop_point_rate(limits: VehicleLimits) -> float:
    """An upper bound of how fast a vehicle's service stop point can move forward, m/s.

    ``d/dt (p + D(v, a))`` with ``D`` the bound of :func:`~trajgen.coordination.stopping_distance`:
    ``v + D_v a + D_a j`` over ``|v| <= v_max``, ``|a| <= a_max``, ``|j| <= j_max``.
    """
    v, a, j = limits.max_velocity, limits.max_acceleration, limits.max_jerk
    peak = v + a * a / (2.0 * j)
    d_dv = a / j + peak / a + a / (2.0 * j)  # of the ramp term, and of peak^2 / 2a + peak a / 2j
    d_da = v / j + a * a / (j * j) + (peak / a + a / (2.0 * j)) * (a / j)
    return v + d_dv * a + d_da * j


def braking_rule_failures(schedule: Schedule, *, separation: float | None = None) -> list[str]:
    """Where a follower of ``schedule`` could not stop short of its frontier, as failure messages.

    Parameters
    ----------
    schedule : Schedule
    separation : float, optional
        Track distance the conflicts keep, metres (default: the schedule's own separation).

    Returns
    -------
    list of str
        Empty if the rule holds throughout; else one message per vehicle, at its worst instant.
    """
    separation = schedule.limits.min_separation if separation is None else separation
    if schedule.duration <= 0.0:
        return []
    paths, times, travel = plan_paths(schedule)
    diagram = CoordinationDiagram(paths, separation, schedule, times)
    if not diagram.conflicts:
        return []
    vehicles = schedule.limits.vehicles
    emergency = [v.emergency_braking for v in vehicles]
    rates = [stop_point_rate(v) for v in vehicles]

    def margins(t: np.ndarray) -> np.ndarray:
        """``F_j(e_i) - r_j`` of both vehicles at times ``t``, shape (2, n) (``inf`` where nothing binds)."""
        state = schedule.state(t)
        k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
        axis0 = schedule.state(times[k]).axis
        p = travel[:, k] + np.abs(state.axis - axis0)
        direction = np.sign(state.axis - axis0)
        direction = np.where(direction == 0.0, np.sign(state.velocity), direction)
        speed = np.abs(state.velocity)
        acceleration = direction * state.acceleration
        out = np.full((2, t.size), math.inf)
        for n in range(t.size):
            earliest = [earliest_rest(p[v, n], speed[v, n], emergency[v]) for v in (0, 1)]
            for j in (0, 1):
                frontier = diagram.frontier(j, earliest[1 - j])
                if frontier < math.inf:
                    stop = p[j, n] + stopping_distance(speed[j, n], acceleration[j, n], vehicles[j])
                    out[j, n] = frontier - stop
        return out

    worst: list[tuple[float, float] | None] = [None, None]  # (margin, time) of each vehicle's worst failure
    grid = np.unique(np.concatenate([times, np.linspace(0.0, schedule.duration, 64)]))
    pending = [(float(a), float(b)) for a, b in itertools.pairwise(grid) if b > a]
    while pending:
        starts = np.array([a for a, _ in pending])
        values = margins(starts)
        split = []
        for n, (a, b) in enumerate(pending):
            for j in (0, 1):
                g = values[j, n]
                if g < -BRAKING_RULE_TOLERANCE and (worst[j] is None or g < worst[j][0]):
                    worst[j] = (float(g), a)
            need = (
                max(rates[j] * (b - a) for j in (0, 1) if values[j, n] < math.inf)
                if np.any(values[:, n] < math.inf)
                else 0.0
            )
            thin = bool(np.any(values[:, n] < need - BRAKING_RULE_TOLERANCE))
            if thin and b - a > _SHORTEST_STEP and np.all(values[:, n] >= -BRAKING_RULE_TOLERANCE):
                middle = 0.5 * (a + b)
                split += [(a, middle), (middle, b)]
        pending = split
    return [
        f"vehicle {j + 1} cannot stop short of its frontier at t={when:.6f} s: its service stop point "
        f"passes it by {-margin:.3g} m (the braking rule; expected <= {BRAKING_RULE_TOLERANCE:g} m)"
        for j, found in enumerate(worst)
        if found is not None
        for margin, when in [found]
    ]
