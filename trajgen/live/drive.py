"""A simulated vehicle's motion along the order it holds: Ruckig, cycle by cycle, to rest at its next stop.

:class:`Drive` knows the driven path (:class:`~trajgen.live.driven_path.DrivenPath`), where the vehicle
is on it (arc length, velocity, acceleration) and which node it passed last. Each cycle Ruckig takes
it, time-optimally under its limits, towards rest at its next stop: the next reversal, its decision
point, or, once its order is cancelled, the first node of its base it can come to rest at.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from limits import VehicleLimits
from trajgen.live.driven_path import NODE_TOLERANCE, DrivenPath

__all__ = ["AT_REST", "Drive", "VehicleSnapshot"]

logger = logging.getLogger(__name__)

#: Slower than this is at rest, m/s.
AT_REST = 1e-6


@dataclass(frozen=True, slots=True)
class VehicleSnapshot:
    """Where a simulated vehicle truly is (not what it reported).

    Attributes
    ----------
    time : float
        Seconds of the run.
    x, y : float
        Metres, map coordinates (NaN where its orders give none).
    velocity : float
        Along its path, m/s (>= 0).
    last_node : int
        How many nodes of its current order it has passed (0: at its first node).
    finished : bool
        At rest at the last node of an order with no horizon left.
    node, next_node : str
        The ids of the last node it passed (its start node before any order) and of the next
        (``""`` at the end of its order).
    along : float
        Metres driven past ``node`` towards ``next_node``.
    """

    time: float
    x: float
    y: float
    velocity: float
    last_node: int
    finished: bool
    node: str = ""
    next_node: str = ""
    along: float = 0.0


class Drive:
    """The motion of one vehicle along the path of its order.

    Parameters
    ----------
    limits : VehicleLimits
        Its velocity, acceleration and jerk limits (SI).
    period : float
        Its control cycle, seconds.
    who : str
        The vehicle in messages.
    """

    def __init__(self, limits: VehicleLimits, period: float, *, who: str) -> None:
        from ruckig import InputParameter, OutputParameter, Ruckig

        self.limits = limits
        self.period = period
        self.who = who
        self._otg = Ruckig(1, period)
        self._input = InputParameter(1)
        self._output = OutputParameter(1)
        self._input.max_velocity = [limits.max_velocity]
        self._input.max_acceleration = [limits.max_acceleration]
        self._input.max_jerk = [limits.max_jerk]
        #: arc length along the path (m), velocity (m/s), acceleration (m/s²)
        self.p = self.v = self.a = 0.0
        #: the path of the order it holds; ``None``: no order
        self.path: DrivenPath | None = None
        #: the index of the last node it passed
        self.last = 0
        #: the arc length a cancelled order stops at; ``None``: not cancelled
        self.cancel_at: float | None = None

    def take(self, path: DrivenPath) -> None:
        """A new order's path, driven from rest at its first node."""
        self.path, self.last, self.cancel_at = path, 0, None
        self.p = self.v = self.a = 0.0

    def clear(self) -> None:
        """No order any more (a cancelled one, once the vehicle stands)."""
        self.path, self.last, self.cancel_at = None, 0, None
        self.p = self.v = self.a = 0.0

    @property
    def at_rest(self) -> bool:
        """Whether it stands."""
        return abs(self.v) <= AT_REST

    def next_stop(self) -> float:
        """Where it is to come to rest next: a reversal, its decision point, or its cancelled order's node."""
        path = self.path
        if self.cancel_at is not None:
            return self.cancel_at
        end = path.base_end
        k = self.last + 1
        while k < end and not path.reversal(k):
            k += 1
        return path.arcs[max(min(k, end), self.last)]

    def cancel(self) -> float:
        """Stop at the first node of its base it can come to rest at, braking now; that node's arc length."""
        from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory

        path = self.path
        brake = InputParameter(1)
        brake.control_interface = ControlInterface.Velocity
        brake.current_position, brake.current_velocity = [self.p], [self.v]
        brake.current_acceleration = [self.a]
        brake.target_velocity, brake.target_acceleration = [0.0], [0.0]
        brake.max_velocity = [self.limits.max_velocity]
        brake.max_acceleration = [self.limits.max_acceleration]
        brake.max_jerk = [self.limits.max_jerk]
        trajectory = Trajectory(1)
        rest = self.p
        if Ruckig(1).calculate(brake, trajectory) == Result.Working:
            rest = trajectory.at_time(trajectory.duration)[0][0]
        end = path.base_end
        k = next((k for k in range(self.last, end + 1) if path.arcs[k] >= rest - NODE_TOLERANCE), end)
        self.cancel_at = path.arcs[k]
        return self.cancel_at

    def step(self, *, held: bool) -> bool:
        """One control cycle (``held``: a fault stops it); whether it passed a node."""
        from ruckig import ControlInterface, Result

        path = self.path
        if path is None:
            return False
        inp = self._input
        inp.current_position = [self.p]
        inp.current_velocity = [self.v]
        inp.current_acceleration = [self.a]
        inp.target_velocity = [0.0]
        inp.target_acceleration = [0.0]
        if held:
            inp.control_interface = ControlInterface.Velocity
        else:
            inp.control_interface = ControlInterface.Position
            inp.target_position = [self.next_stop()]
        result = self._otg.update(inp, self._output)
        if result not in (Result.Working, Result.Finished):
            logger.error("vehicle %s: Ruckig failed (%s); braking", self.who, result)
            self.v = max(0.0, self.v - self.limits.max_acceleration * self.period)
            self.a = 0.0
        else:
            out = self._output
            self.p, self.v, self.a = out.new_position[0], out.new_velocity[0], out.new_acceleration[0]
        passed = False
        end = path.base_end
        while self.last < end and self.p >= path.arcs[self.last + 1] - NODE_TOLERANCE:
            self.last += 1
            passed = True
        return passed

    @property
    def cancelled_and_standing(self) -> bool:
        """Whether its order is cancelled and it stands at the node it stops at."""
        return self.cancel_at is not None and self.at_rest and self.p >= self.cancel_at - NODE_TOLERANCE

    def progress(self, start_node: str, *, base_request: float) -> dict:
        """Where it is on its order, as a VDA 5050 state says it (fields of vda5050-sdk's ``State``).

        ``lastNodeId`` and ``lastNodeSequenceId``, the nodes and edges still ahead, the distance since
        the last node, and ``newBaseRequest`` (closer than ``base_request`` metres to its decision
        point, with unreleased nodes left). Without an order: ``start_node``, sequence 0, nothing ahead.
        """
        path, passed = self.path, self.last
        if path is None:
            return {
                "last_node_id": start_node,
                "last_node_sequence_id": 0,
                "node_states": [],
                "edge_states": [],
                "new_base_request": False,
                "distance_since_last_node": 0.0,
            }
        last = path.nodes[passed]
        return {
            "last_node_id": last.node_id,
            "last_node_sequence_id": last.sequence_id,
            "node_states": [
                {"node_id": n.node_id, "sequence_id": n.sequence_id, "released": n.released}
                for n in path.nodes[passed + 1 :]
            ],
            "edge_states": [
                {"edge_id": e.edge_id, "sequence_id": e.sequence_id, "released": e.released}
                for e in path.edges[passed:]
            ],
            "new_base_request": any(not n.released for n in path.nodes)
            and path.arcs[path.base_end] - self.p < base_request,
            "distance_since_last_node": max(0.0, self.p - path.arcs[passed]),
        }

    def finished(self) -> bool:
        """At rest at the last node of an order with everything released (its goal)."""
        path = self.path
        return (
            path is not None
            and self.last == len(path.nodes) - 1
            and all(node.released for node in path.nodes)
            and self.at_rest
        )
