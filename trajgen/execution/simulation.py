"""Closed-loop simulation: the executor drives a simulated plant that applies faults.

The plant (:mod:`trajgen.execution.plant`) moves each vehicle after its setpoints;
faults (:mod:`trajgen.execution.faults`) act on the plant only, and the executor
sees their effects through the measurements, and goal requests.

Every cycle the simulation checks the *true* positions against the minimum
separation, certified between cycles too (track distance is 1-Lipschitz in
each vehicle's position, so between two cycles it is at least the mean of the
two distances less half the distance both vehicles drove), and the commanded
setpoints against the vehicle limits. Memory does not grow with the simulated
time (:mod:`trajgen.execution.trace`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from limits import Limits
from topology import StarGraph, TrackGraph
from topology.indexed import leg_travel
from topology.indexed import separation as indexed_separation
from trajgen.errors import InputError
from trajgen.execution.executor import Executor
from trajgen.execution.faults import Fault, FaultError, FaultKind, parse_fault
from trajgen.execution.goals import execution_margin, for_execution, schedule_for_execution
from trajgen.execution.messages import Command, Event, Mode, VehicleState
from trajgen.execution.plant import Plant
from trajgen.execution.trace import PLOT_SAMPLES, Decimated, Trace
from trajgen.export.csv import CsvOptions
from trajgen.model.coordination import schedule_paths
from trajgen.model.graph_vehicle_path import GraphMetric
from trajgen.model.schedule import TimingMethod
from trajgen.model.summary import provenance
from trajgen.model.values import frozen
from trajgen.scenario import GraphScenario, Scenario
from trajgen.verification import VerifiedSchedule

__all__ = ["PLOT_SAMPLES", "ExecutedPlan", "SimulationResult", "Trace", "parse_faults", "simulate"]

logger = logging.getLogger(__name__)

#: A vehicle slower than this is at rest, m/s (a drive closing its last gap creeps for a while).
_AT_REST = 1e-3
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
        When the run took it up, and when both came to rest at its goals, or the run left it (for a
        new goal) or ended, seconds of the run.
    planned_s : float
        How long the part of it the run drove takes undisturbed, seconds: the whole plan if the run
        drove it to its end, or if it is the run's last (the goal the run ended at, reached or
        not), else the plan's time at which both vehicles got as far along their paths as they
        were when the run left it.
    travel_before : tuple of 2 float
        Each vehicle's travel along the earlier plans' paths when the run took this one up, metres
        (where its paths start on the run's travel axes).
    axis_signs : tuple of 2 int
        Each vehicle's own axis against the plan's (+1 or -1): the plan's velocity times this is the
        vehicle's.
    """

    schedule: object = field(repr=False)
    started_s: float
    ended_s: float
    planned_s: float
    travel_before: tuple[float, float]
    axis_signs: tuple[int, int]

    @property
    def lost_s(self) -> float:
        """Time the run took on this plan beyond its undisturbed time, seconds."""
        return self.ended_s - self.started_s - self.planned_s


