"""A simulated VDA 5050 vehicle: takes orders by the protocol's rules and drives its base with Ruckig.

It accepts, ignores or rejects each order and order update by the decision
chain of VDA 5050's figure 8 (vda5050-sdk's ``OrderAcceptancePolicy``); a
rejection shows as an error in its state. It drives only on its base: Ruckig
takes it, time-optimally under its own limits, to rest at its decision point
(or at a reversal on the way), and re-plans every cycle as the base grows. It
publishes ``state`` at a fixed rate and at once on every event (a node
reached, an order taken or refused), and ``connection`` ONLINE, retained, with
a last will of CONNECTIONBROKEN.

Positions are the order's node positions (metres, the map's x/y), interpolated
along each edge: the vehicle knows no more of the track than its orders say.
Where an order gives no position (a track graph without coordinates, a curved
edge) it drives by the edges' ``length`` and reports where it is by its last
node and ``distanceSinceLastNode`` alone, as a line-guided vehicle does
(:mod:`trajgen.live.driven_path`).
"""

from __future__ import annotations

import contextlib
import logging
import math
import queue
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from limits import VehicleLimits
from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.live.clock import RunClock
from trajgen.live.driven_path import NODE_TOLERANCE, DrivenPath
from trajgen.live.faults import StopFault
from trajgen.live.link import BrokerLink
from trajgen.live.mqtt import BrokerSettings, Topic, VehicleIdentity, make_client

__all__ = ["SimulatedVehicle", "StopFault", "VehicleSnapshot"]

logger = logging.getLogger(__name__)

#: Slower than this is at rest, m/s.
AT_REST = 1e-6
#: How far ahead of its decision point the vehicle asks for more base (``newBaseRequest``), metres.
_BASE_REQUEST_DISTANCE = 2.0
#: Wall seconds the drive loop sleeps between its catch-ups.
_LOOP_SLEEP_S = 0.004


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


