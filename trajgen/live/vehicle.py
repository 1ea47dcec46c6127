"""A simulated VDA 5050 vehicle: takes orders by the protocol's rules and drives its base with Ruckig.

It accepts, ignores or rejects each order and order update by the decision
chain of VDA 5050's figure 8 (vda5050-sdk's ``OrderAcceptancePolicy``); a
rejection shows as an error in its state. It drives only on its base: Ruckig
takes it, time-optimally under its own limits, to rest at its decision point
(or at a reversal on the way), and re-plans every cycle as the base grows. It
publishes ``state`` at a fixed rate and at once on every event (a node
reached, an order taken or refused), and ``connection`` ONLINE, retained, with
a last will of CONNECTIONBROKEN.

The instant action ``cancelOrder`` (VDA 5050 section 6.6.3) stops it at the first node of its
base it can come to rest at; its state shows the action RUNNING, then FINISHED once it stands,
with no order left (its ``orderId`` and ``orderUpdateId`` stay, its node counted from there). It
watches the master's ``connection`` too: when the master is gone (its last will, or OFFLINE) it
drives on to the end of its released base, which is safe, and says so (:attr:`SimulatedVehicle.over`).
With a ``memory`` file it keeps where it last said it stands, for a restart (``--start last``).

Positions are the order's node positions (metres, the map's x/y), interpolated
along each edge: the vehicle knows no more of the track than its orders say.
Where an order gives no position (a track graph without coordinates, a curved
edge) it drives by the edges' ``length`` and reports where it is by its last
node and ``distanceSinceLastNode`` alone, as a line-guided vehicle does
(:mod:`trajgen.live.driven_path`).
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import queue
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from limits import VehicleLimits
from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.live.clock import RunClock
from trajgen.live.drive import AT_REST, Drive, VehicleSnapshot
from trajgen.live.driven_path import NODE_TOLERANCE, DrivenPath
from trajgen.live.faults import StopFault
from trajgen.live.link import BrokerLink
from trajgen.live.memory import VehicleMemory
from trajgen.live.mqtt import BrokerSettings, Topic, VehicleIdentity, make_client
from trajgen.live.notices import CANCEL_ORDER, VDA5050_VERSION, connection_message

__all__ = ["SimulatedVehicle", "StopFault", "VehicleSnapshot"]

logger = logging.getLogger(__name__)

#: How far ahead of its decision point the vehicle asks for more base (``newBaseRequest``), metres.
_BASE_REQUEST_DISTANCE = 2.0
#: Wall seconds the drive loop sleeps between its catch-ups.
_LOOP_SLEEP_S = 0.004


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
        ``state`` messages per second of the run, besides those on events (default 1: a node
        reached, starting and stopping are said at once, so the master needs no more).
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
    memory : path, optional
        A file where it keeps the place of every state it publishes (``lastNodeId``, the next node,
        ``distanceSinceLastNode``, x/y), written over in place each time: where it stood if it is killed
        (:func:`~trajgen.live.memory.remembered_place`).
    """

    def __init__(
        self,
        identity: VehicleIdentity,
        limits: VehicleLimits,
        start: tuple[float, float] | None,
        *,
        broker: BrokerSettings,
        clock: RunClock | None = None,
        state_rate: float = 1.0,
        period: float = 0.02,
        faults: Sequence[StopFault] = (),
        map_id: str = "trajgen",
        record: bool = False,
        observer: Callable[[VehicleSnapshot], None] | None = None,
        start_node: str = "",
        memory: str | Path | None = None,
    ) -> None:
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
        self._drive = Drive(limits, self.period, who=identity.serial_number)
        self._t = 0.0
        self._order = None  # the accepted order, merged with its updates (vda5050 Order)
        self._reported = ("", 0)  # orderId and orderUpdateId its states give (kept after a cancel)
        self._state = None  # the last state published (vda5050 State)
        self._errors: list = []
        self._actions: dict[str, dict] = {}  # actionId -> its action state (instant actions)
        self._cancelled = False  # its last order was cancelled (it stands with no order)
        self._master_state = "ONLINE"  # the master's connection as last said (before any: online)
        self._master_left = False  # the master went (OFFLINE, its last will) while this vehicle ran
        self.memory = Path(memory) if memory is not None else None
        self._memory: VehicleMemory | None = None  # the memory file, open while it runs
        self._headers = {Topic.STATE: 0, Topic.CONNECTION: 0}
        # (arrival, topic, payload)
        self._inbox: queue.SimpleQueue[tuple[float, str, bytes]] = queue.SimpleQueue()
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
        self._headers[Topic.CONNECTION] += 1
        header, stamp = self._headers[Topic.CONNECTION], self.clock.timestamp()
        return connection_message(self.identity, state, header=header, timestamp=stamp)

    def _connected(self, client) -> None:
        client.subscribe(self.identity.topic(Topic.ORDER), qos=0)
        client.subscribe(self.identity.topic(Topic.INSTANT_ACTIONS), qos=0)
        client.subscribe(self.identity.master.topic(Topic.CONNECTION), qos=1)
        client.publish(
            self.identity.topic(Topic.CONNECTION), self._connection_message("ONLINE"), qos=1, retain=True
        )
        self._event = True  # a state at once: the master learns where the vehicle is

    def _on_message(self, client, userdata, message) -> None:
        topics = (self.identity.topic(Topic.ORDER), self.identity.topic(Topic.INSTANT_ACTIONS))
        if message.topic == self.identity.master.topic(Topic.CONNECTION):
            self._take_master(bytes(message.payload), live=not message.retain)
        elif message.topic in topics:
            self._inbox.put((self.clock.now(), message.topic, bytes(message.payload)))
        else:  # amqtt may replay others' retained messages
            logger.debug("vehicle %s: ignored a message on %s", self.identity.serial_number, message.topic)

    def _take_master(self, payload: bytes, *, live: bool) -> None:
        """The master's connection: once it is gone, the vehicle says so (and drives its base to its end).

        ``live``: the change happened now (a retained message delivered on subscribing is old news:
        the master of an earlier run).
        """
        try:
            state = json.loads(payload)["connectionState"]
        except (ValueError, KeyError, TypeError):
            logger.debug("vehicle %s: an unreadable master connection message", self.identity.serial_number)
            return
        before, self._master_state = self._master_state, state
        self._master_left = state != "ONLINE" and live
        cancelled = self._drive.cancel_at is not None
        driving_an_order = self._order is not None and not cancelled and not self.snapshot.finished
        if state != "ONLINE" and before == "ONLINE" and driving_an_order:
            logger.warning(
                "vehicle %s: the master is gone (%s): it drives on to the end of its released base and "
                "holds there",
                self.identity.serial_number,
                state,
            )

    def start(self) -> SimulatedVehicle:
        """Connect and start driving (in threads of its own); returns itself."""
        # its time is the clock's from here (a vehicle started late must not pull the clock back), on
        # the grid of its cycles, so that vehicles of one clock drive their cycles at the same times
        self._t = self._next_state = math.floor(self.clock.now() / self.period) * self.period
        if self.memory is not None:
            self._memory = VehicleMemory.opened(self.memory, who=self.identity.serial_number)
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
        if self._memory is not None:  # after the last state: it holds the place said last
            self._memory.close()
            self._memory = None

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
    def over(self) -> str | None:
        """Why its run is over without its goal, once it stands: its order cancelled, or the master gone.

        ``None`` while it drives, holds an order from a master that is there, or is at its goal.
        """
        with self._lock:
            snapshot = self._snapshot
        if snapshot.finished or snapshot.velocity > AT_REST:
            return None
        if self._cancelled:
            return "its order was cancelled by the master"
        if self._master_state != "ONLINE" and (self._order is not None or self._master_left):
            gone = f"the master is gone ({self._master_state})"
            ordered = self._order is not None or self._first_order is not None
            return gone if ordered else f"{gone} before any order"
        return None

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
        if self._state is None or self._event:  # the acceptance must know where it stands now
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
        self._reported = (order.order_id, order.order_update_id)
        if result.decision is AcceptanceDecision.ACCEPT_NEW:
            if self._first_order is None:
                self._first_order = self._t
            self._cancelled = False
            self._drive.take(DrivenPath(list(order.nodes), list(order.edges)))
            self._order = order
            here = self._drive.path.point(0.0)
            self._start = (math.nan, math.nan) if here is None else here[:2]
            self._start_node = order.nodes[0].node_id
        else:
            path = self._drive.path
            first = order.nodes[0].sequence_id
            stitch = next(k for k, node in enumerate(path.nodes) if node.sequence_id == first)
            path.extend(stitch, list(order.nodes), list(order.edges))
            self._order = order.model_copy(update={"nodes": path.nodes, "edges": path.edges})
        logger.debug(
            "vehicle %s: took order %s update %d (base to node %d)",
            self.identity.serial_number,
            order.order_id,
            order.order_update_id,
            self._drive.path.base_end,
        )

    def _receive_actions(self, payload: bytes) -> None:
        """``instantActions``: ``cancelOrder`` stops it; any other is refused as not supported."""
        from vda5050.errors import MessageValidationError
        from vda5050.model.instant_actions import InstantActions
        from vda5050.serialization import decode

        self._event = True
        try:
            message = decode(payload, InstantActions)
        except MessageValidationError as error:
            self._reject("validationError", str(error)[:200], {"topic": Topic.INSTANT_ACTIONS})
            return
        if (message.manufacturer, message.serial_number) != (
            self.identity.manufacturer,
            self.identity.serial_number,
        ):
            where = {"topic": Topic.INSTANT_ACTIONS}
            self._reject("validationError", "the instant actions name another vehicle", where)
            return
        for action in message.actions:
            if action.action_type != CANCEL_ORDER:
                self._action(action.action_id, action.action_type, "FAILED", "not supported by this vehicle")
                self._reject("actionError", f"instant action {action.action_type!r} is not supported", {})
            elif action.action_id in self._actions:  # the same cancelOrder again: it is under way
                continue
            elif self._order is None:
                self._action(action.action_id, CANCEL_ORDER, "FAILED", "no order to cancel")
                where = {"actionId": action.action_id}
                self._reject("noOrderToCancel", "cancelOrder: no order to cancel", where)
            else:
                self._action(action.action_id, CANCEL_ORDER, "RUNNING")
                ahead = self._drive.cancel() - self._drive.p
                logger.warning(
                    "vehicle %s: its order is cancelled: it stops %.3f m ahead, at a node of its base",
                    self.identity.serial_number,
                    ahead,
                )

    def _action(self, action_id: str, action_type: str, status: str, description: str = "") -> None:
        self._actions[action_id] = {
            "action_id": action_id,
            "action_type": action_type,
            "action_status": status,
            "result_description": description or None,
        }

    def _end_cancel(self) -> None:
        """A cancelled order once the vehicle stands: no order left, its node counted from here."""
        where = self._where()
        place = self._drive.path.place(self._drive.p, self._drive.last)
        self._start = (math.nan, math.nan) if where is None else (where[0], where[1])
        self._start_node = place[0] if place[2] <= NODE_TOLERANCE else self._start_node
        for action in self._actions.values():
            if action["action_type"] == CANCEL_ORDER and action["action_status"] == "RUNNING":
                action["action_status"] = "FINISHED"
        self._drive.clear()
        self._order = None
        self._cancelled = True
        self._event = True
        logger.info("vehicle %s: it stands; its order is cancelled", self.identity.serial_number)

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

    def _step(self) -> None:
        self._t += self.period
        if self._drive.step(held=self._held(self._t)):
            self._event = True  # a node passed: said at once
        if self._drive.cancelled_and_standing:
            self._end_cancel()

    def _where(self) -> tuple[float, float, float] | None:
        """``(x, y, theta)`` now, ``None`` where its orders give no position."""
        drive = self._drive
        if drive.path is not None:
            return drive.path.point(drive.p)
        return None if math.isnan(self._start[0]) else (*self._start, 0.0)

    def _update_snapshot(self) -> None:
        x, y, _ = self._where() or (math.nan, math.nan, 0.0)
        drive = self._drive
        standing = (self._start_node, "", 0.0)
        place = drive.path.place(drive.p, drive.last) if drive.path is not None else standing
        snapshot = VehicleSnapshot(self._t, x, y, drive.v, drive.last, drive.finished(), *place)
        with self._lock:
            self._snapshot = snapshot
            if self.record:
                self._trace.append(snapshot)
        if self.observer is not None:
            self.observer(snapshot)

    def _state_message(self) -> bytes:
        from vda5050.model.state import State

        drive, v = self._drive, self._drive.v
        self._headers[Topic.STATE] += 1
        where = self._where()
        theta = where[2] if where is not None else 0.0
        state = State(
            header_id=self._headers[Topic.STATE],
            timestamp=self.clock.timestamp(self._t),
            version=VDA5050_VERSION,
            manufacturer=self.identity.manufacturer,
            serial_number=self.identity.serial_number,
            order_id=self._reported[0],
            order_update_id=self._reported[1],
            **drive.progress(self._start_node, base_request=_BASE_REQUEST_DISTANCE),
            agv_position=None
            if where is None
            else {
                "position_initialized": True,
                "x": where[0],
                "y": where[1],
                "theta": theta,
                "map_id": self.map_id,
            },
            velocity={"vx": v * math.cos(theta), "vy": v * math.sin(theta), "omega": 0.0},
            driving=not drive.at_rest,
            paused=self._held(self._t),
            action_states=list(self._actions.values()),
            battery_state={"battery_charge": 100.0, "charging": False},
            operating_mode="AUTOMATIC",
            errors=list(self._errors),
            safety_state={"e_stop": "NONE", "field_violation": False},
        )
        self._state = state
        if self._memory is not None and not self._memory.keep(state):
            self._memory = None  # said once: it drives on without its memory
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
            if self._event or self._t >= self._next_state or (not self._drive.at_rest) != said_driving:
                self._publish_state()

    def _run(self) -> None:
        try:
            while not self._halt.is_set():
                now = self.clock.now()
                # a message takes effect when it arrived: a vehicle whose thread fell behind first
                # drives to that moment without it (else it would act on news from its future)
                while True:
                    try:
                        arrival, topic, payload = self._inbox.get_nowait()
                    except queue.Empty:
                        break
                    self._advance(min(arrival, now))
                    if topic == self.identity.topic(Topic.ORDER):
                        self._receive(payload)
                    else:
                        self._receive_actions(payload)
                self._advance(now)
                if self._event:
                    self._publish_state()
                time.sleep(_LOOP_SLEEP_S)
        except Exception:  # a simulated vehicle that dies says so; the master sees it go silent
            logger.exception("vehicle %s: stopped by an error", self.identity.serial_number)
            raise
