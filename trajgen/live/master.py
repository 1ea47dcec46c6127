"""The live master: drives VDA 5050 vehicles over MQTT, releasing base by the frontier.

It connects to the broker and plans at the same time: each plan is made, and made ready to send,
in a thread of its own (:mod:`trajgen.live.planner`), so that the MQTT client's thread keeps
pumping (its keep-alive, the states that come in meanwhile). What to send, and when, is the
coordinator's (:class:`~trajgen.live.coordinator.LiveCoordinator`): the master decodes each message,
drops what cannot be read or trusted (malformed, another vehicle's, on no topic of the run), hands
the rest to the coordinator under one lock, and publishes what the coordinator asks.

No order leaves before every vehicle has said, in a state, where it stands, at rest, and stands where
the plan starts it; elsewhere, the master plans again from the reported places, or refuses. While the
run goes, nothing is released to anyone while a vehicle is offline, back online and unheard, has not
taken its plan's order, or stands off its plan. After a broker restart the client reconnects and
re-sends every vehicle's latest order (a vehicle ignores one it already has).

What keeps the vehicles apart is the released base, never the timing: a vehicle claims the track
from the last node it reported to its decision point, the claims never come closer than the minimum
separation, and a claim only shrinks when its vehicle reports it has moved on.

:meth:`LiveMaster.interrupt` stops a run (``trajgen serve`` on SIGINT or SIGTERM): nothing more is
released and each vehicle is sent ``cancelOrder``, which stops it within its released base. The
master's own ``connection`` (ONLINE, OFFLINE, and a last will of CONNECTIONBROKEN) tells the
vehicles when it is gone.
"""

from __future__ import annotations

import logging
import threading
import time

from trajgen.errors import InputError
from trajgen.live.clock import RunClock
from trajgen.live.coordinator import LiveCoordinator
from trajgen.live.link import BrokerLink
from trajgen.live.mqtt import MASTER_SERIAL, BrokerSettings, Topic, make_client
from trajgen.live.notices import connection_message
from trajgen.live.outcome import LiveOutcome, LiveRun
from trajgen.live.planner import PlanJob
from trajgen.live.plans import START_TOLERANCE
from trajgen.live.runlog import RunLog
from trajgen.live.view import GIVE_UP_AFTER_S
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["RELEASE_SPACING", "START_TOLERANCE", "LiveMaster", "LiveOutcome", "LiveRun"]

logger = logging.getLogger(__name__)

#: Longest edge of the paths sent by default, metres.
RELEASE_SPACING = 0.25