class SimulatedVehicle:
    """A VDA 5050 vehicle simulated in this process, on an MQTT broker.

    Parameters
    ----------
    identity : VehicleIdentity
    limits : VehicleLimits
        Its own velocity, acceleration and jerk limits (SI).
    start : (float, float) or None
        Where it stands, metres (map x, y); ``None``: a line-guided vehicle that knows its node only.
    broker : BrokerSettings
    clock : RunClock, optional
        The run's clock (shared with others in the process to compare their times).
    state_rate : float
        ``state`` messages per second of the run, besides those on events (default 10).
    period : float
        Control cycle, seconds of the run (default 0.02).
    faults : sequence of StopFault
    map_id : str
        ``agvPosition.mapId`` (default ``"trajgen"``).
    record : bool
        Keep a :class:`VehicleSnapshot` of every cycle (:attr:`trace`; for tests: it grows with the run).
    observer : callable, optional
        Called with each cycle's :class:`VehicleSnapshot` (in the vehicle's thread).
    start_node : str, optional
        The id of the node it stands at (its ``lastNodeId`` until its first order; ``""``: none).
    """

    def __init__(
        self,
        identity: VehicleIdentity,
        limits: VehicleLimits,
        start: tuple[float, float] | None,
        *,
        broker: BrokerSettings,
        clock: RunClock | None = None,
        state_rate: float = 10.0,
        period: float = 0.02,
        faults: Sequence[StopFault] = (),
        map_id: str = "trajgen",
        record: bool = False,
        observer: Callable[[VehicleSnapshot], None] | None = None,
        start_node: str = "",
    ) -> None:
        from ruckig import InputParameter, OutputParameter, Ruckig

        if not isinstance(state_rate, int | float) or not 0.1 <= state_rate <= 100.0:
            raise InputError(f"state rate {short_repr(state_rate)} Hz is out of range: expected 0.1 to 100")
        if not isinstance(period, int | float) or not 0.001 <= period <= 0.1:
            raise InputError(f"control period {short_repr(period)} s is out of range: expected 0.001 to 0.1")
        self.identity = identity
        self.limits = limits
        self.clock = clock if clock is not None else RunClock()
        self.state_rate = float(state_rate)
        self.period = float(period)
        self.faults = tuple(faults)
        self._first_order: float | None = None  # its time when it took its first order: faults count from it
        self.map_id = map_id
        self.record = record
        self.observer = observer
        self._start = (math.nan, math.nan) if start is None else (float(start[0]), float(start[1]))
        self._start_node = start_node
        self._otg = Ruckig(1, self.period)
        self._input = InputParameter(1)
        self._output = OutputParameter(1)
        self._input.max_velocity = [limits.max_velocity]
        self._input.max_acceleration = [limits.max_acceleration]
        self._input.max_jerk = [limits.max_jerk]
        self._t = 0.0
        self._p = self._v = self._a = 0.0
        self._path: DrivenPath | None = None
        self._last = 0
        self._order = None  # the accepted order, merged with its updates (vda5050 Order)
        self._state = None  # the last state published (vda5050 State)
        self._errors: list = []
        self._headers = {Topic.STATE: 0, Topic.CONNECTION: 0}
        self._inbox: queue.SimpleQueue[tuple[float, bytes]] = queue.SimpleQueue()  # (arrival, payload)
        self._event = True
        self._next_state = 0.0
        self._lock = threading.Lock()
        self._snapshot = VehicleSnapshot(0.0, *self._start, 0.0, 0, False, start_node)
        self._trace: list[VehicleSnapshot] = []
        self._halt = threading.Event()
        self._thread: threading.Thread | None = None
        self.clock.follow(self._simulated_time)
        self._client = make_client(
            broker,
            f"trajgen-vehicle-{identity.manufacturer}-{identity.serial_number}",
            will=(identity.topic(Topic.CONNECTION), self._connection_message("CONNECTIONBROKEN")),
        )
        self._client.on_message = self._on_message
        self.link = BrokerLink(
            self._client, broker, who=f"vehicle {identity.serial_number}", on_connected=self._connected
        )
        self._broker = broker
        self.rejections = 0

    # ----------------------------------------------------------------- MQTT
    def _connection_message(self, state: str) -> bytes:
        from vda5050.model.connection import Connection

        self._headers[Topic.CONNECTION] += 1
        message = Connection(
            header_id=self._headers[Topic.CONNECTION],
            timestamp=self.clock.timestamp(),
            version="2.1.0",
            manufacturer=self.identity.manufacturer,
            serial_number=self.identity.serial_number,
            connection_state=state,
        )
        return message.to_json().encode()

    def _connected(self, client) -> None:
        client.subscribe(self.identity.topic(Topic.ORDER), qos=0)
        client.publish(
            self.identity.topic(Topic.CONNECTION), self._connection_message("ONLINE"), qos=1, retain=True
        )
        self._event = True  # a state at once: the master learns where the vehicle is

    def _on_message(self, client, userdata, message) -> None:
        if message.topic != self.identity.topic(Topic.ORDER):  # amqtt may replay others' retained messages
            logger.debug("vehicle %s: ignored a message on %s", self.identity.serial_number, message.topic)
            return
        self._inbox.put((self.clock.now(), bytes(message.payload)))

    def start(self) -> SimulatedVehicle:
        """Connect and start driving (in threads of its own); returns itself."""
        # its time is the clock's from here (a vehicle started late must not pull the clock back), on
        # the grid of its cycles, so that vehicles of one clock drive their cycles at the same times
        self._t = self._next_state = math.floor(self.clock.now() / self.period) * self.period
        self.link.start()
        self._thread = threading.Thread(
            target=self._run, name=f"trajgen-vehicle-{self.identity.serial_number}", daemon=True
        )
        self._thread.start()
        return self

    def stop(self) -> None:
        """Say OFFLINE, disconnect and stop driving (saying which faults never applied)."""
        halted = self._halt.is_set()
        self._halt.set()
        if self._thread is not None:
            self._thread.join(5.0)
        if not halted:
            self._report_faults()
        if self.link.connected and self._client.is_connected():
            # its last state first: whatever it did since the last one reaches the master
            self._client.publish(self.identity.topic(Topic.STATE), self._state_message(), qos=0)
            info = self._client.publish(
                self.identity.topic(Topic.CONNECTION), self._connection_message("OFFLINE"), qos=1, retain=True
            )
            info.wait_for_publish(1.0)
        self.link.close()

    def drop_connection(self) -> None:
        """Lose the broker without a word (the broker sends the last will); it keeps driving its base."""
        self._client.loop_stop()
        sock = self._client.socket()
        if sock is not None:
            import socket

            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
        logger.info("vehicle %s: connection dropped", self.identity.serial_number)

    def restore_connection(self) -> None:
        """Reconnect after :meth:`drop_connection`."""
        self._client.reconnect()
        self._client.loop_start()

    def __enter__(self) -> SimulatedVehicle:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def _simulated_time(self) -> float:
        """Its time, for the clock to wait for; unbounded when it is not driving (not started, stopped)."""
        running = self._thread is not None and self._thread.is_alive() and not self._halt.is_set()
        return self._t if running else float("inf")

    # ----------------------------------------------------------------- readouts
    @property
    def snapshot(self) -> VehicleSnapshot:
        """Where it truly is now."""
        with self._lock:
            return self._snapshot

    @property
    def since_first_order(self) -> float | None:
        """Seconds of the run since it took its first order (the run's time); ``None``: no order yet."""
        began = self._first_order
        return None if began is None else self.snapshot.time - began

    @property
    def trace(self) -> tuple[VehicleSnapshot, ...]:
        """Every cycle's snapshot (with ``record=True``; empty otherwise)."""
        with self._lock:
            return tuple(self._trace)

    # ----------------------------------------------------------------- orders
    def _reject(self, error_type: str, detail: str, references: dict[str, str]) -> None:
        from vda5050.model.common import Error

        self.rejections += 1
        self._errors.append(
            Error(
                error_type=error_type,
                error_references=[{"reference_key": k, "reference_value": v} for k, v in references.items()],
                error_description=detail,
                error_level="WARNING",
            )
        )
        logger.warning("vehicle %s: order refused (%s): %s", self.identity.serial_number, error_type, detail)

    def _receive(self, payload: bytes) -> None:
        from vda5050.domain.order.acceptance import AcceptanceDecision, OrderAcceptancePolicy
        from vda5050.domain.sessions.vehicle_session import VehicleSession
        from vda5050.errors import MessageValidationError
        from vda5050.identity import VehicleKey
        from vda5050.model.order import Order
        from vda5050.serialization import decode

        self._event = True
        try:
            order = decode(payload, Order)
        except MessageValidationError as error:
            self._reject("validationError", str(error)[:200], {"topic": Topic.ORDER})
            return
        references = {
            "headerId": str(order.header_id),
            "orderId": order.order_id,
            "orderUpdateId": str(order.order_update_id),
        }
        if (order.manufacturer, order.serial_number) != (
            self.identity.manufacturer,
            self.identity.serial_number,
        ):
            self._reject("orderError", "the order names another vehicle", references)
            return
        if any(node.node_position is None for node in order.nodes) and any(
            edge.length is None for edge in order.edges
        ):
            self._reject(
                "orderError",
                "a node has no nodePosition and an edge no length: this vehicle drives by positions or "
                "by edge lengths",
                references,
            )
            return
        if self._state is None:  # no state sent yet: the acceptance must still know where it stands
            self._state_message()
        session = VehicleSession(
            key=VehicleKey(self.identity.manufacturer, self.identity.serial_number),
            order=self._order,
            state=self._state,
        )
        result = OrderAcceptancePolicy().evaluate(order, session, available_map_ids={self.map_id})
        if result.decision is AcceptanceDecision.IGNORE_DUPLICATE:
            return
        if not result.accepted:
            self._reject(
                result.error_type or "orderError", result.detail or result.decision.value, references
            )
            return
        self._errors.clear()
        if result.decision is AcceptanceDecision.ACCEPT_NEW:
            if self._first_order is None:
                self._first_order = self._t
            self._path = DrivenPath(list(order.nodes), list(order.edges))
            self._order = order
            self._last = 0
            self._p = self._v = self._a = 0.0
            here = self._path.point(0.0)
            self._start = (math.nan, math.nan) if here is None else here[:2]
            self._start_node = order.nodes[0].node_id
        else:
            stitch = next(
                k for k, node in enumerate(self._path.nodes) if node.sequence_id == order.nodes[0].sequence_id
            )
            self._path.extend(stitch, list(order.nodes), list(order.edges))
            self._order = order.model_copy(update={"nodes": self._path.nodes, "edges": self._path.edges})
        logger.debug(
            "vehicle %s: took order %s update %d (base to node %d)",
            self.identity.serial_number,
            order.order_id,
            order.order_update_id,
            self._path.base_end,
        )

    # ----------------------------------------------------------------- driving
    def _held(self, t: float) -> bool:
        began = self._first_order
        return began is not None and any(fault.active(t - began) for fault in self.faults)

    def _report_faults(self) -> None:
        """Say which faults never applied: no order came, or the run ended before their time."""
        began = self._first_order
        for fault in self.faults:
            if began is None or self._t - began < fault.at:
                why = (
                    "no order came"
                    if began is None
                    else f"it ended {self._t - began:.1f} s after its first order"
                )
                logger.warning(
                    "vehicle %s: fault stop@%g+%g never applied (%s)",
                    self.identity.serial_number,
                    fault.at,
                    fault.duration,
                    why,
                )

    def _next_stop(self) -> float:
        path = self._path
        end = path.base_end
        k = self._last + 1
        while k < end and not path.reversal(k):
            k += 1
        return path.arcs[max(min(k, end), self._last)]

    def _step(self) -> None:
        from ruckig import ControlInterface, Result

        self._t += self.period
        path = self._path
        if path is None:
            return
        inp = self._input
        inp.current_position = [self._p]
        inp.current_velocity = [self._v]
        inp.current_acceleration = [self._a]
        if self._held(self._t):
            inp.control_interface = ControlInterface.Velocity
            inp.target_velocity = [0.0]
            inp.target_acceleration = [0.0]
        else:
            inp.control_interface = ControlInterface.Position
            inp.target_position = [self._next_stop()]
            inp.target_velocity = [0.0]
            inp.target_acceleration = [0.0]
        result = self._otg.update(inp, self._output)
        if result not in (Result.Working, Result.Finished):
            logger.error("vehicle %s: Ruckig failed (%s); braking", self.identity.serial_number, result)
            self._v = max(0.0, self._v - self.limits.max_acceleration * self.period)
            self._a = 0.0
        else:
            self._p, self._v, self._a = (
                self._output.new_position[0],
                self._output.new_velocity[0],
                self._output.new_acceleration[0],
            )
        end = path.base_end
        while self._last < end and self._p >= path.arcs[self._last + 1] - NODE_TOLERANCE:
            self._last += 1
            self._event = True

    def _finished(self) -> bool:
        path = self._path
        return (
            path is not None
            and self._last == len(path.nodes) - 1
            and all(node.released for node in path.nodes)
            and abs(self._v) <= AT_REST
        )

    def _where(self) -> tuple[float, float, float] | None:
        """``(x, y, theta)`` now, ``None`` where its orders give no position."""
        if self._path is not None:
            return self._path.point(self._p)
        return None if math.isnan(self._start[0]) else (*self._start, 0.0)

    def _update_snapshot(self) -> None:
        x, y, _ = self._where() or (math.nan, math.nan, 0.0)
        path = self._path
        place = path.place(self._p, self._last) if path is not None else (self._start_node, "", 0.0)
        snapshot = VehicleSnapshot(self._t, x, y, self._v, self._last, self._finished(), *place)
        with self._lock:
            self._snapshot = snapshot
            if self.record:
                self._trace.append(snapshot)
        if self.observer is not None:
            self.observer(snapshot)

    def _state_message(self) -> bytes:
        from vda5050.model.state import State

        path = self._path
        self._headers[Topic.STATE] += 1
        where = self._where()
        theta = where[2] if where is not None else 0.0
        nodes = path.nodes if path is not None else []
        edges = path.edges if path is not None else []
        last = nodes[self._last] if nodes else None
        to_decision_point = path.arcs[path.base_end] - self._p if path is not None else 0.0
        state = State(
            header_id=self._headers[Topic.STATE],
            timestamp=self.clock.timestamp(self._t),
            version="2.1.0",
            manufacturer=self.identity.manufacturer,
            serial_number=self.identity.serial_number,
            order_id=self._order.order_id if self._order is not None else "",
            order_update_id=self._order.order_update_id if self._order is not None else 0,
            last_node_id=last.node_id if last is not None else self._start_node,
            last_node_sequence_id=last.sequence_id if last is not None else 0,
            node_states=[
                {"node_id": n.node_id, "sequence_id": n.sequence_id, "released": n.released}
                for n in nodes[self._last + 1 :]
            ],
            edge_states=[
                {"edge_id": e.edge_id, "sequence_id": e.sequence_id, "released": e.released}
                for e in edges[self._last :]
            ],
            agv_position=None
            if where is None
            else {
                "position_initialized": True,
                "x": where[0],
                "y": where[1],
                "theta": theta,
                "map_id": self.map_id,
            },
            velocity={"vx": self._v * math.cos(theta), "vy": self._v * math.sin(theta), "omega": 0.0},
            driving=abs(self._v) > AT_REST,
            paused=self._held(self._t),
            new_base_request=path is not None
            and any(not n.released for n in nodes)
            and to_decision_point < _BASE_REQUEST_DISTANCE,
            distance_since_last_node=max(0.0, self._p - path.arcs[self._last]) if path is not None else 0.0,
            action_states=[],
            battery_state={"battery_charge": 100.0, "charging": False},
            operating_mode="AUTOMATIC",
            errors=list(self._errors),
            safety_state={"e_stop": "NONE", "field_violation": False},
        )
        self._state = state
        return state.to_json().encode()

    def _publish_state(self) -> None:
        if not (self.link.connected and self._client.is_connected()):  # offline, or not yet ONLINE
            return
        try:
            self._client.publish(self.identity.topic(Topic.STATE), self._state_message(), qos=0)
        except OSError as error:  # the connection broke under it: the link notices and reconnects
            logger.debug("vehicle %s: state not sent: %s", self.identity.serial_number, error)
        self._event = False
        self._next_state = self._t + 1.0 / self.state_rate

    def _advance(self, until: float) -> None:
        """Drive cycle by cycle up to run time ``until`` with what it knows now."""
        while self._t + self.period <= until:
            self._step()
            self._update_snapshot()
            # starting and stopping are events: the master learns at once that a vehicle stands
            said_driving = self._state is not None and self._state.driving
            if self._event or self._t >= self._next_state or (abs(self._v) > AT_REST) != said_driving:
                self._publish_state()

    def _run(self) -> None:
        try:
            while not self._halt.is_set():
                now = self.clock.now()
                # a message takes effect when it arrived: a vehicle whose thread fell behind first
                # drives to that moment without it (else it would act on news from its future)
                while True:
                    try:
                        arrival, payload = self._inbox.get_nowait()
                    except queue.Empty:
                        break
                    self._advance(min(arrival, now))
                    self._receive(payload)
                self._advance(now)
                if self._event:
                    self._publish_state()
                time.sleep(_LOOP_SLEEP_S)
        except Exception:  # a simulated vehicle that dies says so; the master sees it go silent
            logger.exception("vehicle %s: stopped by an error", self.identity.serial_number)
            raise
