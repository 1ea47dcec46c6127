"""What the live master knows of one vehicle: its path, its releases, its last report, its session."""

from __future__ import annotations

from topology import Position
from trajgen.live.mqtt import VehicleIdentity

__all__ = ["RESEND_INTERVAL_S", "VehicleView"]

#: Wall seconds between re-sends to a vehicle whose states show it lacks the latest order (at first;
#: the wait doubles while re-sends change nothing).
RESEND_INTERVAL_S = 0.25


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
        self.header = 0
        self.state_header: int | None = None
        self.node = 0  # last node reached (index on the current path)
        self.driving = False
        self.online: bool | None = None
        self.errors: set[str] = set()
        self.record: dict = {}
        self.elements: list = []  # [(nodes, edges) in horizon, (nodes, edges) in base]
        self.rejoined = False  # back online: its first state tells whether it kept its order
        self.restart: Position | None = None  # where it stands after a restart without its order
