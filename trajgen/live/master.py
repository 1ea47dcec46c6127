"""The live master: drives two VDA 5050 vehicles over MQTT, releasing base by the frontier.

It sends each vehicle one order: its whole path, the base up to its current
frontier (the last released node) and the rest as horizon. Then it follows the
vehicles' states. When a vehicle reports a node reached, the release rule
(:class:`~trajgen.export.vda5050_release.BaseRelease`) may let the base of
either vehicle grow; each growth is an order update (same ``orderId``,
``orderUpdateId`` + 1, stitched at the previous decision point).

What keeps the vehicles apart is the released base, never the timing: a
vehicle claims the track from the last node it reported to its decision point,
the two claims never come closer than the minimum separation, and a claim only
shrinks when its vehicle reports it has moved on. A late, lost or duplicated
message therefore only delays a release; it never makes one unsafe. Messages
that cannot be trusted (malformed, another vehicle's, older than one already
taken, or naming a node the vehicle cannot have reached) are logged and
ignored. While a vehicle is offline (its last will, or OFFLINE) nothing is
released to either vehicle; when it is back, the latest order is sent again.
After a broker restart the client reconnects and re-sends every vehicle's
latest order (a vehicle ignores one it already has).

A new goal: no more base is released; once both vehicles stand at their
decision points, the planner plans from there and each vehicle gets an order
update stitched where it stands, with the new path.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Sequence

import numpy as np

from topology import JUNCTION_INDEX, Configuration, Position
from trajgen.errors import InputError
from trajgen.export.vda5050_messages import VDA5050_VERSION, node_id, order_elements
from trajgen.export.vda5050_release import BaseRelease, plan_orders
from trajgen.live.clock import RunClock
from trajgen.live.geometry import track_position
from trajgen.live.link import BrokerLink
from trajgen.live.mqtt import BrokerSettings, Topic, VehicleIdentity, make_client
from trajgen.live.outcome import LiveOutcome, LiveRun
from trajgen.live.runlog import RunLog
from trajgen.live.view import RESEND_INTERVAL_S, VehicleView
from trajgen.methods import METHODS
from trajgen.model.summary import provenance
from trajgen.online.goals import goal_refusal, plan_from_rest
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["NODE_DEVIATION", "RELEASE_SPACING", "LiveMaster", "LiveOutcome", "LiveRun"]

logger = logging.getLogger(__name__)

#: ``allowedDeviationXY`` of every node sent: how close a vehicle must be to count as on it, metres.
NODE_DEVIATION = 1e-3
#: Longest edge of the paths sent by default, metres.
RELEASE_SPACING = 0.25
#: Longest wait between two re-sends to a vehicle whose states show it lacks the latest order.
_RESEND_MAX_S = 8.0
#: The re-send interval at which an order not taken is reported (after three re-sends, about 2 s).
_NOT_TAKEN_AFTER = 8 * RESEND_INTERVAL_S
#: Slower than this (reported ``velocity``) a vehicle at its decision point stands, m/s.
_AT_REST = 1e-6


class LiveMaster:
    """Drive two VDA 5050 vehicles through a verified plan over an MQTT broker.

    Parameters
    ----------
    verified : VerifiedSchedule
        The plan (from :func:`~trajgen.verification.certify`); its route fixes both paths and the
        order at every conflict.
    names : sequence of 2 str
        The vehicles' names (in the run log).
    identities : tuple of 2 VehicleIdentity
    broker : BrokerSettings
    method : TimingMethod or str, optional
        What times a new plan after a goal change (default: the registry's default).
    clock : RunClock, optional
        The run's clock (its time scale must be the vehicles').
    order_id : str
        ``orderId`` prefix: ``<order_id>-<vehicle name>`` (default ``"trajgen"``).
    map_id : str
        ``nodePosition.mapId`` (default ``"trajgen"``).
    log : RunLog, optional
        Where every event is logged (default: a new one, its ``log``).
    spacing : float
        Longest edge of the paths sent, metres (default :data:`RELEASE_SPACING`): the base is released
        node by node, so finer nodes let a vehicle follow the other closely instead of braking early.
    """

    def __init__(
        self,
        verified: VerifiedSchedule,
        names: Sequence[str],
        *,
        identities: tuple[VehicleIdentity, VehicleIdentity],
        broker: BrokerSettings,
        method=None,
        clock: RunClock | None = None,
        order_id: str = "trajgen",
        map_id: str = "trajgen",
        log: RunLog | None = None,
        spacing: float = RELEASE_SPACING,
    ) -> None:
        verified = require_verified(verified, "LiveMaster")
        self.spacing = spacing
        if len(identities) != 2 or identities[0].topic("") == identities[1].topic(""):
            raise InputError("live vehicles must have two different identities (one topic each)")
        self.graph = verified.schedule.route.graph
        self.limits = verified.schedule.limits
        self.names = tuple(names)
        self.method = method
        self._asked = METHODS.create(method).name  # as the plans name it (exact after a fallback)
        self._provenance: dict = {}
        self.broker = broker
        self.clock = clock if clock is not None else RunClock()
        self.order_id = order_id
        self.map_id = map_id
        self.log = log if log is not None else RunLog()
        self._views = [VehicleView(self.names[v], identities[v]) for v in (0, 1)]
        self._topics = {}
        for v, identity in enumerate(identities):
            self._topics[identity.topic(Topic.STATE)] = (v, Topic.STATE)
            self._topics[identity.topic(Topic.CONNECTION)] = (v, Topic.CONNECTION)
        self._lock = threading.RLock()
        self._done = threading.Event()
        self._goal: Configuration | None = None
        self._rule: BaseRelease | None = None
        self._started_at: float | None = None
        self._latencies: list[float] = []
        self._counts = {"orders": 0, "resent": 0, "ignored": 0, "replans": 0}
        self._planned = 0.0
        self._end_time = 0.0
        self._adopt(verified, first=True)
        self._client = make_client(broker, f"trajgen-master-{identities[0].interface}-{id(self):x}")
        self._client.on_message = self._on_message
        self.link = BrokerLink(self._client, broker, who="master", on_connected=self._connected)

    # ----------------------------------------------------------------- plans and orders
    def _adopt(self, verified: VerifiedSchedule, *, first: bool) -> None:
        """Take a new plan: paths, release rule, and (after a goal change) the stitch offsets."""
        self._plan_goal = verified.schedule.route.goal
        plan = plan_orders(verified, spacing=self.spacing)
        rule = BaseRelease(plan.paths, verified.schedule.limits.min_separation)
        for v, view in enumerate(self._views):
            if not first:
                view.offset += 2 * view.node
                start = view.arcs[view.node]
            else:
                start = 0.0
            view.path = plan.paths[v]
            view.arcs = [start]
            for edge in view.path.edges:
                view.arcs.append(view.arcs[-1] + edge.length)
            view.node = 0
            self._elements(v)
        self._rule = rule
        if first:
            self._planned = plan.planned_duration
            self._provenance = provenance(verified.schedule, self._asked)
        self.log.write(
            {
                "t": self.clock.now(),
                "event": "plan",
                **provenance(verified.schedule, self._asked),
                "planned_s": plan.planned_duration,
                "nodes": [len(p.nodes) for p in plan.paths],
            }
        )

    def _elements(self, v: int) -> None:
        """Each node and edge of vehicle ``v``'s path as a validated model, in base and in horizon."""
        from vda5050.model.order import Edge, Node

        view = self._views[v]
        last = len(view.path.nodes) - 1
        forms = []
        for released in (False, True):
            nodes, edges = order_elements(
                self.graph, view.path, first=0, decision_point=last if released else -1, map_id=self.map_id
            )
            for node in nodes:
                node["sequenceId"] += view.offset
                node["nodePosition"]["allowedDeviationXY"] = NODE_DEVIATION
            for edge in edges:
                edge["sequenceId"] += view.offset
            forms.append(([Node.model_validate(n) for n in nodes], [Edge.model_validate(e) for e in edges]))
        view.elements = forms

    def _order(self, v: int, first: int, decision_point: int):
        """The order (update) of vehicle ``v`` from node ``first``, its base up to ``decision_point``."""
        from vda5050.model.order import Order

        view = self._views[v]
        (horizon_nodes, horizon_edges), (base_nodes, base_edges) = view.elements
        nodes = [
            base_nodes[j] if j <= decision_point else horizon_nodes[j] for j in range(first, len(base_nodes))
        ]
        edges = [
            base_edges[k] if k < decision_point else horizon_edges[k] for k in range(first, len(base_edges))
        ]
        view.header += 1
        # its nodes and edges were validated once per plan (_elements), its header is this master's
        order = Order.model_construct(
            header_id=view.header,
            timestamp=self.clock.timestamp(),
            version=VDA5050_VERSION,
            manufacturer=view.identity.manufacturer,
            serial_number=view.identity.serial_number,
            order_id=f"{self.order_id}-{view.name}",
            order_update_id=view.update + 1,
            nodes=nodes,
            edges=edges,
        )
        return order

    def _publish(self, v: int, payload: bytes, *, resent: bool, record: dict) -> None:
        view = self._views[v]
        self._client.publish(view.identity.topic(Topic.ORDER), payload, qos=0)
        view.sent_at = time.monotonic()
        self._counts["orders"] += 1
        self._counts["resent"] += resent
        self.log.write(
            {"t": self.clock.now(), "event": "order", "vehicle": view.name, "resent": resent, **record}
        )

    def _send(self, v: int, first: int, decision_point: int) -> None:
        view = self._views[v]
        order = self._order(v, first, decision_point)
        view.update += 1
        view.order = order
        view.resend_after = RESEND_INTERVAL_S
        view.record = {
            "update": view.update,
            "first": first,
            "decision_point": decision_point,
            "frontier_m": view.arcs[decision_point],
        }
        self._publish(v, order.to_json().encode(), resent=False, record=view.record)

    def _resend(self, v: int) -> None:
        """The latest order (update) again, under a new headerId (VDA 5050: one per message)."""
        view = self._views[v]
        if view.order is not None:
            view.header += 1
            header = {"header_id": view.header, "timestamp": self.clock.timestamp()}
            again = view.order.model_copy(update=header)
            self._publish(v, again.to_json().encode(), resent=True, record=view.record)

    # ----------------------------------------------------------------- MQTT
    def _connected(self, client) -> None:
        for topic in self._topics:
            client.subscribe(topic, qos=1)
        with self._lock:
            if self._started_at is None:
                self._started_at = self.clock.now()
                for v in (0, 1):
                    self._send(v, 0, self._rule.released[v])
            else:  # reconnected (the broker restarted): the latest orders again
                for v in (0, 1):
                    self._resend(v)

    def _ignore(self, topic: str, reason: str, vehicle: str | None = None) -> None:
        self._counts["ignored"] += 1
        logger.warning("master: ignored a message on %s: %s", topic, reason)
        self.log.write(
            {"t": self.clock.now(), "event": "ignored", "topic": topic, "vehicle": vehicle, "reason": reason}
        )

    def _on_message(self, client, userdata, message) -> None:
        taken = time.perf_counter()
        where = self._topics.get(message.topic)
        try:
            with self._lock:
                if where is None:
                    self._ignore(message.topic, "not a topic of this run's vehicles")
                elif where[1] == Topic.STATE:
                    self._take_state(where[0], message.topic, bytes(message.payload), taken)
                else:
                    self._take_connection(where[0], message.topic, bytes(message.payload))
        except Exception:  # a message must never stop the master: log it, keep the releases as they are
            logger.exception("master: a message on %s raised; ignored", message.topic)

    def _decode(self, v: int, topic: str, payload: bytes, model):
        from vda5050.errors import MessageValidationError
        from vda5050.serialization import decode

        view = self._views[v]
        try:
            message = decode(payload, model)
        except MessageValidationError as error:
            self._ignore(topic, f"malformed: {str(error)[:120]}", view.name)
            return None
        identity = (message.manufacturer, message.serial_number)
        if identity != (view.identity.manufacturer, view.identity.serial_number):
            self._ignore(topic, f"from {identity[0]}/{identity[1]}, not {view.name}", view.name)
            return None
        return message

    def _take_connection(self, v: int, topic: str, payload: bytes) -> None:
        from vda5050.model.connection import Connection

        message = self._decode(v, topic, payload, Connection)
        if message is None:
            return
        view = self._views[v]
        online = message.connection_state.value == "ONLINE"
        if online == view.online:
            return
        back = view.online is False  # None: the first news (a retained message), after the first order
        view.online = online
        self.log.write(
            {
                "t": self.clock.now(),
                "event": "connection",
                "vehicle": view.name,
                "state": message.connection_state.value,
            }
        )
        if online:
            logger.info("master: %s is online", view.name)
            view.state_header = None  # a vehicle that restarted counts its headers afresh
            view.rejoined = back  # its first state tells whether it kept its order
        elif view.arcs and view.node == len(view.arcs) - 1:
            logger.info("master: %s is %s at its goal", view.name, message.connection_state.value)
        else:
            logger.warning("master: %s is %s: no base is released", view.name, message.connection_state.value)

    def _not_taken(self, view: VehicleView, state) -> None:
        """Say that a vehicle still reports an older order than the one sent (three re-sends)."""
        held = f"order {state.order_id!r} update {state.order_update_id}" if state.order_id else "no order"
        why = "the broker may refuse the master's publishes (an ACL) or the vehicle its orders"
        logger.warning(
            "master: %s has not taken its order (it reports %s after 4 sends): %s", view.name, held, why
        )
        self.log.write(
            {"t": self.clock.now(), "event": "order-not-taken", "vehicle": view.name, "reports": held}
        )

    def _report_errors(self, view: VehicleView, state) -> None:
        """A vehicle's new errors (an order it refused, say), said at once and logged, each once."""
        for error in state.errors:
            if error.error_description not in view.errors:
                view.errors.add(error.error_description)
                logger.warning(
                    "master: %s reports %s: %s", view.name, error.error_type, error.error_description
                )
                self.log.write(
                    {
                        "t": self.clock.now(),
                        "event": "vehicle-error",
                        "vehicle": view.name,
                        "type": error.error_type,
                        "description": error.error_description,
                    }
                )

    def _take_state(self, v: int, topic: str, payload: bytes, taken: float) -> None:
        from vda5050.model.state import State

        state = self._decode(v, topic, payload, State)
        if state is None:
            return
        view = self._views[v]
        if view.state_header is not None and state.header_id <= view.state_header:
            self._ignore(topic, f"headerId {state.header_id} is not after {view.state_header}", view.name)
            return
        self._report_errors(view, state)
        if view.rejoined:
            view.rejoined = False
            if not state.order_id and state.agv_position is not None:  # restarted: its order is gone
                self._recover(v, state)
                return
        expected = f"{self.order_id}-{view.name}"
        if state.order_id != expected or state.order_update_id < view.update:
            view.state_header = state.header_id
            if time.monotonic() - view.sent_at >= view.resend_after:  # it lacks the latest order
                logger.debug("master: %s has not the latest order: sent again", view.name)
                self._resend(v)
                view.resend_after = min(2.0 * view.resend_after, _RESEND_MAX_S)
                if view.resend_after == _NOT_TAKEN_AFTER:  # said once per order
                    self._not_taken(view, state)
            return
        view.resend_after = RESEND_INTERVAL_S
        j = (state.last_node_sequence_id - view.offset) // 2
        if not (
            0 <= j <= self._rule.released[v]
            and (state.last_node_sequence_id - view.offset) % 2 == 0
            and state.last_node_id == self._node_id(v, j)
        ):
            self._ignore(
                topic,
                f"last node {state.last_node_id!r} (sequenceId {state.last_node_sequence_id}) is not a node "
                f"of {view.name}'s base",
                view.name,
            )
            return
        view.state_header = state.header_id
        view.node = max(view.node, j)
        view.driving = state.driving
        self.log.write(
            {
                "t": self.clock.now(),
                "event": "state",
                "vehicle": view.name,
                "x": state.agv_position.x if state.agv_position else None,
                "y": state.agv_position.y if state.agv_position else None,
                "node": view.node + view.offset // 2,
                "along_m": view.arcs[j] + (state.distance_since_last_node or 0.0),
                "driving": state.driving,
            }
        )
        released = self._release()
        if released:
            self._latencies.append(time.perf_counter() - taken)
        self._check_end()

    def _node_id(self, v: int, j: int) -> str:
        node = self._views[v].path.nodes[j]
        return node_id(self.graph, node.leg, node.s)

    def _release(self) -> int:
        """Take the nodes reached into the rule and send the releases that follow; their count."""
        if self._goal is not None:
            self._maybe_replan()
            return 0
        if not all(view.online is not False for view in self._views):
            return 0
        count = 0
        for v, view in enumerate(self._views):
            if view.node > self._rule.reached[v]:
                for vehicle, old, new in self._rule.reach(v, view.node):
                    self._send(vehicle, old, new)
                    count += 1
        return count

    def _check_end(self) -> None:
        if self._goal is None and all(
            view.node == len(view.path.nodes) - 1 and not view.driving for view in self._views
        ):
            if not self._done.is_set():
                self._end_time = self.clock.now()
            self._done.set()

    # ----------------------------------------------------------------- goals
    def request_goal(self, goal: Configuration) -> None:
        """Ask for a new goal: both vehicles stop at their bases, then are re-planned from there.

        Raises
        ------
        InputError
            ``goal`` is not on the track, or leaves the vehicles closer than the separation.
        """
        if not isinstance(goal, Configuration):
            raise InputError(f"live goal must be a Configuration, got {type(goal).__name__}")
        goal = Configuration(self.graph.check(goal.first), self.graph.check(goal.second))
        refusal = goal_refusal(self.graph, goal, self.limits.min_separation)
        if refusal is not None:
            raise InputError(refusal)
        with self._lock:
            self._goal = goal
            self._done.clear()
            self.log.write({"t": self.clock.now(), "event": "goal", "goal": str(goal)})
            logger.info("master: new goal %s: holding both vehicles at their bases", goal)
            self._maybe_replan()

    def _recover(self, v: int, state) -> None:
        """A vehicle back without its order (restarted): hold the other, re-plan from where both stand."""
        view = self._views[v]
        view.restart = track_position(self.graph, state.agv_position.x, state.agv_position.y)
        view.driving = state.driving
        if self._goal is None:
            self._goal = self._plan_goal
        self.log.write(
            {"t": self.clock.now(), "event": "restart", "vehicle": view.name, "at": str(view.restart)}
        )
        logger.warning("master: %s is back without its order, at %s: re-planning", view.name, view.restart)
        self._maybe_replan()

    def _maybe_replan(self) -> None:
        views = self._views
        if not all(
            (view.restart is not None or view.node == self._rule.released[v])
            and not view.driving
            and view.online is not False
            for v, view in enumerate(views)
        ):
            return
        here = [views[v].path.nodes[views[v].node] for v in (0, 1)]
        start = Configuration(
            *(
                views[v].restart
                if views[v].restart is not None
                else Position(None, 0.0)
                if n.leg == JUNCTION_INDEX
                else Position(self.graph.names[n.leg], n.s)
                for v, n in enumerate(here)
            )
        )
        for view in views:
            view.restart = None
        goal, self._goal = self._goal, None
        verified = plan_from_rest(self.graph, self.limits, start, goal, method=self.method, margin=0.0)
        self._counts["replans"] += 1
        self.log.write({"t": self.clock.now(), "event": "replan", "goal": str(goal)})
        self._adopt(verified, first=False)
        for v in (0, 1):
            self._send(v, 0, self._rule.released[v])
        self._check_end()

    # ----------------------------------------------------------------- running
    def run(self, *, timeout: float) -> LiveRun:
        """Connect, drive both vehicles to their goals, disconnect.

        Parameters
        ----------
        timeout : float
            Seconds of the run after which it ends unfinished.

        Returns
        -------
        LiveRun
            Outcome ``broker-failed`` with its ``error`` when the connection failed for good (a
            refused login, an untrusted certificate); ``timed-out`` if the broker never answered.
        """
        self.start()
        try:
            self.wait(timeout=timeout)
        finally:
            self.stop()
        return self.result()

    def start(self) -> LiveMaster:
        """Connect in the background (see :class:`~trajgen.live.BrokerLink`); returns itself at once.

        The orders go out once connected; an unreachable broker is retried until :meth:`wait` ends.
        """
        self.link.start()
        return self

    def wait(self, *, timeout: float) -> bool:
        """Wait until both vehicles stand at their goals or ``timeout`` seconds of the run pass."""
        deadline = self.clock.now() + timeout
        while not self._done.is_set() and not self.link.failed.is_set():
            left = deadline - self.clock.now()
            if left <= 0.0:
                return False
            self._done.wait(min(self.clock.wall_seconds(left), 0.05))
        return True

    def stop(self) -> None:
        """Disconnect."""
        self.link.close()

    def _failure(self, outcome: LiveOutcome) -> str | None:
        if outcome is LiveOutcome.BROKER_FAILED:
            return self.link.failure
        if outcome is LiveOutcome.TIMED_OUT and not self.link.ever_connected:
            return f"master: the broker {self.broker.url} was never reached (retried until the time limit)"
        return None

    def result(self) -> LiveRun:
        """The run so far (see :class:`LiveRun`); logs its end."""
        with self._lock:
            now = self.clock.now()
            began = self._started_at if self._started_at is not None else now
            outcome = LiveOutcome.GOALS_REACHED if self._done.is_set() else LiveOutcome.TIMED_OUT
            if outcome is LiveOutcome.TIMED_OUT and self.link.failed.is_set():
                outcome = LiveOutcome.BROKER_FAILED
            latency = np.array(self._latencies, dtype=float)
            latency.flags.writeable = False
            run = LiveRun(
                outcome,
                (self._end_time if self._done.is_set() else now) - began,
                self._planned,
                self._counts["orders"],
                self._counts["resent"],
                self._counts["ignored"],
                self._counts["replans"],
                latency,
                dict(self._provenance),
                self._failure(outcome),
            )
            end = {"t": now, "event": "end", "outcome": outcome.value, "makespan_s": run.makespan}
            if run.error is not None:
                end["error"] = run.error
            self.log.write(end)
            return run
