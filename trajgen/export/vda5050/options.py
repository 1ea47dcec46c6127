"""The options of the VDA 5050 messages (start time, map, order id, vehicle ids, header ids) and their checks.

Every field a message takes from the caller is checked when the options are
made, so a :class:`Vda5050Options` always renders messages that the protocol
and the MQTT topics accept.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime

from topology.validation import short_repr
from trajgen.errors import OptionError

__all__ = [
    "FIRST_YEAR",
    "LAST_YEAR",
    "MANIFEST_NAME",
    "MAX_FIRST_HEADER_ID",
    "SERIAL_NUMBER",
    "Vda5050Options",
]

#: Name of the index file written beside the vehicles' folders.
MANIFEST_NAME = "manifest.json"

#: The characters VDA 5050 allows in a serial number (it is part of the MQTT topic).
SERIAL_NUMBER = re.compile(r"[A-Za-z0-9_.:-]+")
#: The years a start time may fall in (its timestamps must stay representable).
FIRST_YEAR, LAST_YEAR = 1970, 9000
#: Largest ``first_header_id``: header ids are uint32, and a run sends far fewer than a million messages.
MAX_FIRST_HEADER_ID = 2**32 - 1 - 1_000_000


@dataclass(frozen=True, slots=True, kw_only=True)
class Vda5050Options:
    """How the VDA 5050 messages are written.

    Parameters
    ----------
    start_time : datetime
        When the schedule starts (time zone aware); each message's
        ``timestamp`` is this plus its ``send_at``. Required: the same
        start time gives the same bytes.
    map_id : str
        ``nodePosition.mapId`` (default ``"trajgen"``).
    order_id : str
        Prefix of the ``orderId``: ``<order_id>-<vehicle name>`` (default ``"trajgen"``).
    manufacturers : tuple of str
        ``manufacturer`` of each vehicle, or one for every vehicle (default ``"unspecified"``).
    serial_numbers : tuple of str or None
        ``serialNumber`` of each vehicle; ``None`` (default): the vehicle names.
    first_header_id : int
        ``headerId`` of each vehicle's first message (default 0); it grows by 1 with each message.
    """

    start_time: datetime
    map_id: str = "trajgen"
    order_id: str = "trajgen"
    manufacturers: tuple[str, ...] = ("unspecified",)
    serial_numbers: tuple[str, ...] | None = None
    first_header_id: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.start_time, datetime) or self.start_time.utcoffset() is None:
            raise OptionError(
                f"VDA 5050 start_time must be a time zone aware datetime, got {short_repr(self.start_time)}"
            )
        try:
            start = self.start_time.astimezone(UTC)
        except OverflowError:
            start = None
        if start is None or not FIRST_YEAR <= start.year <= LAST_YEAR:
            raise OptionError(
                f"VDA 5050 start_time {short_repr(str(self.start_time))} is out of range: expected a time "
                f"from the years {FIRST_YEAR} to {LAST_YEAR} (UTC)"
            )
        object.__setattr__(self, "start_time", start)
        for name in ("map_id", "order_id"):
            _check_text(getattr(self, name), f"VDA 5050 {name}")
        manufacturers = _texts(self.manufacturers, "manufacturers")
        for value in manufacturers:
            if any(character in value for character in "/#+"):
                raise OptionError(
                    f"VDA 5050 manufacturer {short_repr(value)} has '/', '#' or '+': it is part of the "
                    "MQTT topic; expected none of them"
                )
        object.__setattr__(self, "manufacturers", manufacturers)
        if self.serial_numbers is not None:
            serials = _texts(self.serial_numbers, "serial_numbers")
            for value in serials:
                if not SERIAL_NUMBER.fullmatch(value):
                    raise OptionError(
                        f"VDA 5050 serial number {short_repr(value)} is not allowed: expected the characters "
                        "A-Z a-z 0-9 _ . : - only"
                    )
            object.__setattr__(self, "serial_numbers", serials)
            if len(manufacturers) not in (1, len(serials)):
                raise OptionError(
                    f"VDA 5050 manufacturers: {len(manufacturers)} given for {len(serials)} serial numbers: "
                    "expected one, or one per vehicle"
                )
            topics = {}
            for vehicle, serial in enumerate(serials):
                other = topics.setdefault((self.manufacturer(vehicle), serial), vehicle)
                if other != vehicle:
                    raise OptionError(
                        f"VDA 5050 serial numbers of vehicles {other + 1} and {vehicle + 1} are both "
                        f"{serial!r} with one manufacturer: expected one MQTT topic per vehicle"
                    )
        value = self.first_header_id
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_FIRST_HEADER_ID:
            raise OptionError(
                f"VDA 5050 first_header_id must be an integer from 0 to {MAX_FIRST_HEADER_ID:,}, "
                f"got {short_repr(value)}"
            )

    def manufacturer(self, vehicle: int) -> str:
        """``manufacturer`` of ``vehicle`` (its index, 0 for vehicle 1)."""
        return self.manufacturers[0] if len(self.manufacturers) == 1 else self.manufacturers[vehicle]

    def serial_number(self, vehicle: int, names: Sequence[str]) -> str:
        """``serialNumber`` of ``vehicle`` (its index) named ``names[vehicle]``."""
        return names[vehicle] if self.serial_numbers is None else self.serial_numbers[vehicle]

    def check_vehicles(self, count: int) -> None:
        """Refuse options that do not name ``count`` vehicles (one manufacturer may serve them all).

        Raises
        ------
        OptionError
            Naming the option, its number of values and the vehicles'.
        """
        if len(self.manufacturers) not in (1, count):
            raise OptionError(
                f"VDA 5050 manufacturers: {len(self.manufacturers)} given: expected one, or one per vehicle "
                f"({count})"
            )
        if self.serial_numbers is not None and len(self.serial_numbers) != count:
            raise OptionError(
                f"VDA 5050 serial_numbers: {len(self.serial_numbers)} given: expected one per vehicle "
                f"({count})"
            )


def _check_text(value: object, what: str) -> str:
    if not isinstance(value, str) or not value or not value.isprintable():
        raise OptionError(f"{what} must be a non-empty printable string, got {short_repr(value)}")
    return value


def _texts(value: object, what: str) -> tuple[str, ...]:
    if isinstance(value, str) or not isinstance(value, (tuple, list)) or not value:
        raise OptionError(f"VDA 5050 {what} must be a sequence of strings, one per vehicle, got {value!r}")
    return tuple(_check_text(text, f"VDA 5050 {what}[{k}]") for k, text in enumerate(value))
