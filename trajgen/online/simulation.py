"""Closed-loop simulation: the executor drives a simulated plant that applies faults.

The plant moves each vehicle along the track after its setpoints: it lands on
each setpoint while it is on track. Faults (:mod:`trajgen.online.faults`) act on the plant only;
the executor sees their effects through the measurements, and goal requests.
A drive that is off its setpoint (after a jump, a stop) closes the gap gradually:
its speed is the setpoint's plus twice the gap per second, at most
``0.2 * max_velocity`` more or less.

Every cycle the simulation checks the *true* positions against the minimum
separation, certified between cycles too (track distance is 1-Lipschitz in
each vehicle's position, so between two cycles it is at least the mean of the
two distances less half the distance both vehicles drove), and the commanded
setpoints against the vehicle limits. Memory does not grow with the simulated
time: the trace is spooled to temporary files a block of rows at a time and
the plot keeps at most :data:`PLOT_SAMPLES` samples per curve.
"""

from __future__ import annotations

import bisect
import collections
import logging
import math
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np

from limits import Limits
from topology import JUNCTION_INDEX, StarGraph
from topology.indexed import leg_travel
from topology.indexed import separation as indexed_separation
from trajgen.errors import InputError
from trajgen.export.csv import HEADER_NAMES, CsvOptions, format_rows
from trajgen.online.executor import Command, Event, Executor, Mode, VehicleState
from trajgen.online.faults import Fault, FaultError, FaultKind, parse_fault
from trajgen.online.goals import execution_margin, plan_for_execution
from trajgen.scenario import Scenario
from trajgen.schedule import ScheduleState, TimingMethod
from trajgen.values import frozen
from trajgen.verify import VerifiedSchedule

__all__ = ["PLOT_SAMPLES", "SimulationResult", "Trace", "parse_faults", "simulate"]

logger = logging.getLogger(__name__)

#: Most samples per curve kept for the plot.
PLOT_SAMPLES = 20_000
#: Rows formatted and spooled at a time.
_ROWS_PER_BLOCK = 5_000
#: How fast a drive closes a gap to its setpoint beyond the setpoints' own speed (fraction of max_velocity).
_CORRECTION = 0.2
#: How fast a drive closes a gap to its setpoint: the gap times this, m/s per m (a 0.5 s time constant).
_GAIN = 2.0
#: A vehicle slower than this is at rest, m/s (a drive closing its last gap creeps for a while).
_AT_REST = 1e-3
#: True track distance below the minimum separation that counts as a violation, metres (1 µm).
_VIOLATION_TOLERANCE = 1e-6
#: Relative tolerance on the commanded limits (Ruckig's jerk phases are exactly at the limit).
_LIMIT_TOLERANCE = 1e-6


class _Body:
    """One vehicle's true state in the plant."""

    __slots__ = ("a", "axis", "branch", "j", "leg", "orientation", "s", "v")

    def __init__(self, leg: int, s: float, orientation: int, axis: float, branch: int) -> None:
        self.leg, self.s, self.orientation, self.axis, self.branch = leg, s, orientation, axis, branch
        self.v = self.a = self.j = 0.0

    def move(self, d_axis: float, lengths: tuple[float, ...]) -> None:
        """Drive ``d_axis`` metres along the axis, through the junction onto ``branch``.

        The end of a leg (and the junction, when the branch is the same leg) stops the vehicle: it
        does not get further, and neither does its axis; it is then at rest.
        """
        s = self.s + self.orientation * d_axis
        blocked = 0.0
        if s < 0.0:
            if self.branch != self.leg:
                self.leg, self.orientation = self.branch, -self.orientation
                s = -s
            else:
                blocked, s = -s, 0.0
        top = lengths[self.leg]
        if s > top:
            blocked, s = s - top, top
        self.s = s
        self.axis += d_axis - math.copysign(blocked, d_axis)
        if blocked:
            self.v = self.a = 0.0

    def state(self) -> VehicleState:
        return VehicleState(self.leg if self.s > 0.0 else JUNCTION_INDEX, self.s, self.v, self.a)


