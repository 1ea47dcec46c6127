"""What the live master knows of one vehicle: its path, its releases, its last report, its session."""

from __future__ import annotations

from topology import EdgePoint, Position
from trajgen.errors import InputError
from trajgen.live.mqtt import Topic, VehicleIdentity
from trajgen.live.outcome import LiveOutcome
from trajgen.live.places import path_place, reported_place

__all__ = [
    "GIVE_UP_AFTER_S",
    "NOT_TAKEN_AFTER",
    "NOT_TAKEN_WHY",
    "RESEND_INTERVAL_S",
    "RESEND_MAX_S",
    "VehicleView",
    "never_heard_message",
    "not_taken_message",
    "reported_order",
    "run_failure",
]

#: Wall seconds between re-sends to a vehicle whose states show it lacks the latest order (at first;
#: the wait doubles while re-sends change nothing).
RESEND_INTERVAL_S = 0.25
#: Longest wait between two re-sends to a vehicle whose states show it lacks the latest order.
RESEND_MAX_S = 8.0
#: The re-send interval at which an order not taken is reported (after three re-sends, about 2 s).
NOT_TAKEN_AFTER = 8 * RESEND_INTERVAL_S
#: Seconds of the run a vehicle's states may show that it lacks its latest order (while the order is
#: sent again, backing off) before the run ends as ``LiveOutcome.ORDER_NOT_TAKEN``.
GIVE_UP_AFTER_S = 30.0
#: Why a vehicle may not take its orders, said with it.
NOT_TAKEN_WHY = "the broker may refuse the master's publishes (an ACL) or the vehicle its orders"


def reported_order(state) -> str:
    """The order a vehicle's state (vda5050 State) says it holds, in words."""
    return f"order {state.order_id!r} update {state.order_update_id}" if state.order_id else "no order"


def not_taken_message(state, seconds: float) -> str:
    """Why a run ends when a vehicle's states showed for ``seconds`` that it lacks its order.

    The vehicle's own reasons (its state's errors) when it gives any; else what may keep an order
    from it (:data:`NOT_TAKEN_WHY`).
    """
    reasons = "; ".join(dict.fromkeys(f"{e.error_type}: {e.error_description}" for e in state.errors))
    why = f"it says {reasons}" if reasons else NOT_TAKEN_WHY
    return f"has not taken its order in {seconds:g} s of re-sends (it reports {reported_order(state)}): {why}"


def never_heard_message(silent) -> str:
    """Which vehicles (views) were never heard, and where the master listened for them."""
    topics = ", ".join(view.identity.topic(Topic.CONNECTION) for view in silent)
    names = " and ".join(view.name for view in silent)
    return f"{names} never came online (nothing on {topics}; are they started, with these serial numbers?)"


def run_failure(outcome, link, *, why: str | None, broker_url: str) -> str | None:
    """Why a live run ended early (its :class:`~trajgen.live.outcome.LiveOutcome`), or ``None``.

    ``link``: the master's BrokerLink; ``why``: the master's own reason (a refusal, a vehicle given
    up, a signal, what the first orders still waited for).
    """
    if outcome is LiveOutcome.BROKER_FAILED:
        return link.failure
    if outcome is LiveOutcome.TIMED_OUT and not link.ever_connected:
        return f"master: the broker {broker_url} was never reached (retried until the time limit)"
    return why


