"""The simulated plant: every vehicle's true motion after the executor's setpoints, under faults.

Each vehicle moves along the track after its setpoints: it lands on each
setpoint while it is on track, passes the junction onto the leg the setpoint
names (on a track graph: a node onto the edge the setpoint is on or names next),
and is stopped by the end of a leg. Faults
(:mod:`trajgen.execution.faults`) act here only; the executor sees their effects
through the measurements. A stop (or the executor's emergency brake) brakes at
the vehicle's emergency deceleration (the brake engages within a cycle); every
other change of speed is the drive's, within its ``max_acceleration`` and never
beyond ``max_velocity``: a drive released from a stop, slowed by a cap, or off
its setpoint (after a jump, a stop) ramps; off its setpoint it closes the gap
gradually, aiming for the setpoint's speed plus twice the gap per second, at
most ``0.2 * max_velocity`` more or less. The one exception is a lag: a lagging
drive replays its setpoints late as a delay line, their steps included (released
from a stop, it ramps too).
"""

from __future__ import annotations

import bisect
import collections
import math
from collections.abc import Sequence

from topology import JUNCTION_INDEX, TrackGraph
from trajgen.execution.executor import Executor
from trajgen.execution.faults import Fault, FaultKind
from trajgen.execution.messages import Command, VehicleState
from trajgen.model.graph_vehicle_path import GraphVehiclePath

__all__ = ["Body", "GraphBody", "Plant"]

#: How fast a drive closes a gap to its setpoint beyond the setpoints' own speed (fraction of max_velocity).
_CORRECTION = 0.2
#: How fast a drive closes a gap to its setpoint: the gap times this, m/s per m (a 0.5 s time constant).
_GAIN = 2.0


class Body:
    """One vehicle's true state in the plant."""

    __slots__ = ("a", "axis", "braked", "branch", "j", "leg", "orientation", "ramping", "s", "v")

    def __init__(self, leg: int, s: float, orientation: int, axis: float, branch: int) -> None:
        self.leg, self.s, self.orientation, self.axis, self.branch = leg, s, orientation, axis, branch
        self.v = self.a = self.j = 0.0
        self.ramping = False  # off its setpoints: closing the gap within the limits
        self.braked = False  # released from a brake and not yet back on its setpoints

    def move(self, d_axis: float, lengths: tuple[float, ...]) -> None:
        """Drive ``d_axis`` metres along the axis, through the junction onto ``branch``.

        The end of a leg (and the junction, when the branch is the same leg) stops the vehicle: it
        does not get further, and neither does its axis; it is then at rest.
        """
        if self.s <= 0.0 and d_axis != 0.0 and self.branch != JUNCTION_INDEX:
            # at the junction every move leaves it, onto the branch: the axis sign there is a convention
            self.leg, self.orientation = self.branch, (1 if d_axis > 0.0 else -1)
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

    def steer(self, setpoint) -> None:
        """Take the leg ``setpoint`` names for the next pass through the junction."""
        if setpoint.branch != JUNCTION_INDEX:  # a path that never moves, parked at the junction, names no leg
            self.branch = setpoint.branch

    def state(self) -> VehicleState:
        """What the vehicle's sensors measure: its true state."""
        return VehicleState(self.leg if self.s > 0.0 else JUNCTION_INDEX, self.s, self.v, self.a)


class GraphShape:
    """A track graph's edge lengths and end nodes as plain tuples, for the plant's every cycle."""

    __slots__ = ("ends", "lengths")

    def __init__(self, track: TrackGraph) -> None:
        self.lengths = tuple(track.length(k) for k in range(track.edge_count))
        self.ends = tuple(track.ends(k) for k in range(track.edge_count))