class _Lag:
    """Setpoints of one vehicle kept long enough to replay them late."""

    __slots__ = ("items", "times")

    def __init__(self, size: int) -> None:
        self.times: collections.deque = collections.deque(maxlen=size)
        self.items: collections.deque = collections.deque(maxlen=size)

    def push(self, time: float, setpoint) -> None:
        self.times.append(time)
        self.items.append(setpoint)

    def at(self, time: float):
        """Axis, velocity, acceleration, branch at ``time`` (linear between kept setpoints)."""
        times = list(self.times)
        k = bisect.bisect_right(times, time) - 1
        if k < 0:
            first = self.items[0]
            return first.axis, first.velocity, first.acceleration, first.branch
        if k >= len(times) - 1:
            last = self.items[-1]
            return last.axis, last.velocity, last.acceleration, last.branch
        a, b = self.items[k], self.items[k + 1]
        w = (time - times[k]) / (times[k + 1] - times[k])
        return (
            a.axis + w * (b.axis - a.axis),
            a.velocity + w * (b.velocity - a.velocity),
            a.acceleration + w * (b.acceleration - a.acceleration),
            a.branch,
        )


class _Plant:
    """Both vehicles' true motion under setpoints and faults."""

    def __init__(self, executor: Executor, faults: Sequence[Fault], period: float) -> None:
        self.lengths = executor.graph.lengths
        self.period = period
        self.limits = executor.limits
        self.bodies = []
        for path in executor.paths:
            leg, s = path.locate(0.0)
            if path.legs:
                leg = path.legs[0]
                orientation = path.outward(0.0) * path.heading(0.0)
            else:
                leg = leg if leg != JUNCTION_INDEX else 0
                orientation = 1
            self.bodies.append(_Body(leg, s, orientation, path.axis(0.0), leg))
        self.faults = list(faults)
        size = math.ceil(0.25 / period) + 4
        self.lags = (_Lag(size), _Lag(size))

    def measure(self) -> tuple[VehicleState, VehicleState]:
        return self.bodies[0].state(), self.bodies[1].state()

    def _active(self, kind: FaultKind, vehicle: int, t: float) -> Fault | None:
        found = None
        for fault in self.faults:
            if fault.kind is kind and fault.vehicle == vehicle and fault.time <= t < fault.end:
                found = fault
        return found

    def jump(self, fault: Fault) -> None:
        self.bodies[fault.vehicle].move(fault.value, self.lengths)

    def advance(self, command: Command, t: float) -> None:
        """Move both vehicles from ``t`` to ``t + period`` after ``command``."""
        dt = self.period
        for v, (body, setpoint) in enumerate(zip(self.bodies, command.setpoints, strict=True)):
            self.lags[v].push(command.time, setpoint)
            stop = self._active(FaultKind.STOP, v, t)
            if stop is not None or command.emergency:  # a stop fault, or the executor's emergency brake
                decel = self.limits.vehicles[v].emergency_braking
                speed = abs(body.v)
                new = max(speed - decel * dt, 0.0)
                d = math.copysign(
                    0.5 * (speed + new) * dt if new > 0.0 else speed * speed / (2 * decel), body.v
                )
                a_new = -math.copysign(decel, body.v) if speed > 0.0 else 0.0
                body.j = (a_new - body.a) / dt
                body.a = a_new
                body.v = math.copysign(new, body.v)
                body.move(d, self.lengths)
                continue
            lag = self._active(FaultKind.LAG, v, t)
            if lag is not None:
                delay = min(lag.value, 0.5 * (t + dt - lag.time))
                axis, velocity, acceleration, branch = self.lags[v].at(t + dt - delay)
                jerk = setpoint.jerk
            else:
                axis, velocity, acceleration, jerk, branch = (
                    setpoint.axis,
                    setpoint.velocity,
                    setpoint.acceleration,
                    setpoint.jerk,
                    setpoint.branch,
                )
            body.branch = branch
            slow = self._active(FaultKind.SLOW, v, t)
            cap = slow.value if slow is not None else math.inf  # a throttled drive's top speed
            wanted = axis - body.axis
            gap = wanted - velocity * dt  # beyond the setpoint's own motion this cycle
            on_track = abs(gap) <= abs(acceleration) * dt * dt + abs(jerk) * dt**3 + 1e-12
            if on_track and abs(velocity) <= cap:
                body.j, body.a, body.v = jerk, acceleration, velocity
                body.move(wanted, self.lengths)
                continue
            # off its setpoint (after a fault) or throttled: the drive closes the gap gradually,
            # within its top speed, and never runs past the setpoint
            correction = _CORRECTION * self.limits.vehicles[v].max_velocity
            v_new = velocity + max(-correction, min(correction, _GAIN * gap))
            v_new = max(-cap, min(cap, v_new))
            step = v_new * dt
            if wanted * (wanted - step) < 0.0:
                step, v_new = wanted, min(max(velocity, -cap), cap)
            a_new = (v_new - body.v) / dt
            body.j = (a_new - body.a) / dt
            body.a, body.v = a_new, v_new
            body.move(step, self.lengths)