class LiveMaster:
    """Drive VDA 5050 vehicles to their goals in a scenario over an MQTT broker.

    Parameters
    ----------
    scenario : trajgen.scenario.Scenario or trajgen.scenario.GraphScenario
        Its track, vehicles (names, limits), start and goal.
    identities : sequence of VehicleIdentity
        One per vehicle, in the scenario's order; each its own topics.
    broker : BrokerSettings
    method : TimingMethod or str, optional
        What times the plans (default: :func:`~trajgen.methods.method_for` the track).
    plan : VerifiedSchedule, optional
        The plan from the scenario's start (from :func:`~trajgen.live.session.live_plan`); default:
        planned by :meth:`start`, while the master connects.
    clock : RunClock, optional
        The run's clock (its time scale must be the vehicles').
    order_id : str
        ``orderId`` prefix: ``<order_id>-<vehicle name>-<run>``, ``<run>`` the UTC time the master
        was made (``20261207T170512345``): each run's orders are new to the vehicles (default
        ``"trajgen"``).
    map_id : str
        ``nodePosition.mapId`` (default ``"trajgen"``).
    log : RunLog, optional
        Where every event is logged (default: a new one, its ``log``).
    spacing : float
        Longest edge of the paths sent, metres (default :data:`RELEASE_SPACING`): the base is released
        node by node, so finer nodes let a vehicle follow the other closely instead of braking early.
    give_up_after : float
        Seconds of the run a vehicle may show it lacks its order, or stand off its plan, before the
        run ends (``ORDER_NOT_TAKEN``, ``REFUSED``).

    Raises
    ------
    InputError
        Not one identity per vehicle, two on the same topics, or one with the master's serial
        number (:data:`~trajgen.live.mqtt.MASTER_SERIAL`).
    """

    def __init__(
        self,
        scenario,
        *,
        identities,
        broker: BrokerSettings,
        method=None,
        plan: VerifiedSchedule | None = None,
        clock: RunClock | None = None,
        order_id: str = "trajgen",
        map_id: str = "trajgen",
        log: RunLog | None = None,
        spacing: float = RELEASE_SPACING,
        give_up_after: float = GIVE_UP_AFTER_S,
    ) -> None:
        identities = tuple(identities)
        names = tuple(scenario.names)
        topics = {identity.topic("") for identity in identities}
        if len(identities) != len(names) or len(topics) != len(names):
            raise InputError(
                f"live vehicles must have {len(names)} different identities (one topic each), "
                f"got {len(identities)}"
            )
        if any(identity.serial_number == MASTER_SERIAL for identity in identities):
            raise InputError(
                f"serial number {MASTER_SERIAL!r} is the master's own (its connection topic): "
                "expected other serial numbers for the vehicles"
            )
        self.names = names
        self.spacing = spacing
        self.broker = broker
        self.clock = clock if clock is not None else RunClock()
        self.log = log if log is not None else RunLog()
        self._identities = identities
        self._master = identities[0].master
        self._master_header = 0
        self._topics = {
            identity.topic(kind): (v, kind)
            for v, identity in enumerate(identities)
            for kind in (Topic.STATE, Topic.CONNECTION)
        }
        self._lock = threading.RLock()
        #: what the master decides (its caller: this object, under its lock)
        self.coordinator = LiveCoordinator(
            scenario,
            identities,
            outbox=self,
            clock=self.clock,
            log=self.log,
            method=method,
            order_prefix=order_id,
            map_id=map_id,
            spacing=spacing,
            give_up_after=give_up_after,
        )
        if plan is not None:
            self.coordinator.take_plan(require_verified(plan, "LiveMaster"))
        self._client = make_client(
            broker,
            f"trajgen-master-{identities[0].interface}-{id(self):x}",
            will=(self._master.topic(Topic.CONNECTION), self._master_connection("CONNECTIONBROKEN")),
        )
        self._client.on_message = self._on_message
        coordinator = self.coordinator
        self.link = BrokerLink(
            self._client,
            broker,
            who="master",
            on_connected=self._connected,
            on_change=coordinator.link_changed,
        )

    # ----------------------------------------------------------------- the outbox
    def order(self, v: int, payload: bytes) -> None:
        """Publish an order (update) to vehicle ``v`` (the coordinator's outbox)."""
        self._client.publish(self._identities[v].topic(Topic.ORDER), payload, qos=0)

    def instant_actions(self, v: int, payload: bytes) -> None:
        """Publish ``instantActions`` to vehicle ``v`` (the coordinator's outbox)."""
        self._client.publish(self._identities[v].topic(Topic.INSTANT_ACTIONS), payload, qos=0)

    def plan(self, make, *, what: str, context) -> PlanJob:
        """Run ``make`` in a thread of its own; the coordinator takes its result under the lock."""

        def done(job: PlanJob) -> None:
            with self._lock:
                self.coordinator.planned(job)

        return PlanJob(make, done, what=what, context=context).start()

    def _master_connection(self, state: str) -> bytes:
        self._master_header += 1
        stamp = self.clock.timestamp()
        return connection_message(self._master, state, header=self._master_header, timestamp=stamp)

    # ----------------------------------------------------------------- MQTT
    def _connected(self, client) -> None:
        for topic in self._topics:
            client.subscribe(topic, qos=1)
        online = self._master_connection("ONLINE")
        client.publish(self._master.topic(Topic.CONNECTION), online, qos=1, retain=True)
        with self._lock:
            self.coordinator.connected()

    def _on_message(self, client, userdata, message) -> None:
        from vda5050.model.connection import Connection
        from vda5050.model.state import State

        taken = time.perf_counter()
        where = self._topics.get(message.topic)
        try:
            with self._lock:
                if where is None:
                    self.coordinator.ignore(message.topic, "not a topic of this run's vehicles")
                    return
                v, kind = where
                model = State if kind == Topic.STATE else Connection
                decoded = self._decode(v, message.topic, bytes(message.payload), model)
                if decoded is None:
                    return
                if kind == Topic.STATE:
                    self.coordinator.take_state(v, message.topic, decoded, taken)
                else:
                    self.coordinator.take_connection(v, decoded)
        except Exception:  # a message must never stop the master: log it, keep the releases as they are
            logger.exception("master: a message on %s raised; ignored", message.topic)

    def _decode(self, v: int, topic: str, payload: bytes, model):
        """The message as ``model``, or ``None`` (logged and ignored): malformed, or another vehicle's."""
        from vda5050.errors import MessageValidationError
        from vda5050.serialization import decode

        name, identity = self.names[v], self._identities[v]
        try:
            message = decode(payload, model)
        except MessageValidationError as error:
            self.coordinator.ignore(topic, f"malformed: {str(error)[:120]}", name)
            return None
        sender = (message.manufacturer, message.serial_number)
        if sender != (identity.manufacturer, identity.serial_number):
            self.coordinator.ignore(topic, f"from {sender[0]}/{sender[1]}, not {name}", name)
            return None
        return message

    # ----------------------------------------------------------------- the run's time
    @property
    def elapsed(self) -> float:
        """Seconds of the run's clock since :meth:`start` (planning and waits included)."""
        return self.clock.now() - self.coordinator.record.began_at

    @property
    def run_time(self) -> float | None:
        """Seconds of the run since the first orders; ``None`` before them."""
        with self._lock:
            began = self.coordinator.started_at
            return None if began is None else self.clock.now() - began

    @property
    def planned_duration(self) -> float | None:
        """When the plan being driven brings every vehicle to its goal, seconds; ``None`` while planning."""
        with self._lock:
            return None if self.coordinator.verified is None else self.coordinator.record.planned_s

    # ----------------------------------------------------------------- running
    def request_goal(self, goal) -> None:
        """Ask for a new goal: the vehicles stop at their bases, then are re-planned from there.

        ``goal``: a Configuration on a junction; on a track graph every vehicle's position
        (``"EDGE:s"``, a node's name, or an EdgePoint). Before the first orders, the first plan is
        made for it.

        Raises
        ------
        InputError
            ``goal`` is not on the track, or leaves the vehicles closer than the separation.
        """
        with self._lock:
            self.coordinator.request_goal(goal)

    def run(self, *, timeout: float) -> LiveRun:
        """Connect, plan, drive every vehicle to its goal, disconnect.

        Parameters
        ----------
        timeout : float
            Seconds of the run's clock from the start (planning included) after which it ends
            unfinished.

        Returns
        -------
        LiveRun
            With its ``error`` when it ended early (see :class:`LiveOutcome`).
        """
        self.start()
        try:
            self.wait(timeout=timeout)
        finally:
            self.stop()
        return self.result()

    def start(self) -> LiveMaster:
        """Connect, and plan (without a plan given), in the background; returns itself at once.

        The first orders go out once the plan is made, the broker is there and every vehicle stands
        where the plan starts it; an unreachable broker is retried until :meth:`wait` ends.
        """
        with self._lock:
            self.coordinator.start()
        self.link.start()
        return self

    def over(self) -> bool:
        """Whether the run has ended: every vehicle at its goal, or ended early (any reason)."""
        coordinator = self.coordinator
        return coordinator.done.is_set() or coordinator.over.is_set() or self.link.failed.is_set()

    def wait(self, *, timeout: float) -> bool:
        """Wait until the run is over (:meth:`over`) or ``timeout`` seconds of the run pass; whether it is."""
        deadline = self.clock.now() + timeout
        while not self.over():
            left = deadline - self.clock.now()
            if left <= 0.0:
                return False
            self.coordinator.done.wait(min(self.clock.wall_seconds(left), 0.05))
        return True

    def interrupt(self, reason: str) -> tuple:
        """Stop the run now: release nothing more and send each vehicle ``cancelOrder``.

        A vehicle that holds an order of this run (or of an earlier one) is told; each stops where it
        can within its released base. :meth:`wait_told` waits for their states to show it.

        Parameters
        ----------
        reason : str
            Why, for the log and the summary (``"SIGINT"``).

        Returns
        -------
        tuple of str
            The vehicles told.
        """
        with self._lock:
            return self.coordinator.interrupt(reason, linked=self.link.connected)

    def wait_told(self, timeout: float) -> bool:
        """Wait up to ``timeout`` wall seconds until every vehicle sent ``cancelOrder`` shows it.

        ``cancelOrder`` goes again every :data:`~trajgen.live.start_check.CANCEL_RESEND_S` to a vehicle
        that does not show it. Whether all show it.
        """
        deadline = time.monotonic() + timeout
        while True:
            with self._lock:
                if self.coordinator.cancels_shown(linked=self.link.connected):
                    return True
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.02)

    def stop(self) -> None:
        """Say OFFLINE on the master's connection topic, and disconnect."""
        with self._lock:
            self.coordinator.drop_plan()  # a plan still being made is never used
        if self.link.connected and self._client.is_connected():
            offline = self._master_connection("OFFLINE")
            info = self._client.publish(self._master.topic(Topic.CONNECTION), offline, qos=1, retain=True)
            info.wait_for_publish(1.0)
        self.link.close()

    def result(self) -> LiveRun:
        """The run so far (see :class:`LiveRun`); logs its end."""
        with self._lock:
            return self.coordinator.result(self.link, self.broker.url)
