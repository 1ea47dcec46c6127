"""The messages besides orders and states: a connection state, and ``cancelOrder``.

A vehicle says ``connection`` ``ONLINE`` when it connects, ``OFFLINE`` when it stops, and its
broker says ``CONNECTIONBROKEN`` (its last will) when it drops off; the live master does the same
on a topic of its own (:attr:`~trajgen.live.mqtt.VehicleIdentity.master`), so that vehicles see
the master's last will. ``cancelOrder`` is the VDA 5050 instant action by which the master tells
a vehicle that the run is over: the vehicle stops where it can, within its released base.
"""

from __future__ import annotations

from trajgen.live.mqtt import VehicleIdentity

__all__ = ["CANCEL_ORDER", "VDA5050_VERSION", "cancel_order_message", "connection_message"]

#: The protocol version every message says.
VDA5050_VERSION = "2.1.0"
#: The ``actionType`` of the instant action that ends a vehicle's order.
CANCEL_ORDER = "cancelOrder"


def _header(identity: VehicleIdentity, header: int, timestamp: str) -> dict:
    """The header fields every message of ``identity`` carries."""
    return {
        "header_id": header,
        "timestamp": timestamp,
        "version": VDA5050_VERSION,
        "manufacturer": identity.manufacturer,
        "serial_number": identity.serial_number,
    }


def connection_message(identity: VehicleIdentity, state: str, *, header: int, timestamp: str) -> bytes:
    """A ``connection`` message of ``identity`` (``ONLINE``, ``OFFLINE`` or ``CONNECTIONBROKEN``)."""
    from vda5050.model.connection import Connection

    message = Connection(**_header(identity, header, timestamp), connection_state=state)
    return message.to_json().encode()


def cancel_order_message(identity: VehicleIdentity, *, action_id: str, header: int, timestamp: str) -> bytes:
    """``instantActions`` with one ``cancelOrder`` for ``identity`` (VDA 5050 section 6.6.3)."""
    from vda5050.model.instant_actions import InstantActions

    message = InstantActions(
        **_header(identity, header, timestamp),
        actions=[{"action_type": CANCEL_ORDER, "action_id": action_id, "blocking_type": "HARD"}],
    )
    return message.to_json().encode()