@dataclass(frozen=True, slots=True, eq=False)
class SimulationResult:
    """What a closed-loop simulation did.

    Attributes
    ----------
    reached_goal : bool
        Both vehicles at rest (under 1 mm/s) at their goals, every fault applied, within the time limit.
    makespan_s : float
        When they got there, seconds (the time limit if they did not).
    planned_s : float
        How long the plans the run drove take undisturbed, seconds: the undisturbed schedule's
        duration without a re-plan; with re-plans for new goals the sum of each plan's part driven
        (:attr:`plans`), so a new goal's plan is not measured against the old goal's.
    time_lost_s : float
        ``makespan_s - planned_s - idle_s``: what faults, and stopping for new goals, cost.
    min_separation_m : float
        Smallest true track distance at the cycles, metres.
    certified_separation_m : float
        Lower bound of the true track distance between cycles, metres.
    velocity_ratio, acceleration_ratio, jerk_ratio : float
        Worst ``|v|, |a|, |j|`` of the setpoints over the vehicle's limit.
    replans : int
        Re-plans (a new goal's).
    rejected_goals : int
    holds : int
        Cycles in which the braking invariant held a vehicle back.
    emergency_brakes : int
        Cycles in which nothing but both braking hard could be certified (must be 0).
    separation_violations, limit_violations : int
        Cycles with the true separation below the minimum, or a setpoint beyond a limit.
    events : tuple of Event
    faults : tuple of Fault
    cycles : int
    plot : dict
        Decimated samples for the plot (read-only arrays): ``t`` (n,), ``speed`` (2, n) m/s,
        ``separation`` (n,) m, ``travel`` (2, n) each vehicle's travel along its paths, m (across
        re-plans: each plan's paths continue where the earlier ones were left), and
        ``frontier`` (2, n) its frontier, m of travel (``inf`` where none binds it).
    schedule : VerifiedSchedule
        The undisturbed plan.
    position_margin : float
        The margin the executor's conflicts kept beyond the separation, metres.
    unapplied_faults : tuple of Fault
        The faults that never applied: due after the run had ended (both vehicles at their goals).
    method : str
        The timing method asked for the plan (its ``computed_by`` is the schedule's own, ``exact``
        after a fallback).
    plans : tuple of ExecutedPlan
        The plans the run drove, in order: the undisturbed one, then one per re-plan.
    idle_s : float
        Seconds both vehicles stood at their goals waiting for a new goal (a goal that came after a
        plan was driven to its end): no plan's time, and not lost.
    """

    reached_goal: bool
    makespan_s: float
    planned_s: float
    time_lost_s: float
    min_separation_m: float
    certified_separation_m: float
    velocity_ratio: float
    acceleration_ratio: float
    jerk_ratio: float
    replans: int
    rejected_goals: int
    holds: int
    emergency_brakes: int
    separation_violations: int
    limit_violations: int
    events: tuple[Event, ...]
    faults: tuple[Fault, ...]
    cycles: int
    plot: dict = field(repr=False)
    schedule: VerifiedSchedule = field(repr=False)
    position_margin: float = 0.0
    unapplied_faults: tuple[Fault, ...] = ()
    method: str = "optimal"
    plans: tuple[ExecutedPlan, ...] = ()
    idle_s: float = 0.0

    @property
    def violations(self) -> int:
        """Separation and limit violations together (must be 0)."""
        return self.separation_violations + self.limit_violations

    def summary(self) -> dict:
        """JSON-ready summary."""
        return {
            "reached_goal": self.reached_goal,
            **provenance(self.schedule.schedule, self.method),
            "makespan_s": round(self.makespan_s, 6),
            "planned_s": round(self.planned_s, 6),
            "time_lost_s": round(self.time_lost_s, 6),
            "idle_s": round(self.idle_s, 6),
            "min_separation_m": round(self.min_separation_m, 6),
            "certified_separation_m": round(self.certified_separation_m, 6),
            "velocity_ratio": round(self.velocity_ratio, 6),
            "acceleration_ratio": round(self.acceleration_ratio, 6),
            "jerk_ratio": round(self.jerk_ratio, 6),
            "replans": self.replans,
            "rejected_goals": self.rejected_goals,
            "holds": self.holds,
            "emergency_brakes": self.emergency_brakes,
            "violations": self.violations,
            "separation_violations": self.separation_violations,
            "limit_violations": self.limit_violations,
            "cycles": self.cycles,
            "faults": [fault.spec for fault in self.faults],
            "unapplied_faults": [fault.spec for fault in self.unapplied_faults],
            "events": [{"t_s": round(e.time, 6), "kind": e.kind, "detail": e.detail} for e in self.events],
            "plans": [
                {
                    "started_s": round(plan.started_s, 6),
                    "ended_s": round(plan.ended_s, 6),
                    "planned_s": round(plan.planned_s, 6),
                    "lost_s": round(plan.lost_s, 6),
                    "duration_s": round(plan.schedule.duration, 6),
                }
                for plan in self.plans
            ],
        }


def parse_faults(
    scenario: Scenario | GraphScenario, specs: Sequence[str], *, position_margin: float = 0.05
) -> tuple[Fault, ...]:
    """Parse ``--fault`` specs against a scenario (see :func:`~trajgen.execution.faults.parse_fault`).

    A jump may be as large as the position margin the executor keeps in this scenario
    (:func:`~trajgen.execution.executor.execution_margin`: at most ``position_margin``).
    """
    margin = execution_margin(scenario, position_margin)
    return tuple(
        parse_fault(
            spec,
            names=scenario.names,
            graph=scenario.track,
            max_velocity=tuple(v.max_velocity for v in scenario.limits.vehicles),
            max_jump=margin,
        )
        for spec in specs
    )


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


def _time_reached(schedule, travel: tuple[float, float]) -> float:
    """The earliest time of ``schedule`` at which each vehicle has travelled ``travel``, seconds.

    Each vehicle's travel grows with time; between two instants of :func:`schedule_paths` a
    vehicle does not turn, so its travel there is the one before plus how far its axis moved.
    Bisection to 1e-9 s.
    """
    _, times, along = schedule_paths(schedule)
    reached = 0.0
    for v in (0, 1):
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


