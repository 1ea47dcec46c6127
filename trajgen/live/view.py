"""What the live master knows of one vehicle: its path, its releases, its last report, its session."""

from __future__ import annotations

from topology import JUNCTION_INDEX, EdgePoint, Position
from trajgen.export.vda5050.graph_path import GraphPathNode
from trajgen.live.mqtt import Topic, VehicleIdentity
from trajgen.live.outcome import LiveOutcome

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
    """Why a run ends when a vehicle's states showed for ``seconds`` that it lacks its order."""
    said = dict.fromkeys(f"; {e.error_type}: {e.error_description}" for e in state.errors)  # each once
    errors = "".join(said)
    return (
        f"has not taken its order in {seconds:g} s of re-sends (it reports {reported_order(state)}"
        f"{errors}): {NOT_TAKEN_WHY}"
    )


def never_heard_message(silent) -> str:
    """Which vehicles (views) were never heard, and where the master listened for them."""
    topics = ", ".join(view.identity.topic(Topic.CONNECTION) for view in silent)
    names = " and ".join(view.name for view in silent)
    return f"{names} never came online (nothing on {topics}; are they started, with these serial numbers?)"


def run_failure(outcome, link, *, gave_up: str | None, broker_url: str, sent: bool, silent) -> str | None:
    """Why a live run ended early (its :class:`~trajgen.live.outcome.LiveOutcome`), or ``None``.

    ``link``: the master's BrokerLink; ``gave_up``: why it gave a vehicle up; ``sent``: whether the
    first orders went out; ``silent``: the views of vehicles never heard.
    """
    if outcome is LiveOutcome.BROKER_FAILED:
        return link.failure
    if outcome is LiveOutcome.ORDER_NOT_TAKEN:
        return gave_up
    if outcome is LiveOutcome.TIMED_OUT and not link.ever_connected:
        return f"master: the broker {broker_url} was never reached (retried until the time limit)"
    if outcome is LiveOutcome.TIMED_OUT and not sent and silent:
        return f"master: no order was sent: {never_heard_message(silent)}"
    return None


class VehicleView:
    """What the master knows of one vehicle."""

    def __init__(self, name: str, identity: VehicleIdentity) -> None:
        self.name = name
        self.identity = identity
        self.path = None  # OrderPath of the current plan
        self.arcs: list[float] = []  # distance along the whole run at each node of the current path
        self.offset = 0  # sequenceId of the current path's node 0
        self.update = -1  # the latest orderUpdateId sent
        self.order = None  # the latest order (update) sent (vda5050 Order); a re-send gets a new header
        self.resend_after = RESEND_INTERVAL_S  # wall seconds: doubles while re-sends change nothing
        self.sent_at = -float("inf")  # wall time of the latest send
        self.lacking_since: float | None = None  # run time its states began to lack the latest order
        self.header = 0
        self.state_header: int | None = None
        self.node = 0  # last node reached (index on the current path)
        self.driving = False
        self.online: bool | None = None
        self.heard = False  # ONLINE or a state came from it: the run can begin
        self.errors: set[str] = set()
        self.record: dict = {}
        self.elements: list = []  # [(nodes, edges) in horizon, (nodes, edges) in base]
        self.rejoined = False  # back online: its first state tells whether it kept its order
        self.restart: Position | None = None  # where it stands after a restart without its order

    def standing(self, graph) -> Position | EdgePoint:
        """Where it stands: where it restarted, else the last node of its path it reached.

        A Position on a junction, an EdgePoint on a track graph.
        """
        if self.restart is not None:
            return self.restart
        node = self.path.nodes[self.node]
        if isinstance(node, GraphPathNode):
            return node.point
        return Position(None, 0.0) if node.leg == JUNCTION_INDEX else Position(graph.names[node.leg], node.s)

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