class GraphBody:
    """One vehicle's true state on a track graph: ``leg`` is its edge, ``s`` metres from its ``from`` node.

    ``orientation`` is ``ds / d axis`` on its edge. At a node it passes onto the edge its setpoint
    is on, or else the branch its setpoint names; with neither (a reversal, a dead end) the node
    stops it.
    """

    __slots__ = ("a", "ahead", "axis", "braked", "j", "leg", "orientation", "ramping", "s", "v")

    def __init__(self, edge: int, s: float, orientation: int, axis: float) -> None:
        self.leg, self.s, self.orientation, self.axis = edge, s, orientation, axis
        self.ahead = (edge, edge)
        self.v = self.a = self.j = 0.0
        self.ramping = False  # off its setpoints: closing the gap within the limits
        self.braked = False  # released from a brake and not yet back on its setpoints

    def steer(self, setpoint) -> None:
        """Take the edges ``setpoint`` is on and names next, for the next node it passes."""
        self.ahead = (setpoint.leg, setpoint.branch)

    def move(self, d_axis: float, shape: GraphShape) -> None:
        """Drive ``d_axis`` metres along the axis, through a node onto the edge it is steered to."""
        s = self.s + self.orientation * d_axis
        top = shape.lengths[self.leg]
        blocked = 0.0
        if s < 0.0 or s > top:
            start, end = shape.ends[self.leg]
            node, past = (start, -s) if s < 0.0 else (end, s - top)
            onto = next((e for e in self.ahead if e != self.leg and node in shape.ends[e]), None)
            if onto is None:
                blocked, s = past, min(max(s, 0.0), top)
            else:
                here = 1 if start == node else -1
                there = 1 if shape.ends[onto][0] == node else -1
                self.leg, self.orientation = onto, -self.orientation * here * there
                length = shape.lengths[onto]
                if past > length:  # beyond the next edge too within one cycle: stopped at its end
                    blocked, past = past - length, length
                s = past if there > 0 else length - past
        self.s = s
        self.axis += d_axis - math.copysign(blocked, d_axis)
        if blocked:
            self.v = self.a = 0.0

    def state(self) -> VehicleState:
        """What the vehicle's sensors measure: its true state."""
        return VehicleState(self.leg, self.s, self.v, self.a)


class Lag:
    """Setpoints of one vehicle kept long enough to replay them late."""

    __slots__ = ("items", "times")

    def __init__(self, size: int) -> None:
        self.times: collections.deque = collections.deque(maxlen=size)
        self.items: collections.deque = collections.deque(maxlen=size)

    def push(self, time: float, setpoint) -> None:
        self.times.append(time)
        self.items.append(setpoint)

    def at(self, time: float):
        """Axis, velocity, acceleration at ``time``, and the setpoint before it (which steers).

        Linear between the kept setpoints.
        """
        times = list(self.times)
        k = bisect.bisect_right(times, time) - 1
        if k < 0:
            first = self.items[0]
            return first.axis, first.velocity, first.acceleration, first
        if k >= len(times) - 1:
            last = self.items[-1]
            return last.axis, last.velocity, last.acceleration, last
        a, b = self.items[k], self.items[k + 1]
        w = (time - times[k]) / (times[k + 1] - times[k])
        return (
            a.axis + w * (b.axis - a.axis),
            a.velocity + w * (b.velocity - a.velocity),
            a.acceleration + w * (b.acceleration - a.acceleration),
            a,
        )


