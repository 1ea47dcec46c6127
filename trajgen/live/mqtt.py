"""Where the broker is and how to log in, each vehicle's VDA 5050 topics, and the MQTT client.

VDA 5050 gives every vehicle its own topics,
``<interface>/<major version>/<manufacturer>/<serial number>/<topic>``
(``uagv/v2/unspecified/agv1/order``). The master publishes ``order`` and
``instantActions`` (``cancelOrder`` when it stops); a vehicle publishes ``state``
and, retained, ``connection`` (with a last will of ``CONNECTIONBROKEN`` that the
broker sends when the vehicle drops off). The master says its own connection the
same way, on the topics of a serial number of its own, :data:`MASTER_SERIAL`
(``uagv/v2/unspecified/master/connection``): vehicles see its last will.
The client is paho-mqtt 2.x, driven by its own network thread, which
reconnects by itself after the broker restarts.
"""

from __future__ import annotations

import importlib
import logging
import re
import ssl
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

from topology.validation import short_repr
from trajgen.errors import InputError, MissingExtraError

__all__ = [
    "DEFAULT_INTERFACE",
    "DEFAULT_VERSION",
    "LIVE_EXTRA",
    "MASTER_SERIAL",
    "BrokerSettings",
    "Topic",
    "VehicleIdentity",
    "make_client",
    "require_live",
]

logger = logging.getLogger(__name__)

#: The VDA 5050 interface name (first topic level).
DEFAULT_INTERFACE = "uagv"
#: The major version of the protocol (second topic level).
DEFAULT_VERSION = "v2"
#: What a topic level may contain (MQTT forbids '/', '+' and '#' inside one).
_LEVEL = re.compile(r"[^/+#\s]+")
#: Seconds between a lost connection and the first reconnection attempt, and the longest wait.
_RECONNECT_MIN_S, _RECONNECT_MAX_S = 0.1, 2.0


#: The serial-number level of the master's own topics (its ``connection``): no vehicle may take it.
MASTER_SERIAL = "master"


class Topic:
    """The VDA 5050 topic names used here."""

    ORDER = "order"
    INSTANT_ACTIONS = "instantActions"
    STATE = "state"
    CONNECTION = "connection"


def _level(value: object, what: str) -> str:
    if not isinstance(value, str) or not _LEVEL.fullmatch(value):
        raise InputError(
            f"{what} {short_repr(value)} is not an MQTT topic level: expected text without '/', '+', "
            "'#' or spaces"
        )
    return value


@dataclass(frozen=True, slots=True)
class VehicleIdentity:
    """Who a vehicle is on the broker.

    Parameters
    ----------
    manufacturer, serial_number : str
        The message headers' ``manufacturer`` and ``serialNumber``.
    interface : str
        First topic level (default ``"uagv"``).
    version : str
        Second topic level, the protocol's major version (default ``"v2"``).
    """

    manufacturer: str
    serial_number: str
    interface: str = DEFAULT_INTERFACE
    version: str = DEFAULT_VERSION

    def __post_init__(self) -> None:
        _level(self.manufacturer, "VDA 5050 manufacturer")
        _level(self.serial_number, "VDA 5050 serial number")
        _level(self.interface, "VDA 5050 interface name")
        _level(self.version, "VDA 5050 version")

    def topic(self, name: str) -> str:
        """The full topic of ``name`` (``"order"``, ``"state"``, ``"connection"``) for this vehicle."""
        return f"{self.interface}/{self.version}/{self.manufacturer}/{self.serial_number}/{name}"

    @property
    def master(self) -> VehicleIdentity:
        """The identity of the master of this vehicle: same interface, version and manufacturer."""
        return VehicleIdentity(self.manufacturer, MASTER_SERIAL, self.interface, self.version)


