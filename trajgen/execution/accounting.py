"""A closed-loop run's accounting: what the true motion and the commands did, cycle by cycle.

:func:`~trajgen.execution.simulation.simulate` runs the loop; this module keeps its books, each
of one job:

- :class:`SeparationWatch`: the true track distance of every pair at every cycle, certified between
  cycles too (track distance is 1-Lipschitz in each vehicle's position, so between two cycles it is
  at least the mean of the two distances less half the distance both vehicles drove), the closest
  approach of any pair and the cycles below the minimum separation;
- :class:`LimitWatch`: the commanded setpoints against the vehicle limits, the worst ratios and the
  cycles beyond them;
- :class:`PlanLedger`: the plans the run drove (the undisturbed one, then one per re-plan for a new
  goal), what each would have taken undisturbed, and the time spent waiting at goals.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from limits import Limits
from topology import TrackGraph
from topology.indexed import leg_travel
from topology.indexed import separation as indexed_separation
from trajgen.model.coordination import schedule_paths
from trajgen.model.graph_vehicle_path import GraphMetric

__all__ = ["ExecutedPlan", "LimitWatch", "PlanLedger", "SeparationWatch"]

#: True track distance below the minimum separation that counts as a violation, metres (1 µm).
_VIOLATION_TOLERANCE = 1e-6
#: Travel short of a point that counts as having reached it, metres (the executor's positions).
_TRAVEL_TOLERANCE = 1e-9
#: Relative tolerance on the commanded limits (Ruckig's jerk phases are exactly at the limit).
_LIMIT_TOLERANCE = 1e-6


@dataclass(frozen=True, slots=True, eq=False)
class ExecutedPlan:
    """One plan a run drove: the undisturbed one, then one per re-plan for a new goal.

    Attributes
    ----------
    schedule : Schedule or GraphSchedule
        The plan (the first is the run's undisturbed plan; each later one was verified when it was made).
    started_s, ended_s : float
        When the run took it up, and when every vehicle came to rest at its goal, or the run left it
        (for a new goal) or ended, seconds of the run.
    planned_s : float
        How long the part of it the run drove takes undisturbed, seconds: the whole plan if the run
        drove it to its end, or if it is the run's last (the goal the run ended at, reached or
        not), else the plan's time at which every vehicle got as far along its path as it was
        when the run left it.
    travel_before : tuple of float
        Each vehicle's travel along the earlier plans' paths when the run took this one up, metres
        (where its paths start on the run's travel axes).
    axis_signs : tuple of int
        Each vehicle's own axis against the plan's (+1 or -1): the plan's velocity times this is the
        vehicle's.
    """

    schedule: object = field(repr=False)
    started_s: float
    ended_s: float
    planned_s: float
    travel_before: tuple[float, ...]
    axis_signs: tuple[int, ...]

    @property
    def lost_s(self) -> float:
        """Time the run took on this plan beyond its undisturbed time, seconds."""
        return self.ended_s - self.started_s - self.planned_s


def _closing_rate(same_leg: bool, s: tuple, v: tuple, orientation: tuple) -> float:
    """How fast the track distance of two vehicles on their legs changes, m/s."""
    ds = (orientation[0] * v[0], orientation[1] * v[1])
    if same_leg:
        return (ds[0] - ds[1]) * (1.0 if s[0] >= s[1] else -1.0)
    return ds[0] + ds[1]


def _between(before, bodies, first: float, second: float, bend: float) -> float:
    """A lower bound of the true track distance between two cycles, metres.

    ``before``: each vehicle's ``(leg, s, a, v, orientation)`` at the earlier cycle. While each vehicle
    stays on its leg, the distance (``|s1 - s2|`` or ``s1 + s2``) can dip below both end values only
    if its rate turns from closing to opening inside the cycle: then the smaller end value less the
    bend of the two motions (``max |a| * dt**2 / 8`` each), else the smaller end value; 0 if two
    vehicles on one leg swapped order. Through the junction: the mean of the two ends less half of
    how far both drove (track distance is 1-Lipschitz in each position).
    """
    stayed = all(
        old[0] == b.leg and (old[1] > 0.0) == (b.s > 0.0) for old, b in zip(before, bodies, strict=True)
    )
    if stayed:
        same_leg = before[0][0] == before[1][0]
        if same_leg and (before[0][1] - before[1][1]) * (bodies[0].s - bodies[1].s) < 0.0:
            return 0.0
        start = _closing_rate(
            same_leg, (before[0][1], before[1][1]), (before[0][3], before[1][3]), (before[0][4], before[1][4])
        )
        end = _closing_rate(
            same_leg,
            (bodies[0].s, bodies[1].s),
            (bodies[0].v, bodies[1].v),
            (bodies[0].orientation, bodies[1].orientation),
        )
        return min(first, second) - (bend if start < 0.0 < end else 0.0)
    moved = sum(leg_travel(old[0], old[1], b.leg, b.s) for old, b in zip(before, bodies, strict=True))
    return 0.5 * (first + second - moved)


def _graph_between(before, bodies, first: float, second: float, bend: float) -> float:
    """:func:`_between` on a track graph: a lower bound of the track distance between two cycles, metres.

    While each vehicle stays on its edge, the track distance is the least of affine functions of
    the two positions, ``c + σ1 s1 + σ2 s2`` (one per way between them, ``|s1 - s2|`` on one edge
    while neither passes the other), so it is at least the smaller end value unless one of them
    dips inside the cycle: only if its rate turns from closing to opening there, and then by at
    most the bend of the two motions (``max |a| * dt**2 / 8`` each). 0 if two vehicles on one edge
    swapped order. Through a node: the mean of the two ends less half of how far both drove.
    """
    if all(old[0] == b.leg for old, b in zip(before, bodies, strict=True)):
        if before[0][0] == before[1][0] and (before[0][1] - before[1][1]) * (bodies[0].s - bodies[1].s) < 0.0:
            return 0.0
        start = [old[4] * old[3] for old in before]  # ds / dt = (ds / d axis) * (d axis / dt)
        end = [b.orientation * b.v for b in bodies]
        turns = any(
            first_sign * start[0] + second_sign * start[1] < 0.0 < first_sign * end[0] + second_sign * end[1]
            for first_sign in (1.0, -1.0)
            for second_sign in (1.0, -1.0)
        )
        return min(first, second) - (bend if turns else 0.0)
    moved = sum(abs(b.axis - old[5]) for old, b in zip(before, bodies, strict=True))
    return 0.5 * (first + second - moved)


def _time_reached(schedule, travel: tuple[float, ...]) -> float:
    """The earliest time of ``schedule`` at which each vehicle has travelled ``travel``, seconds.

    Each vehicle's travel grows with time; between two instants of :func:`schedule_paths` a
    vehicle does not turn, so its travel there is the one before plus how far its axis moved.
    Bisection to 1e-9 s.
    """
    _, times, along = schedule_paths(schedule)
    reached = 0.0
    for v in range(len(travel)):
        wanted = travel[v] - _TRAVEL_TOLERANCE
        if wanted <= 0.0:
            continue
        k = int(np.searchsorted(along[v], wanted))
        if k >= len(times):
            reached = max(reached, float(times[-1]))
            continue
        low, high = float(times[max(k - 1, 0)]), float(times[k])
        base, origin = along[v][max(k - 1, 0)], schedule.state(low).axis[v]
        while high - low > 1e-9:
            middle = 0.5 * (low + high)
            if base + abs(schedule.state(middle).axis[v] - origin) >= wanted:
                high = middle
            else:
                low = middle
        reached = max(reached, high)
    return reached


class SeparationWatch:
    """The true track distance between the vehicles' bodies, every pair, every cycle and between cycles.

    Parameters
    ----------
    track : StarGraph or TrackGraph
    bodies : sequence of plant bodies
        The plant's vehicles (``leg``, ``s``, ``v``, ``a``, ``orientation``, ``axis``), read in place.
    required : float
        The minimum separation, metres.
    """

    def __init__(self, track, bodies, required: float) -> None:
        self.bodies = bodies
        self.required = required
        self.pairs = tuple(itertools.combinations(range(len(bodies)), 2))
        if isinstance(track, TrackGraph):
            metric = GraphMetric(track)
            self._distance = lambda a, b: metric.distance(a.leg, a.s, b.leg, b.s)
            self._between = _graph_between
        else:
            self._distance = lambda a, b: indexed_separation((a.leg, a.s, b.leg, b.s))
            self._between = _between
        #: Every pair's distance at the last cycle, metres.
        self.distances = self._apart()
        #: The closest pair's distance at the last cycle, metres.
        self.separation = min(self.distances, default=math.inf)
        #: The smallest distance at a cycle, and the smallest certified between cycles too, metres.
        self.smallest = self.certified = self.separation
        #: Cycles at which the distance (or its bound between cycles) fell below the separation.
        self.violations = 0

    def _apart(self) -> tuple[float, ...]:
        return tuple(self._distance(self.bodies[i], self.bodies[j]) for i, j in self.pairs)

    def before(self) -> list[tuple]:
        """What the next :meth:`cycle` needs of the bodies before they move."""
        return [(b.leg, b.s, b.a, b.v, b.orientation, b.axis) for b in self.bodies]

    def cycle(self, before: list[tuple], period: float) -> float:
        """The distance after the bodies moved one ``period`` from ``before``, metres, accounted."""
        bodies = self.bodies
        distances = self._apart()
        low = math.inf
        for (i, j), first, second in zip(self.pairs, self.distances, distances, strict=True):
            pair_before, pair = (before[i], before[j]), (bodies[i], bodies[j])
            # how far the motions (acceleration between its values at the two cycles) leave their chords
            bend = sum(max(abs(old[2]), abs(b.a)) for old, b in zip(pair_before, pair, strict=True))
            low = min(low, second, self._between(pair_before, pair, first, second, bend * period**2 / 8.0))
        now = min(distances, default=math.inf)
        self.smallest = min(self.smallest, now)
        self.certified = min(self.certified, low)
        if low < self.required - _VIOLATION_TOLERANCE:
            self.violations += 1
        self.distances, self.separation = distances, now
        return now


class LimitWatch:
    """The commanded setpoints against each vehicle's limits: worst ratios, cycles beyond them."""

    def __init__(self, limits: Limits, jerk_limited: bool) -> None:
        self.limits = limits
        self.jerk_limited = jerk_limited
        #: Largest ``|velocity|``, ``|acceleration|``, ``|jerk|`` over its limit, of any vehicle.
        self.worst = [0.0, 0.0, 0.0]
        #: Setpoints beyond a limit (or not finite).
        self.violations = 0

    def check(self, setpoints) -> None:
        """Account one cycle's setpoints, one per vehicle."""
        for v, setpoint in enumerate(setpoints):
            vehicle = self.limits.vehicles[v]
            ratios = (
                abs(setpoint.velocity) / vehicle.max_velocity,
                abs(setpoint.acceleration) / vehicle.max_acceleration,
                # a plan that does not limit jerk (toppra) is played with its own jerk
                abs(setpoint.jerk) / vehicle.max_jerk if self.jerk_limited else 0.0,
            )
            if any(r > 1.0 + _LIMIT_TOLERANCE for r in ratios) or not all(map(math.isfinite, ratios)):
                self.violations += 1
            for k in range(3):
                self.worst[k] = max(self.worst[k], ratios[k])


class PlanLedger:
    """The plans a run drove, and when: the undisturbed one, then one per re-plan for a new goal.

    Parameters
    ----------
    schedule : Schedule or GraphSchedule
        The run's first plan, taken up at t = 0.
    axis_signs : tuple of int
        The executor's axis signs for it, one per vehicle.
    """

    def __init__(self, schedule, axis_signs) -> None:
        self.plans: list[ExecutedPlan] = []
        # the plan driven: its schedule, when taken up, each vehicle's travel before it, its axis signs
        self.driving = (schedule, 0.0, (0.0,) * len(axis_signs), tuple(axis_signs))
        #: When every vehicle came to rest at the driven plan's goals, if they have (seconds of the run).
        self.arrived: float | None = None
        #: Seconds every vehicle stood at its goal waiting for a new one.
        self.idle = 0.0

    @property
    def offset(self) -> tuple[float, ...]:
        """Each vehicle's travel along the earlier plans' paths, metres."""
        return self.driving[2]

    def replanned(self, t: float, travel: tuple[float, ...], schedule, axis_signs) -> None:
        """The run left its plan at ``t`` (travel ``travel`` along it) for ``schedule``."""
        driven, started, offset, signs = self.driving
        if self.arrived is None:
            part = ExecutedPlan(driven, started, t, _time_reached(driven, travel), offset, signs)
        else:  # driven to its end: the wait at the goals for the new one is no plan's
            part = ExecutedPlan(driven, started, self.arrived, driven.duration, offset, signs)
            self.idle += t - self.arrived
        self.plans.append(part)
        offset = tuple(before + now for before, now in zip(offset, travel, strict=True))
        self.driving = (schedule, t, offset, tuple(axis_signs))
        self.arrived = None

    def finish(self, makespan: float) -> tuple[ExecutedPlan, ...]:
        """Every plan the run drove, the last up to ``makespan`` (seconds)."""
        schedule, started, offset, signs = self.driving
        self.plans.append(ExecutedPlan(schedule, started, makespan, schedule.duration, offset, signs))
        return tuple(self.plans)
