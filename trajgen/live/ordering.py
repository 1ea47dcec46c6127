"""The master's messages to the vehicles: orders, order updates, their re-sends, ``cancelOrder``.

:class:`OrderDesk` builds each message from a vehicle's view and hands it to the outbox (the MQTT
client, in :class:`~trajgen.live.master.LiveMaster`); it counts and logs what it sent. A vehicle
whose states show it lacks its latest order gets it again, 0.25 s after the send and then twice as
long each time (at most 8 s apart), said after four sends.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

from trajgen.live.notices import cancel_order_message
from trajgen.live.orders import horizon_length, order_message
from trajgen.live.view import NOT_TAKEN_AFTER, NOT_TAKEN_WHY, RESEND_INTERVAL_S, RESEND_MAX_S, reported_order

__all__ = ["OrderDesk"]

logger = logging.getLogger(__name__)
#: Log lines that the run log says too (``timeline``: left off stderr while a command prints it).
said = logging.LoggerAdapter(logger, {"timeline": True})


class OrderDesk:
    """Send each vehicle its orders, again when its states lag, and ``cancelOrder``.

    Parameters
    ----------
    views : list of VehicleView
    outbox
        ``order(v, payload)`` and ``instant_actions(v, payload)``: publish to vehicle ``v``.
    limits : sequence of VehicleLimits
        Per vehicle (its horizon: its stop from full speed).
    order_ids : sequence of str
        Per vehicle, its ``orderId`` in this run.
    run_id : str
        This run's id (in ``cancelOrder``'s ``actionId``).
    clock : RunClock
    write : callable
        ``write(event, **fields)``: a record of the run log.
    """

    def __init__(self, views, outbox, *, limits, order_ids, run_id: str, clock, write: Callable) -> None:
        self.views = views
        self.outbox = outbox
        self.order_ids = tuple(order_ids)
        self.run_id = run_id
        self.clock = clock
        self.write = write
        self.horizons = [horizon_length(each) for each in limits]
        self.sent = 0  # orders and updates published, re-sends included
        self.resent = 0

    def _publish(self, v: int, payload: bytes, *, resent: bool, record: dict) -> None:
        view = self.views[v]
        self.outbox.order(v, payload)
        view.sent_at = time.monotonic()
        self.sent += 1
        self.resent += resent
        self.write("order", vehicle=view.name, resent=resent, **record)

    def send(self, v: int, first: int, decision_point: int) -> None:
        """Vehicle ``v``'s order (update) from node ``first``, its base up to ``decision_point``."""
        view = self.views[v]
        order = order_message(
            view,
            first=first,
            decision_point=decision_point,
            horizon_m=self.horizons[v],
            order_id=self.order_ids[v],
            timestamp=self.clock.timestamp(),
        )
        view.update += 1
        view.order = order
        view.resend_after = RESEND_INTERVAL_S
        view.lacking_since = None  # a new order: what the vehicle lacked is another
        view.record = {
            "update": view.update,
            "first": first,
            "decision_point": decision_point,
            "frontier_m": view.arcs[decision_point],
        }
        self._publish(v, order.to_json().encode(), resent=False, record=view.record)

    def resend(self, v: int) -> None:
        """The latest order (update) again, under a new headerId (VDA 5050: one per message)."""
        view = self.views[v]
        if view.order is not None:
            view.header += 1
            header = {"header_id": view.header, "timestamp": self.clock.timestamp()}
            again = view.order.model_copy(update=header)
            self._publish(v, again.to_json().encode(), resent=True, record=view.record)

    def resend_if_due(self, v: int, state) -> None:
        """Vehicle ``v``'s ``state`` shows it lacks its latest order: again, if the back-off allows."""
        view = self.views[v]
        if time.monotonic() - view.sent_at < view.resend_after:
            return
        logger.debug("master: %s has not the latest order: sent again", view.name)
        self.resend(v)
        view.resend_after = min(2.0 * view.resend_after, RESEND_MAX_S)
        if view.resend_after == NOT_TAKEN_AFTER:  # said once per order
            held = reported_order(state)
            why = "it gave its reason above" if state.errors else NOT_TAKEN_WHY
            said.warning(
                "master: %s has not taken its order (it reports %s after 4 sends): %s", view.name, held, why
            )
            self.write("order-not-taken", vehicle=view.name, reports=held)

    def cancels_shown(self, *, linked: bool, every: float) -> bool:
        """Whether every vehicle sent ``cancelOrder`` shows it; again where due (``linked``: link up).

        Again to a vehicle whose states have not shown it for ``every`` wall seconds.
        """
        waiting = [v for v, view in enumerate(self.views) if view.cancelled is not None and not view.told]
        for v in waiting if linked else ():
            if time.monotonic() - self.views[v].cancel_sent_at >= every:
                self.cancel(v, "sent again: not yet shown in its state", again=True)
        return not waiting

    def cancel(self, v: int, why: str, *, again: bool = False) -> None:
        """``cancelOrder`` to vehicle ``v`` (``again``: the same action); it stops within its base."""
        view = self.views[v]
        view.action_header += 1
        if not again:
            view.cancelled = f"cancel-{self.run_id}-{view.name}-{view.action_header}"
            view.told = False
        payload = cancel_order_message(
            view.identity,
            action_id=view.cancelled,
            header=view.action_header,
            timestamp=self.clock.timestamp(),
        )
        self.outbox.instant_actions(v, payload)
        view.cancel_sent_at = time.monotonic()
        self.write("cancel", vehicle=view.name, reason=why)
        said.info("master: cancelOrder to %s: %s", view.name, why)