def _time_limit(
    planned: float, faults: Sequence[Fault], limits: Limits, graph: StarGraph | TrackGraph
) -> float:
    """Simulated time after which the run counts as stuck, seconds."""
    slowest = min(v.max_velocity for v in limits.vehicles)
    for fault in faults:
        if fault.kind is FaultKind.SLOW:
            slowest = min(slowest, fault.value)
    total = graph.total_length
    crawl = 2.0 * total * 2.0 / slowest  # both vehicles round the whole track twice
    latest = max((f.time + (f.value if f.kind is FaultKind.STOP else 0.0) for f in faults), default=0.0)
    return latest + 3.0 * planned + crawl + 60.0


def simulate(
    scenario: Scenario | GraphScenario,
    faults: Sequence[Fault] = (),
    *,
    period: float = 0.01,
    method: TimingMethod | str | None = None,
    position_margin: float = 0.05,
    trace: CsvOptions | None = None,
    verified: VerifiedSchedule | None = None,
    observer: Callable[[Executor, tuple[VehicleState, VehicleState], Command], None] | None = None,
) -> tuple[SimulationResult, Trace | None]:
    """Run the executor against the simulated plant with ``faults``.

    Parameters
    ----------
    scenario : Scenario
    faults : sequence of Fault
        From :func:`parse_faults`.
    period : float, optional
        Control period, seconds (0.002 to 0.1).
    method : TimingMethod or str, optional
        How the undisturbed schedule is computed (default: the registry's default, ``optimal``).
    position_margin : float, optional
        The executor's position margin, metres (also the largest jump).
    trace : CsvOptions, optional
        Spool the executed motion as CSV rows in this dialect (its sample period is ignored).
    verified : VerifiedSchedule, optional
        The plan, if already computed for ``scenario``
        (:func:`~trajgen.execution.goals.schedule_for_execution`).
    observer : callable, optional
        Called every cycle with the executor, the measured states and the command (for tests and tools).

    Returns
    -------
    SimulationResult, Trace or None
        The trace's temporary files are closed by ``Trace.close``.
    """
    if not isinstance(scenario, (Scenario, GraphScenario)):
        raise InputError(f"simulate expects a Scenario or a GraphScenario, got {type(scenario).__name__}")
    margin = execution_margin(scenario, position_margin)
    for fault in faults:
        if not isinstance(fault, Fault):
            raise InputError(f"faults must be Fault objects (parse_faults), got {type(fault).__name__}")
        if fault.kind is FaultKind.JUMP and abs(fault.value) > margin:
            raise FaultError(
                f"fault {fault.spec!r}: jump beyond the position margin {margin!r} m kept in this scenario"
            )
    # a plan handed in without a method: the method asked for is the one that computed it
    asked = (
        verified.schedule.method.name
        if method is None and verified is not None
        else for_execution(method, scenario.track).name
    )
    if verified is None:
        verified = schedule_for_execution(scenario, method=method, position_margin=position_margin)
    executor = Executor(
        verified,
        period=period,
        position_margin=margin,
        min_separation=scenario.limits.min_separation,
        names=scenario.names,
    )
    plant = Plant(executor, faults, period)
    jerk_limited = verified.schedule.jerk_limited
    limits = scenario.limits
    planned = verified.schedule.duration
    horizon = _time_limit(planned, faults, limits, scenario.track)
    pending = sorted((f for f in faults if f.kind in (FaultKind.JUMP, FaultKind.GOAL)), key=lambda f: f.time)
    spool = Trace(scenario.track, trace) if trace is not None else None
    plot = Decimated(PLOT_SAMPLES)
    worst = [0.0, 0.0, 0.0]
    separation_violations = limit_violations = 0
    bodies = plant.bodies
    on_graph = isinstance(scenario, GraphScenario)
    if on_graph:
        metric = GraphMetric(scenario.track)

        def apart() -> float:
            return metric.distance(bodies[0].leg, bodies[0].s, bodies[1].leg, bodies[1].s)

        between_cycles = _graph_between
    else:

        def apart() -> float:
            return indexed_separation((bodies[0].leg, bodies[0].s, bodies[1].leg, bodies[1].s))

        between_cycles = _between
    separation = apart()
    smallest = certified = separation
    required = limits.min_separation
    if spool is not None:
        spool.add(0.0, bodies)
    plot.add((0.0, bodies[0].v, bodies[1].v, separation, 0.0, 0.0, math.inf, math.inf))
    plans: list[ExecutedPlan] = []
    driving = (verified.schedule, 0.0, (0.0, 0.0), executor.axis_signs)  # plan, taken up at, travel before
    travel = (0.0, 0.0)  # along the plan's paths at the last cycle
    arrived = None  # when both came to rest at the plan's goals, if they have
    idle = 0.0  # seconds both stood at their goals waiting for a new one
    cycle = 0
    t = 0.0
    makespan = None
    try:
        while t < horizon:
            while pending and pending[0].time <= t + 1e-12:
                fault = pending.pop(0)
                if fault.kind is FaultKind.JUMP:
                    plant.jump(fault)
                else:
                    decision = executor.request_goal(fault.vehicle, fault.goal)
                    logger.info("goal request %s: %s", fault.spec, decision)
            measured = plant.measure()
            command = executor.step(measured)
            if observer is not None:
                observer(executor, measured, command)
            if executor.replans > len(plans):  # left for a new goal where both stood at rest
                schedule, started, offset, signs = driving
                if arrived is None:
                    part = ExecutedPlan(schedule, started, t, _time_reached(schedule, travel), offset, signs)
                else:  # driven to its end: the wait at the goals for the new one is no plan's
                    part = ExecutedPlan(schedule, started, arrived, schedule.duration, offset, signs)
                    idle += t - arrived
                plans.append(part)
                offset = (offset[0] + travel[0], offset[1] + travel[1])
                driving = (executor.schedule, t, offset, executor.axis_signs)
                arrived = None
            travel = executor.travel
            for v, setpoint in enumerate(command.setpoints):
                vehicle = limits.vehicles[v]
                ratios = (
                    abs(setpoint.velocity) / vehicle.max_velocity,
                    abs(setpoint.acceleration) / vehicle.max_acceleration,
                    # a plan that does not limit jerk (toppra) is played with its own jerk
                    abs(setpoint.jerk) / vehicle.max_jerk if jerk_limited else 0.0,
                )
                if any(r > 1.0 + _LIMIT_TOLERANCE for r in ratios) or not all(map(math.isfinite, ratios)):
                    limit_violations += 1
                for k in range(3):
                    worst[k] = max(worst[k], ratios[k])
            before = [(b.leg, b.s, b.a, b.v, b.orientation, b.axis) for b in bodies]
            plant.advance(command, t)
            cycle += 1
            t = cycle * period
            now = apart()
            # how far the motions (acceleration between its values at the two cycles) leave their chords
            bend = (
                sum(max(abs(old[2]), abs(b.a)) for old, b in zip(before, bodies, strict=True))
                * period**2
                / 8.0
            )
            between = between_cycles(before, bodies, separation, now, bend)
            smallest = min(smallest, now)
            certified = min(certified, now, between)
            if min(now, between) < required - _VIOLATION_TOLERANCE:
                separation_violations += 1
            separation = now
            if spool is not None:
                spool.add(t, bodies)
            offset = driving[2]
            plot.add(
                (
                    t,
                    bodies[0].v,
                    bodies[1].v,
                    now,
                    offset[0] + travel[0],
                    offset[1] + travel[1],
                    offset[0] + command.frontiers[0],
                    offset[1] + command.frontiers[1],
                )
            )
            at_goals = command.mode is Mode.DONE and all(abs(b.v) <= _AT_REST for b in bodies)
            if at_goals and arrived is None:
                arrived = t
            # both at their goals: the run ends, also before a stop or slow-down that would come later
            if at_goals and not pending:
                makespan = t
                break
    except BaseException:
        if spool is not None:
            spool.close()
        raise
    rows = np.array(plot.rows) if plot.rows else np.zeros((0, 8))
    samples = {
        "t": frozen(rows[:, 0].copy()),
        "speed": frozen(rows[:, 1:3].T.copy()),
        "separation": frozen(rows[:, 3].copy()),
        "travel": frozen(rows[:, 4:6].T.copy()),
        "frontier": frozen(rows[:, 6:8].T.copy()),
    }
    reached = makespan is not None
    makespan = makespan if reached else t
    schedule, started, offset, signs = driving
    plans.append(ExecutedPlan(schedule, started, makespan, schedule.duration, offset, signs))
    planned = sum(plan.planned_s for plan in plans)
    unapplied = tuple(f for f in faults if f.time > makespan + 1e-9)
    for fault in unapplied:
        logger.info("fault %s never applied: the run ended at %.3f s", fault.spec, makespan)
    result = SimulationResult(
        reached_goal=reached,
        makespan_s=makespan,
        planned_s=planned,
        time_lost_s=makespan - planned - idle,
        min_separation_m=smallest,
        certified_separation_m=certified,
        velocity_ratio=worst[0],
        acceleration_ratio=worst[1],
        jerk_ratio=worst[2],
        replans=executor.replans,
        rejected_goals=executor.rejected_goals,
        holds=executor.holds,
        emergency_brakes=executor.emergency_brakes,
        separation_violations=separation_violations,
        limit_violations=limit_violations,
        events=tuple(executor.events),
        faults=tuple(faults),
        cycles=cycle,
        plot=samples,
        schedule=verified,
        position_margin=margin,
        unapplied_faults=unapplied,
        method=asked,
        plans=tuple(plans),
        idle_s=idle,
    )
    return result, spool