class Trace:
    """The executed motion (true positions) of both vehicles, spooled to temporary files as CSV rows.

    Parameters
    ----------
    graph : StarGraph
    options : CsvOptions
        Dialect of the rows (the sample period is the simulation's control period).
    """

    def __init__(self, graph: StarGraph, options: CsvOptions) -> None:
        self.graph = graph
        self.options = options
        self._files = [tempfile.TemporaryFile(), tempfile.TemporaryFile()]  # noqa: SIM115 - closed by close()
        header = (options.delimiter.join(HEADER_NAMES[options.units]) + "\r\n").encode("ascii")
        for handle in self._files:
            handle.write(header)
        self._rows: list[list[float]] = []
        self.rows = 0

    def add(self, t: float, bodies) -> None:
        """Record both vehicles' true state at time ``t``."""
        row = [t]
        for body in bodies:
            row.extend(
                (body.axis, body.v, body.a, body.j, body.leg if body.s > 0.0 else JUNCTION_INDEX, body.s)
            )
        self._rows.append(row)
        self.rows += 1
        if len(self._rows) >= _ROWS_PER_BLOCK:
            self._flush()

    def _flush(self) -> None:
        if not self._rows:
            return
        data = np.array(self._rows)
        self._rows = []
        t = data[:, 0]
        columns = {
            name: np.stack([data[:, 1 + 6 * v + k] for v in (0, 1)])
            for k, name in enumerate(("axis", "velocity", "acceleration", "jerk", "leg", "s"))
        }
        state = ScheduleState(
            t,
            columns["axis"],
            columns["velocity"],
            columns["acceleration"],
            columns["jerk"],
            columns["leg"].astype(int),
            columns["s"],
        )
        for v, handle in enumerate(self._files):
            lines = format_rows(self.graph, state, v, self.options)
            handle.write(("\r\n".join(lines) + "\r\n").encode("ascii"))

    def chunks(self, vehicle: int) -> Iterator[bytes]:
        """The CSV of ``vehicle`` (0 or 1), a block at a time."""
        self._flush()
        handle = self._files[vehicle]
        handle.seek(0)
        while block := handle.read(1 << 20):
            yield block

    def close(self) -> None:
        """Remove the temporary files."""
        for handle in self._files:
            handle.close()


class _Decimated:
    """At most ``limit`` samples of a run of any length: every other sample is dropped when full."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.stride = 1
        self.count = 0
        self.rows: list[tuple] = []

    def add(self, row: tuple) -> None:
        if self.count % self.stride == 0:
            self.rows.append(row)
            if len(self.rows) >= self.limit:
                self.rows = self.rows[::2]
                self.stride *= 2
        self.count += 1


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
        Duration of the undisturbed schedule, seconds.
    time_lost_s : float
        ``makespan_s - planned_s``.
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
        ``separation`` (n,) m, ``travel`` (2, n) each vehicle's travel along its path, m, and
        ``frontier`` (2, n) its frontier, m of travel (``inf`` where none binds it).
    schedule : VerifiedSchedule
        The undisturbed plan.
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

    @property
    def violations(self) -> int:
        """Separation and limit violations together (must be 0)."""
        return self.separation_violations + self.limit_violations

    def summary(self) -> dict:
        """JSON-ready summary."""
        return {
            "reached_goal": self.reached_goal,
            "makespan_s": round(self.makespan_s, 6),
            "planned_s": round(self.planned_s, 6),
            "time_lost_s": round(self.time_lost_s, 6),
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
            "events": [{"t_s": round(e.time, 6), "kind": e.kind, "detail": e.detail} for e in self.events],
        }


def parse_faults(
    scenario: Scenario, specs: Sequence[str], *, position_margin: float = 0.05
) -> tuple[Fault, ...]:
    """Parse ``--fault`` specs against a scenario (see :func:`~trajgen.online.faults.parse_fault`).

    A jump may be as large as the position margin the executor keeps in this scenario
    (:func:`~trajgen.online.executor.execution_margin`: at most ``position_margin``).
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