@dataclass(frozen=True, slots=True, kw_only=True)
class BrokerSettings:
    """How to reach the MQTT broker.

    Parameters
    ----------
    host : str
    port : int
        1 to 65535.
    tls : bool
        Connect over TLS (``mqtts://`` URLs do).
    cafile : Path or None
        Certificate authority file for TLS; ``None``: the system's.
    username, password : str or None
        Login; the password is never shown in a repr or a message.
    """

    host: str
    port: int
    tls: bool = False
    cafile: Path | None = None
    username: str | None = None
    password: str | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.host, str) or not self.host:
            raise InputError(f"broker host {short_repr(self.host)} is empty: expected a host name or address")
        if isinstance(self.port, bool) or not isinstance(self.port, int) or not 1 <= self.port <= 65535:
            raise InputError(f"broker port {short_repr(self.port)} is out of range: expected 1 to 65535")
        if self.cafile is not None and not Path(self.cafile).is_file():
            raise InputError(f"CA file {short_repr(str(self.cafile))} does not exist: expected a PEM file")
        if self.password is not None and self.username is None:
            raise InputError("a broker password was given without a username: expected both or neither")

    @property
    def url(self) -> str:
        """``mqtt://host:port`` (``mqtts://`` with TLS)."""
        return f"{'mqtts' if self.tls else 'mqtt'}://{self.host}:{self.port}"

    @classmethod
    def from_url(
        cls,
        url: str,
        *,
        username: str | None = None,
        password_file: str | Path | None = None,
        tls: bool = False,
        cafile: str | Path | None = None,
    ) -> BrokerSettings:
        """Settings from ``mqtt://HOST:PORT`` (or ``mqtts://``, ``HOST:PORT``).

        Parameters
        ----------
        url : str
            The port defaults to 1883 (8883 with TLS).
        username : str, optional
        password_file : path, optional
            A file whose first line is the password (kept out of the command line and the shell's
            history).
        tls : bool
            Connect over TLS even with an ``mqtt://`` URL.
        cafile : path, optional

        Raises
        ------
        InputError
            A URL, port or file that cannot be used, naming it.
        """
        if not isinstance(url, str) or not url:
            raise InputError(f"broker URL {short_repr(url)} is empty: expected mqtt://HOST:PORT")
        text = url if "://" in url else f"mqtt://{url}"
        parts = urlsplit(text)
        if parts.scheme not in ("mqtt", "mqtts", "tcp", "ssl"):
            raise InputError(
                f"broker URL {short_repr(url)} has scheme {parts.scheme!r}: expected mqtt:// or mqtts://"
            )
        secure = tls or parts.scheme in ("mqtts", "ssl")
        try:
            port = parts.port
        except ValueError:
            raise InputError(f"broker URL {short_repr(url)} has a bad port: expected 1 to 65535") from None
        if not parts.hostname:
            raise InputError(f"broker URL {short_repr(url)} names no host: expected mqtt://HOST:PORT")
        password = None
        if password_file is not None:
            try:
                lines = Path(password_file).read_text(encoding="utf-8").splitlines()
            except (OSError, UnicodeDecodeError) as error:
                name = short_repr(str(password_file))
                raise InputError(
                    f"password file {name} cannot be read ({error.__class__.__name__}): "
                    "expected a readable text file"
                ) from None
            password = lines[0] if lines else ""
        return cls(
            host=parts.hostname,
            port=port if port is not None else (8883 if secure else 1883),
            tls=secure,
            cafile=Path(cafile) if cafile is not None else None,
            username=username,
            password=password,
        )


#: The extra that installs what live runs need (the MQTT client, the embedded broker).
LIVE_EXTRA = "trajgen[live]"


def require_live(module: str, what: str) -> None:
    """Refuse ``what`` at once when ``module`` (``"paho"``, ``"amqtt"``) of the live extra is missing.

    Raises
    ------
    MissingExtraError
        ``module`` cannot be imported (``pip install trajgen`` without the ``live`` extra).
    """
    try:
        importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(
            f"{what} needs {module!r}, which is not installed: expected pip install '{LIVE_EXTRA}'"
        ) from None


def make_client(settings: BrokerSettings, client_id: str, *, will: tuple[str, bytes] | None = None):
    """A paho-mqtt 2.x client for ``settings``, not yet connected.

    Parameters
    ----------
    settings : BrokerSettings
    client_id : str
        Unique on the broker.
    will : (topic, payload), optional
        Published by the broker, retained with QoS 1, when the client drops off without saying so.

    Returns
    -------
    paho.mqtt.client.Client
        Reconnecting by itself (0.1 s after a loss, up to 2 s apart) once its loop runs.
    """
    require_live("paho", "an MQTT connection")
    import paho.mqtt.client as mqtt

    client = mqtt.Client(
        mqtt.CallbackAPIVersion.VERSION2, client_id=client_id, protocol=mqtt.MQTTv311, clean_session=True
    )
    paho_logger = logging.getLogger(f"{__name__}.paho")
    if paho_logger.isEnabledFor(logging.DEBUG):  # paho's own warnings repeat what the callbacks log
        client.enable_logger(paho_logger)
    client.reconnect_delay_set(min_delay=_RECONNECT_MIN_S, max_delay=_RECONNECT_MAX_S)
    if settings.username is not None:
        client.username_pw_set(settings.username, settings.password)
    if settings.tls:
        client.tls_set(
            ca_certs=str(settings.cafile) if settings.cafile else None, tls_version=ssl.PROTOCOL_TLS_CLIENT
        )
    if will is not None:
        client.will_set(will[0], will[1], qos=1, retain=True)
    return client