class VehicleView:
    """What the master knows of one vehicle."""

    def __init__(self, name: str, identity: VehicleIdentity) -> None:
        self.name = name
        self.identity = identity
        self.path = None  # OrderPath of the current plan
        self.arcs: list[float] = []  # distance along the whole run at each node of the current path
        self.offset = 0  # sequenceId of the current path's node 0
        self.update = -1  # the latest orderUpdateId sent
        self.plan_update = 0  # the orderUpdateId of the current plan's first order (update)
        self.order = None  # the latest order (update) sent (vda5050 Order); a re-send gets a new header
        self.resend_after = RESEND_INTERVAL_S  # wall seconds: doubles while re-sends change nothing
        self.sent_at = -float("inf")  # wall time of the latest send
        self.lacking_since: float | None = None  # run time its states began to lack the latest order
        self.header = 0
        self.action_header = 0  # headerId of its instantActions
        self.state_header: int | None = None
        self.node = 0  # last node reached (index on the current path)
        self.driving = False
        self.online: bool | None = None
        self.heard = False  # ONLINE or a state came from it
        self.place = None  # where its latest state puts it (Position or EdgePoint); None: not said
        self.unplaced: str | None = None  # why its latest state places it nowhere on the track
        self.foreign: str | None = None  # the orderId of an earlier run's order it still holds, active
        self.taken = False  # its states show it holds the current plan's order
        self.off_plan: str | None = None  # why its latest state puts it off its plan (releases held)
        self.cancelled: str | None = None  # the actionId of the cancelOrder sent to it
        self.cancelled_order: str | None = None  # the earlier run's order it was sent to cancel
        self.cancel_sent_at = -float("inf")  # wall time of the latest cancelOrder sent
        self.told = False  # its state shows the cancelOrder (running or finished)
        self.off_plan_since: float | None = None  # run time its states began to put it off its plan
        self.errors: set[str] = set()
        self.record: dict = {}
        self.elements: list = []  # [(nodes, edges) in horizon, (nodes, edges) in base]
        self.rejoined = False  # back online: its first state tells whether it kept its order
        self.restart: Position | EdgePoint | None = None  # where it stands after a restart without its order

    def standing(self, graph) -> Position | EdgePoint:
        """Where it stands: where it restarted, else the last node of its path it reached.

        A Position on a junction, an EdgePoint on a track graph.
        """
        if self.restart is not None:
            return self.restart
        return path_place(graph, self.path, self.node, 0.0)

    def adopt(self, path, *, offset: int, elements, first: bool) -> None:
        """Take its path of a new plan (an order path), numbered from ``offset``, its order elements.

        ``first``: the run's first plan (its travel from 0); else the travel goes on from the node it
        reached.
        """
        start = 0.0 if first else self.arcs[self.node]
        self.offset = offset
        self.path = path
        self.arcs = [start]
        for edge in path.edges:
            self.arcs.append(self.arcs[-1] + edge.length)
        self.node = 0
        self.restart = None
        self.taken = False
        self.plan_update = self.update + 1
        self.elements = elements

    def base_node(self, state, released: int) -> int | None:
        """The index on its path of the node its ``state`` says it reached, if on its base.

        ``None``: the state's last node (``lastNodeId``, ``lastNodeSequenceId``) is not a node of its
        path up to node ``released`` (it stands off its plan).
        """
        j, odd = divmod(state.last_node_sequence_id - self.offset, 2)
        on = 0 <= j <= released and not odd and state.last_node_id == self.path.node_id(j)
        return j if on else None

    def connection(self, online: bool, *, running: bool) -> bool:
        """Its connection state said: ONLINE (``online``) or not; whether it changed.

        Back online while the run goes (``running``), its next state tells whether it kept its order;
        a vehicle that restarted counts its headers afresh.
        """
        if online == self.online:
            return False
        back = self.online is False  # None: the first news (a retained message), after the first order
        self.online = online
        if online:
            self.state_header = None
            self.rejoined = back and running
            self.heard = True
        return True

    def take_place(self, graph, state, order_id: str):
        """Before the run: where its ``state`` puts it (or ``None``), whether it drives, an earlier order.

        ``order_id``: this run's for it: an active order under another id is an earlier run's
        (:attr:`foreign`). A place the track does not have leaves :attr:`place` ``None`` and says why
        in :attr:`unplaced`.
        """
        self.driving = state.driving
        active = bool(state.node_states or state.edge_states)
        self.foreign = state.order_id if state.order_id and active and state.order_id != order_id else None
        try:
            place = reported_place(graph, state)
        except InputError as error:
            self.unplaced, self.place = str(error), None
            return None
        self.unplaced = None
        if place is None:
            self.place = None
        return place

    def at_goal(self) -> bool:
        """Whether it reported the last node of its path."""
        return bool(self.arcs) and self.node == len(self.arcs) - 1

    def state_record(self, state, j: int, t: float) -> dict:
        """The run log's record of ``state``, which says it reached node ``j``, at run time ``t``."""
        position = state.agv_position
        return {
            "t": t,
            "event": "state",
            "vehicle": self.name,
            "x": position.x if position else None,
            "y": position.y if position else None,
            "node": self.node + self.offset // 2,
            "along_m": self.arcs[j] + (state.distance_since_last_node or 0.0),
            "driving": state.driving,
        }

    def new_errors(self, state) -> list[tuple[str, str]]:
        """``(errorType, errorDescription)`` of the state's errors not reported before (each once)."""
        new = []
        for error in state.errors:
            if error.error_description not in self.errors:
                self.errors.add(error.error_description)
                new.append((error.error_type, error.error_description))
        return new