class Plant:
    """Every vehicle's true motion under setpoints and faults."""

    def __init__(self, executor: Executor, faults: Sequence[Fault], period: float) -> None:
        self.period = period
        self.limits = executor.limits
        self.faults = list(faults)
        size = math.ceil(0.25 / period) + 4
        self.lags = tuple(Lag(size) for _ in range(executor.limits.count))
        if isinstance(executor.graph, TrackGraph):
            self.lengths = GraphShape(executor.graph)
            self.bodies = [_graph_body(path) for path in executor.paths]
            return
        self.lengths = executor.graph.lengths
        self.bodies = []
        for path in executor.paths:
            leg, s = path.locate(0.0)
            if path.legs:
                leg = path.legs[0]
                orientation = path.outward(0.0) * path.heading(0.0)
            else:
                leg = leg if leg != JUNCTION_INDEX else 0
                orientation = path.home_orientation
            self.bodies.append(Body(leg, s, orientation, path.axis(0.0), leg))

    def measure(self) -> tuple[VehicleState, ...]:
        """Every vehicle's measured state."""
        return tuple(body.state() for body in self.bodies)

    def _active(self, kind: FaultKind, vehicle: int, t: float) -> Fault | None:
        found = None
        for fault in self.faults:
            if fault.kind is kind and fault.vehicle == vehicle and fault.time <= t < fault.end:
                found = fault
        return found

    def jump(self, fault: Fault) -> None:
        """Apply a position correction: the vehicle is ``fault.value`` metres further along its axis."""
        self.bodies[fault.vehicle].move(fault.value, self.lengths)

    def advance(self, command: Command, t: float) -> None:
        """Move every vehicle from ``t`` to ``t + period`` after ``command``."""
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
                a_new = -math.copysign(decel, body.v) if new > 0.0 else 0.0  # at rest the brake holds
                body.j = (a_new - body.a) / dt
                body.a = a_new
                body.v = math.copysign(new, body.v)
                body.ramping = body.braked = True  # released, it takes up its setpoints within its limits
                body.move(d, self.lengths)
                continue
            lag = self._active(FaultKind.LAG, v, t)
            if lag is not None:
                delay = min(lag.value, 0.5 * (t + dt - lag.time))
                axis, velocity, acceleration, steering = self.lags[v].at(t + dt - delay)
                jerk = setpoint.jerk
            else:
                axis, velocity, acceleration, jerk, steering = (
                    setpoint.axis,
                    setpoint.velocity,
                    setpoint.acceleration,
                    setpoint.jerk,
                    setpoint,
                )
            body.steer(steering)
            slow = self._active(FaultKind.SLOW, v, t)
            cap = slow.value if slow is not None else math.inf  # a throttled drive's top speed
            wanted = axis - body.axis
            gap = wanted - velocity * dt  # beyond the setpoint's own motion this cycle
            vehicle = self.limits.vehicles[v]
            if body.ramping:
                # back on its setpoints where it takes them up within its acceleration limit (the gap
                # and the speed each within half a cycle's reach): else a drive creeping after a
                # vanishing gap would stay off them for ever
                on_track = (
                    abs(gap) <= 0.25 * vehicle.max_acceleration * dt * dt
                    and abs(velocity - body.v) <= 0.5 * vehicle.max_acceleration * dt
                )
            else:
                on_track = abs(gap) <= abs(acceleration) * dt * dt + abs(jerk) * dt**3 + 1e-12
            if on_track and abs(velocity) <= cap:
                body.j, body.a, body.v = jerk, acceleration, velocity
                body.ramping = body.braked = False
                body.move(wanted, self.lengths)
                continue
            # a lag replays its setpoints as they come; released from a brake, the drive ramps
            limited = lag is None or body.braked
            self._ramp(v, body, wanted, velocity, cap, limited=limited)

    def _ramp(
        self, v: int, body: Body | GraphBody, wanted: float, velocity: float, cap: float, *, limited: bool
    ) -> None:
        """The drive off its setpoint, or throttled: it closes the gap, its acceleration within its limit.

        The speed it aims for is the setpoint's plus twice the gap per second (at most
        ``0.2 * max_velocity`` more or less), never beyond ``max_velocity`` or ``cap``; its speed
        changes toward that at most ``max_acceleration`` (a drive's current limit: its acceleration
        steps, its jerk is not limited), and it never runs past the setpoint: a step that would
        ends on it, at the speed nearest the setpoint's it can reach. It is back on its setpoints
        (:meth:`advance`) once it is within half a cycle's reach of them in position and speed.
        Not ``limited``: a lagging drive replaying its late setpoints as a delay line takes their
        speeds as they come.
        """
        dt = self.period
        vehicle = self.limits.vehicles[v]
        reach = vehicle.max_acceleration * dt if limited else math.inf
        top = min(cap, vehicle.max_velocity)
        gap = wanted - velocity * dt
        correction = _CORRECTION * vehicle.max_velocity
        aim = max(-top, min(top, velocity + max(-correction, min(correction, _GAIN * gap))))
        v_new = max(body.v - reach, min(body.v + reach, aim))
        step = 0.5 * (body.v + v_new) * dt
        if wanted * (wanted - step) < 0.0:  # it would pass its setpoint: it stops there
            step, v_new = wanted, max(body.v - reach, min(body.v + reach, max(-top, min(top, velocity))))
        a_new = (v_new - body.v) / dt
        body.ramping = True
        body.j = (a_new - body.a) / dt
        body.a, body.v = a_new, v_new
        body.move(step, self.lengths)


def _graph_body(path: GraphVehiclePath) -> GraphBody:
    """A vehicle at the start of its path on a track graph, its axis as the path's."""
    if not path.edges:
        edge, s = path.home
        return GraphBody(edge, s, path.home_orientation, path.axis(0.0))
    orientation = (1 if path.s_to[0] > path.s_from[0] else -1) * path.headings[0]
    return GraphBody(path.edges[0], path.s_from[0], orientation, path.axis(0.0))
