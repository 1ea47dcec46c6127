"""The braking rule a plan meant for execution obeys: what is planned is what executes.

At every instant of a plan, each vehicle that follows at a conflict of the
coordination diagram (:mod:`trajgen.model.coordination`) can still come to rest,
under its service braking, short of its frontier: short of every position
that meets a position where its leader could still come to rest, from the
leader's earliest rest point (its emergency braking) on. The online executor
keeps exactly this frontier; a plan that obeys the rule is played as it is,
and the executor's braking check never has to hold a vehicle back.

:func:`braking_rule_failures` checks it between any two instants: the margin
``g(t) = F_j(e_i(t)) - r_j(t)`` can only fall as fast as the follower's
service stop point ``r_j`` moves forward (the frontier ``F_j`` never moves
back while the leader brakes no harder than its emergency deceleration), so a
margin at an instant larger than what ``r_j`` can gain in the next ``h``
seconds (:func:`stop_point_rate`, from the state and the limits) covers them;
the check samples each piece and halves the step where the margin is thin.
Through a step where the follower rests or cruises (acceleration and jerk 0
at both ends, within one piece), ``r_j`` moves at its speed, not at what the
limits would allow: hours of waiting cost no more than seconds. Its cost grows
with the pieces and the thin stretches, not with the duration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from limits import VehicleLimits
from trajgen.model.coordination import pair_diagrams, schedule_paths, stopping_distances
from trajgen.model.pieces import Pieces
from trajgen.model.values import sorted_unique

__all__ = [
    "BRAKING_RULE_TOLERANCE",
    "BrakingRuleFailure",
    "braking_rule_failures",
    "for_execution",
    "stop_point_rate",
]

#: How far a follower's service stop point may pass its frontier, metres: the rule is certified to this
#: (far inside the executor's position margin), which keeps the check's cost bounded where a plan brakes
#: straight into its frontier (its stop point stays on it throughout).
BRAKING_RULE_TOLERANCE = 1e-3
#: The shortest step the check halves down to, seconds.
_SHORTEST_STEP = 1e-6
#: Most margins evaluated for one schedule: a plan that rides its frontier closer than the tolerance
#: for long is refused rather than certified (it would leave the executor no room either).
_EVALUATIONS = 2_000_000


def stop_point_rate(
    limits: VehicleLimits, velocity, acceleration, step, jerk_limited: bool = True
) -> np.ndarray:
    """An upper bound of how fast a vehicle's service stop point moves during the next ``step`` seconds, m/s.

    ``d/dt (p + D(v, a)) = v + D_v dv/dt + D_a da/dt`` with ``D`` the bound of
    :func:`~trajgen.model.coordination.stopping_distance` (which counts only a positive acceleration),
    over the states the vehicle can reach from ``(velocity, acceleration)`` within ``step``: the
    speed grows by at most ``a+ h + J h^2 / 2`` and the acceleration by ``J h``, within the limits.
    A vehicle at rest can move its stop point only by about ``A h^2``.

    Without a jerk limit the stop point ``p + v^2 / (2 A)`` moves at ``v (1 + a / A) <= 2 v``.

    Parameters
    ----------
    limits : VehicleLimits
    velocity, acceleration, step : ndarray, shape (n,)
        Rate of travel (m/s), its acceleration (m/s²) and the time ahead (s).
    jerk_limited : bool, optional
        Whether the stop is jerk-limited (see :func:`~trajgen.model.coordination.stopping_distance`).
    """
    v_max, a_max, j_max = limits.max_velocity, limits.max_acceleration, limits.max_jerk
    if not jerk_limited:
        return 2.0 * np.minimum(np.maximum(velocity, 0.0) + a_max * step, v_max)
    a_plus = np.maximum(acceleration, 0.0)
    v = np.minimum(np.maximum(velocity, 0.0) + a_plus * step + 0.5 * j_max * step * step, v_max)
    a = np.minimum(a_plus + j_max * step, a_max)
    peak = v + a * a / (2.0 * j_max)
    d_peak = peak / a_max + a_max / (2.0 * j_max)  # of peak^2 / 2A + peak A / 2J
    d_dv = a / j_max + d_peak
    d_da = v / j_max + a * a / (j_max * j_max) + d_peak * a / j_max
    return v + d_dv * a + d_da * j_max


@dataclass(frozen=True, slots=True)
class BrakingRuleFailure:
    """Where a follower of a plan could not stop short of its frontier.

    Attributes
    ----------
    vehicle : int
        Its index in the schedule's vehicles.
    time : float
        The worst instant found, seconds.
    excess : float
        How far its service stop point passes its frontier there, metres (NaN: the margin stays
        too thin for the check to settle, which is refused too).
    """

    vehicle: int
    time: float
    excess: float

    def message(self, where: str) -> str:
        """The finding in words, the vehicle being ``where`` (on the track) at :attr:`time`."""
        what = (
            f"its service stop point passes it by {self.excess:.3g} m"
            if math.isfinite(self.excess)
            else "its margin stays too thin to certify"
        )
        return (
            f"vehicle {self.vehicle + 1} cannot stop short of its frontier at t={self.time:.6f} s ({where}): "
            f"{what} (the braking rule; expected at most {BRAKING_RULE_TOLERANCE:g} m past it)"
        )


def for_execution(schedule) -> bool:
    """Whether ``schedule`` is a plan for execution: its method plans for it, and it is no table read back.

    Such a plan obeys the braking rule (a table read back follows a plan that was checked; its own
    round-off is not an execution).
    """
    method = schedule.method
    planned = method is None or bool(getattr(method, "plans_for_execution", True))
    return planned and schedule.end_tolerance is None


def braking_rule_failures(
    schedule, *, separation: float | None = None, pieces: Pieces | None = None
) -> list[BrakingRuleFailure]:
    """Where a follower of ``schedule`` could not stop short of its frontier: its worst instant, per vehicle.

    Parameters
    ----------
    schedule : Schedule or GraphSchedule
    separation : float, optional
        Track distance the conflicts keep, metres (default: the schedule's own separation).
    pieces : Pieces, optional
        The schedule's polynomial pieces, if at hand (:func:`~trajgen.model.pieces.schedule_pieces`).

    Returns
    -------
    list of BrakingRuleFailure
        Empty if the rule holds throughout.
    """
    separation = schedule.limits.min_separation if separation is None else separation
    if schedule.duration <= 0.0:
        return []
    paths, times, travel = schedule_paths(schedule, pieces)
    count = len(paths)
    # a diagram per pair of vehicles; a vehicle's frontier is the least over the pairs it follows in
    diagrams = [
        (pair, diagram)
        for pair, diagram in pair_diagrams(schedule, paths, separation, times)
        if diagram.conflicts
    ]
    if not diagrams:
        return []
    vehicles = schedule.limits.vehicles
    emergency = np.array([v.emergency_braking for v in vehicles])[:, None]
    axis_at = schedule.state(times).axis
    # each vehicle's reversals and its end, in travel: where its earliest rest is capped
    tips = [np.array([*path.stops, path.length]) for path in paths]

    def reversal(p: np.ndarray) -> np.ndarray:
        """The next reversal (or end) ahead of travel ``p``, per vehicle; (V, n)."""
        out = np.empty_like(p)
        for i in range(count):
            out[i] = tips[i][np.minimum(np.searchsorted(tips[i], p[i], side="left"), tips[i].size - 1)]
        return out

    def margins(t: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Margins ``F_j - r_j`` at times ``t`` and how far they can fall in ``step``; (V, n) each.

        ``F_j``: the least over the pairs of ``j``'s frontier from the other's earliest rest ``e_i``.

        A margin is ``inf`` where no conflict binds the vehicle.
        """
        state = schedule.state(t)
        k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
        # a vehicle resting or cruising through the whole step (acceleration and jerk 0 at both ends of
        # a stretch within one piece, whose jerk is at most linear) moves its stop point at its speed
        after = schedule.state(t + step)
        same_cell = np.searchsorted(times, t + step, side="left") - 1 <= k
        steady = same_cell & (state.acceleration == 0.0) & (state.jerk == 0.0)
        steady &= (after.acceleration == 0.0) & (after.jerk == 0.0)
        moved = state.axis - axis_at[:, k]
        p = travel[:, k] + np.abs(moved)
        direction = np.where(moved != 0.0, np.sign(moved), np.sign(state.velocity))
        speed = np.abs(state.velocity)
        earliest = np.minimum(p + speed * speed / (2.0 * emergency), np.maximum(reversal(p), p))
        frontier = np.full((count, t.size), np.inf)
        for pair, diagram in diagrams:
            for side, j in enumerate(pair):
                other = pair[1 - side]
                np.minimum(frontier[j], diagram.frontiers(side, earliest[other]), out=frontier[j])
        out, fall = np.empty((count, t.size)), np.empty((count, t.size))
        for j in range(count):
            acceleration = direction[j] * state.acceleration[j]
            stop = p[j] + stopping_distances(
                speed[j], acceleration, vehicles[j], jerk_limited=schedule.jerk_limited
            )
            out[j] = frontier[j] - stop
            rate = stop_point_rate(vehicles[j], speed[j], acceleration, step, schedule.jerk_limited)
            fall[j] = np.where(steady[j], speed[j], rate) * step
        return out, fall

    worst: list[BrakingRuleFailure | None] = [None] * count
    grid = sorted_unique(np.concatenate([times, np.linspace(0.0, schedule.duration, 64)]))
    starts, ends = grid[:-1], grid[1:]
    evaluations = 0
    while starts.size:
        evaluations += starts.size
        if evaluations > _EVALUATIONS:
            k = int(np.argmin(ends - starts))
            # the vehicle whose margin is thinnest there, against what it can lose in the step
            values, fall = margins(starts[k : k + 1], ends[k : k + 1] - starts[k : k + 1])
            thinnest = int(np.argmin(values[:, 0] - fall[:, 0]))
            return [BrakingRuleFailure(thinnest, float(starts[k]), math.nan)]
        values, fall = margins(starts, ends - starts)
        for j in range(count):
            bad = np.nonzero(values[j] < -BRAKING_RULE_TOLERANCE)[0]
            if bad.size:
                k = bad[np.argmin(values[j, bad])]
                if worst[j] is None or -values[j, k] > worst[j].excess:
                    worst[j] = BrakingRuleFailure(j, float(starts[k]), float(-values[j, k]))
        # a margin of what it can lose in the next h seconds covers them; thinner ones are looked at
        # twice as closely
        thin = np.any(values < fall - BRAKING_RULE_TOLERANCE, axis=0)
        thin &= np.all(values >= -BRAKING_RULE_TOLERANCE, axis=0) & (ends - starts > _SHORTEST_STEP)
        middle = 0.5 * (starts[thin] + ends[thin])
        starts, ends = np.concatenate([starts[thin], middle]), np.concatenate([middle, ends[thin]])
    return [failure for failure in worst if failure is not None]