def _time_limit(planned: float, faults: Sequence[Fault], limits: Limits, graph: StarGraph) -> float:
    """Simulated time after which the run counts as stuck, seconds."""
    slowest = min(v.max_velocity for v in limits.vehicles)
    for fault in faults:
        if fault.kind is FaultKind.SLOW:
            slowest = min(slowest, fault.value)
    crawl = 2.0 * sum(graph.lengths) * 2.0 / slowest  # both vehicles round the whole track twice
    latest = max((f.time + (f.value if f.kind is FaultKind.STOP else 0.0) for f in faults), default=0.0)
    return latest + 3.0 * planned + crawl + 60.0


def simulate(
    scenario: Scenario,
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
        The plan, if already computed for ``scenario`` (:func:`~trajgen.online.executor.plan_for_execution`).
    observer : callable, optional
        Called every cycle with the executor, the measured states and the command (for tests and tools).

    Returns
    -------
    SimulationResult, Trace or None
        The trace's temporary files are closed by ``Trace.close``.
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"simulate expects a Scenario, got {type(scenario).__name__}")
    margin = execution_margin(scenario, position_margin)
    for fault in faults:
        if not isinstance(fault, Fault):
            raise InputError(f"faults must be Fault objects (parse_faults), got {type(fault).__name__}")
        if fault.kind is FaultKind.JUMP and abs(fault.value) > margin:
            raise FaultError(
                f"fault {fault.spec!r}: jump beyond the position margin {margin!r} m kept in this scenario"
            )
    if verified is None:
        verified = plan_for_execution(scenario, method=method, position_margin=position_margin)
    executor = Executor(
        verified, period=period, position_margin=margin, min_separation=scenario.limits.min_separation
    )
    plant = _Plant(executor, faults, period)
    jerk_limited = verified.schedule.jerk_limited
    limits = scenario.limits
    planned = verified.schedule.duration
    horizon = _time_limit(planned, faults, limits, scenario.track)
    pending = sorted((f for f in faults if f.kind in (FaultKind.JUMP, FaultKind.GOAL)), key=lambda f: f.time)
    settle = max((f.time + (f.value if f.kind is FaultKind.STOP else 0.0) for f in faults), default=0.0)
    spool = Trace(scenario.track, trace) if trace is not None else None
    plot = _Decimated(PLOT_SAMPLES)
    worst = [0.0, 0.0, 0.0]
    separation_violations = limit_violations = 0
    bodies = plant.bodies
    separation = indexed_separation((bodies[0].leg, bodies[0].s, bodies[1].leg, bodies[1].s))
    smallest = certified = separation
    required = limits.min_separation
    if spool is not None:
        spool.add(0.0, bodies)
    plot.add((0.0, bodies[0].v, bodies[1].v, separation, 0.0, 0.0, math.inf, math.inf))
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
            command = executor.step(*measured)
            if observer is not None:
                observer(executor, measured, command)
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
            before = [(b.leg, b.s, b.a, b.v, b.orientation) for b in bodies]
            plant.advance(command, t)
            cycle += 1
            t = cycle * period
            now = indexed_separation((bodies[0].leg, bodies[0].s, bodies[1].leg, bodies[1].s))
            # how far the motions (acceleration between its values at the two cycles) leave their chords
            bend = (
                sum(max(abs(old[2]), abs(b.a)) for old, b in zip(before, bodies, strict=True))
                * period**2
                / 8.0
            )
            between = _between(before, bodies, separation, now, bend)
            smallest = min(smallest, now)
            certified = min(certified, now, between)
            if min(now, between) < required - _VIOLATION_TOLERANCE:
                separation_violations += 1
            separation = now
            if spool is not None:
                spool.add(t, bodies)
            plot.add((t, bodies[0].v, bodies[1].v, now, *executor.travel, *command.frontiers))
            done = (
                command.mode is Mode.DONE
                and not pending
                and t >= settle
                and all(abs(b.v) <= _AT_REST for b in bodies)
            )
            if done:
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
    result = SimulationResult(
        reached_goal=reached,
        makespan_s=makespan,
        planned_s=planned,
        time_lost_s=makespan - planned,
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
    )
    return result, spool
