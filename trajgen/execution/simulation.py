"""Closed-loop simulation: the executor drives a simulated plant that applies faults.

The plant (:mod:`trajgen.execution.plant`) moves each vehicle after its setpoints;
faults (:mod:`trajgen.execution.faults`) act on the plant only, and the executor
sees their effects through the measurements, and goal requests.

:func:`simulate` is the run loop: faults in, measurements to the executor, its setpoints to the
plant. Its books are kept by :mod:`trajgen.execution.accounting`: every cycle the *true* positions
against the minimum separation, certified between cycles too, the commanded setpoints against the
vehicle limits, and the plans driven. Memory does not grow with the simulated time
(:mod:`trajgen.execution.trace`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from limits import Limits
from topology import StarGraph, TrackGraph
from trajgen.errors import InputError
from trajgen.execution.accounting import ExecutedPlan, LimitWatch, PlanLedger, SeparationWatch
from trajgen.execution.executor import Executor
from trajgen.execution.faults import Fault, FaultError, FaultKind, parse_fault
from trajgen.execution.goals import execution_margin, for_execution, schedule_for_execution
from trajgen.execution.messages import Command, Event, Mode, VehicleState
from trajgen.execution.plant import Plant
from trajgen.execution.trace import PLOT_SAMPLES, Decimated, Trace
from trajgen.export.csv import CsvOptions
from trajgen.model.schedule import TimingMethod
from trajgen.model.summary import provenance
from trajgen.model.values import frozen
from trajgen.scenario import GraphScenario, Scenario
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["PLOT_SAMPLES", "ExecutedPlan", "SimulationResult", "Trace", "parse_faults", "simulate"]

logger = logging.getLogger(__name__)

#: A vehicle slower than this is at rest, m/s (a drive closing its last gap creeps for a while).
_AT_REST = 1e-3


@dataclass(frozen=True, slots=True, eq=False)
class SimulationResult:
    """What a closed-loop simulation did.

    Attributes
    ----------
    reached_goal : bool
        Every vehicle at rest (under 1 mm/s) at their goals, every fault applied, within the time limit.
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
        Cycles in which nothing but every vehicle braking hard could be certified (must be 0).
    separation_violations, limit_violations : int
        Cycles with the true separation below the minimum, or a setpoint beyond a limit.
    events : tuple of Event
    faults : tuple of Fault
    cycles : int
    plot : dict
        Decimated samples for the plot (read-only arrays): ``t`` (n,), ``speed`` (V, n) m/s,
        ``separation`` (n,) m (the closest pair), ``travel`` (V, n) each vehicle's travel along its
        paths, m (across re-plans: each plan's paths continue where the earlier ones were left), and
        ``frontier`` (V, n) its frontier, m of travel (``inf`` where none binds it).
    schedule : VerifiedSchedule
        The undisturbed plan.
    position_margin : float
        The margin the executor's conflicts kept beyond the separation, metres.
    unapplied_faults : tuple of Fault
        The faults that never applied: due after the run had ended (every vehicle at its goal).
    method : str
        The timing method asked for the plan (its ``computed_by`` is the schedule's own, ``exact``
        after a fallback).
    plans : tuple of ExecutedPlan
        The plans the run drove, in order: the undisturbed one, then one per re-plan.
    idle_s : float
        Seconds every vehicle stood at its goal waiting for a new goal (a goal that came after a
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
    scenario: Scenario | GraphScenario,
    specs: Sequence[str],
    *,
    position_margin: float = 0.05,
    verified: VerifiedSchedule | None = None,
) -> tuple[Fault, ...]:
    """Parse ``--fault`` specs against a scenario (see :func:`~trajgen.execution.faults.parse_fault`).

    A jump may be as large as the position margin the executor keeps in this scenario
    (:func:`~trajgen.execution.goals.execution_margin`: at most ``position_margin``; with the plan
    at hand, ``verified``, what its closest approach leaves).
    """
    margin = execution_margin(scenario, position_margin, verified=verified)
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


def _time_limit(
    planned: float, faults: Sequence[Fault], limits: Limits, graph: StarGraph | TrackGraph
) -> float:
    """Simulated time after which the run counts as stuck, seconds."""
    slowest = min(v.max_velocity for v in limits.vehicles)
    for fault in faults:
        if fault.kind is FaultKind.SLOW:
            slowest = min(slowest, fault.value)
    total = graph.total_length
    crawl = limits.count * total * 2.0 / slowest  # every vehicle round the whole track twice
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
    observer: Callable[[Executor, tuple[VehicleState, ...], Command], None] | None = None,
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
    if verified is not None:
        require_verified(verified, "simulate")
        if verified.schedule.limits.count != scenario.limits.count:
            raise InputError(
                f"the plan handed to simulate moves {verified.schedule.limits.count} vehicles, the "
                f"scenario {scenario.limits.count}: expected a plan of the scenario's vehicles"
            )
    margin = execution_margin(scenario, position_margin, verified=verified)
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
    limits = scenario.limits
    horizon = _time_limit(verified.schedule.duration, faults, limits, scenario.track)
    pending = sorted((f for f in faults if f.kind in (FaultKind.JUMP, FaultKind.GOAL)), key=lambda f: f.time)
    spool = (
        Trace(verified.schedule.track, trace, verified.schedule.limits.count) if trace is not None else None
    )
    plot = Decimated(PLOT_SAMPLES)
    bodies = plant.bodies
    distance = SeparationWatch(scenario.track, bodies, limits.min_separation)
    commanded = LimitWatch(limits, verified.schedule.jerk_limited)
    ledger = PlanLedger(verified.schedule, executor.axis_signs)
    count = len(bodies)
    if spool is not None:
        spool.add(0.0, bodies)
    plot.add((0.0, *(b.v for b in bodies), distance.separation, *(0.0,) * count, *(math.inf,) * count))
    travel = (0.0,) * count  # along the plan's paths at the last cycle
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
            if executor.replans > len(ledger.plans):  # left for a new goal where every vehicle stood at rest
                ledger.replanned(t, travel, executor.schedule, executor.axis_signs)
            travel = executor.travel
            commanded.check(command.setpoints)
            before = distance.before()
            plant.advance(command, t)
            cycle += 1
            t = cycle * period
            now = distance.cycle(before, period)
            if spool is not None:
                spool.add(t, bodies)
            offset = ledger.offset
            plot.add(
                (
                    t,
                    *(b.v for b in bodies),
                    now,
                    *(o + p for o, p in zip(offset, travel, strict=True)),
                    *(o + f for o, f in zip(offset, command.frontiers, strict=True)),
                )
            )
            at_goals = command.mode is Mode.DONE and all(abs(b.v) <= _AT_REST for b in bodies)
            if at_goals and ledger.arrived is None:
                ledger.arrived = t
            # both at their goals: the run ends, also before a stop or slow-down that would come later
            if at_goals and not pending:
                makespan = t
                break
    except BaseException:
        if spool is not None:
            spool.close()
        raise
    rows = np.array(plot.rows) if plot.rows else np.zeros((0, 2 + 3 * count))
    samples = {
        "t": frozen(rows[:, 0].copy()),
        "speed": frozen(rows[:, 1 : 1 + count].T.copy()),
        "separation": frozen(rows[:, 1 + count].copy()),
        "travel": frozen(rows[:, 2 + count : 2 + 2 * count].T.copy()),
        "frontier": frozen(rows[:, 2 + 2 * count :].T.copy()),
    }
    reached = makespan is not None
    makespan = makespan if reached else t
    plans = ledger.finish(makespan)
    planned = sum(plan.planned_s for plan in plans)
    unapplied = tuple(f for f in faults if f.time > makespan + 1e-9)
    for fault in unapplied:
        logger.info("fault %s never applied: the run ended at %.3f s", fault.spec, makespan)
    result = SimulationResult(
        reached_goal=reached,
        makespan_s=makespan,
        planned_s=planned,
        time_lost_s=makespan - planned - ledger.idle,
        min_separation_m=distance.smallest,
        certified_separation_m=distance.certified,
        velocity_ratio=commanded.worst[0],
        acceleration_ratio=commanded.worst[1],
        jerk_ratio=commanded.worst[2],
        replans=executor.replans,
        rejected_goals=executor.rejected_goals,
        holds=executor.holds,
        emergency_brakes=executor.emergency_brakes,
        separation_violations=distance.violations,
        limit_violations=commanded.violations,
        events=tuple(executor.events),
        faults=tuple(faults),
        cycles=cycle,
        plot=samples,
        schedule=verified,
        position_margin=margin,
        unapplied_faults=unapplied,
        method=asked,
        plans=plans,
        idle_s=ledger.idle,
    )
    return result, spool
