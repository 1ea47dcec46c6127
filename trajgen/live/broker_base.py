"""What the test and demo brokers share: the address, the port held for them, the start probe, the base class.

:class:`Broker` is the interface of :class:`~trajgen.live.broker.EmbeddedBroker` (amqtt in this
process) and :class:`~trajgen.live.mosquitto.MosquittoBroker` (a mosquitto process): both listen on
:data:`HOST` only, on a port held from their construction and kept across a restart.
"""

from __future__ import annotations

import errno
import socket
import threading
import time
import weakref
from collections.abc import Callable
from typing import Self

from topology.validation import finite_real, short_repr
from trajgen.errors import InputError, LiveError

__all__ = [
    "HOST",
    "POLL_S",
    "REBIND_TIMEOUT_S",
    "START_TIMEOUT_S",
    "STOP_TIMEOUT_S",
    "THREAD_NAME",
    "Broker",
    "answers",
    "reserved_port",
    "wait_until_bindable",
]

#: The address the brokers listen on: this machine only.
HOST = "127.0.0.1"
#: Seconds a broker may take to accept connections once started.
START_TIMEOUT_S = 10.0
#: Seconds a start waits for its port to become free again (a listening socket still closing).
REBIND_TIMEOUT_S = 2.0
#: Seconds a stop waits for the broker to close its connections and end.
STOP_TIMEOUT_S = 5.0
#: Seconds between two attempts to reach a starting broker.
POLL_S = 0.02
#: The name of the embedded broker's thread.
THREAD_NAME = "trajgen-broker"
#: An MQTT 3.1.1 CONNECT (clean session, keep-alive 10 s, empty client id: the broker names it), the
#: CONNACK that accepts it, and a DISCONNECT: how a start checks that the broker answers.
_PROBE_CONNECT = bytes((0x10, 12, 0, 4)) + b"MQTT" + bytes((4, 0x02, 0, 10, 0, 0))
_PROBE_CONNACK = bytes((0x20, 2, 0, 0))
_PROBE_DISCONNECT = bytes((0xE0, 0))


def reserved_port() -> socket.socket:
    """A socket bound to a free port of :data:`HOST`, not listening: it holds the port for a broker.

    Only sockets with ``SO_REUSEADDR`` (the brokers') may bind the port then, and no client gets it as
    its own port: one dialling it before the broker listens could otherwise connect to itself.
    """
    reservation = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    reservation.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    reservation.bind((HOST, 0))
    return reservation


def wait_until_bindable(port: int, what: str) -> None:
    """Return once a listening socket with ``SO_REUSEADDR`` could bind ``port``; wait up to 2 s.

    Raises
    ------
    LiveError
        The port is still taken after :data:`REBIND_TIMEOUT_S` seconds (by another program).
    """
    deadline = time.monotonic() + REBIND_TIMEOUT_S
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as trial:
            trial.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                trial.bind((HOST, port))
                return
            except OSError as error:
                if error.errno != errno.EADDRINUSE or time.monotonic() >= deadline:
                    raise LiveError(
                        f"{what} cannot listen on {HOST}:{port}: {error.strerror or error} "
                        f"(still so after {REBIND_TIMEOUT_S:g} s): expected a free port"
                    ) from None
        time.sleep(POLL_S)


def answers(port: int, timeout: float) -> bool:
    """Whether an MQTT broker on ``port`` of :data:`HOST` accepts a connection within ``timeout`` s.

    The check connects, sends a CONNECT, waits for the CONNACK accepting it and says
    DISCONNECT: a bare TCP connection without CONNECT would make the broker log an error.
    """
    try:
        with socket.create_connection((HOST, port), timeout=max(timeout, 0.05)) as probe:
            probe.sendall(_PROBE_CONNECT)
            reply = b""
            while len(reply) < len(_PROBE_CONNACK):
                chunk = probe.recv(len(_PROBE_CONNACK) - len(reply))
                if not chunk:
                    return False
                reply += chunk
            if reply != _PROBE_CONNACK:
                return False
            probe.sendall(_PROBE_DISCONNECT)
            return True
    except OSError:
        return False


class Broker:
    """What both brokers share: the address, the context manager and the restart."""

    #: A name for messages.
    kind = "MQTT broker"

    def __init__(self, *, port: int | None = None) -> None:
        if port is not None and (isinstance(port, bool) or not isinstance(port, int) or not 0 < port < 65536):
            raise InputError(
                f"broker port {short_repr(port)} is out of range: expected 1 to 65535 (None: a free port)"
            )
        if port is None:
            reservation = reserved_port()
            port = reservation.getsockname()[1]
            weakref.finalize(self, reservation.close)
        self._port = port
        #: held while it starts, stops or restarts
        self.lock = threading.RLock()

    @property
    def host(self) -> str:
        """The address the broker listens on, ``"127.0.0.1"``."""
        return HOST

    @property
    def port(self) -> int:
        """The TCP port the broker listens on, the same across restarts."""
        return self._port

    @property
    def url(self) -> str:
        """``mqtt://127.0.0.1:PORT``."""
        return f"mqtt://{HOST}:{self._port}"

    @property
    def running(self) -> bool:
        """Whether the broker is started (and not stopped since)."""
        raise NotImplementedError

    def start(self) -> Self:
        """Start the broker; return once it accepts connections (see the subclasses)."""
        raise NotImplementedError

    def stop(self) -> None:
        """Stop the broker (see the subclasses)."""
        raise NotImplementedError

    def restart(self, *, down_for: float = 0.0) -> None:
        """Stop the broker, wait, and start it again on the same port.

        Every client loses its connection and its session; clients that reconnect by
        themselves find the broker again once it is back.

        Parameters
        ----------
        down_for : float
            Seconds (wall clock) between the stop and the start, at least 0.

        Raises
        ------
        InputError
            ``down_for`` is negative or not a finite number.
        LiveError
            The broker does not start again (see :meth:`start`).
        """
        pause = finite_real(down_for, "the time the broker is down, down_for (s),", InputError)
        if pause < 0:
            raise InputError(f"the time the broker is down, down_for (s), must be at least 0, got {pause!r}")
        with self.lock:
            self.stop()
            time.sleep(pause)
            self.start()

    def wait_until_answering(self, deadline: float, alive: Callable[[], bool]) -> None:
        """Poll the port until the broker answers; raise :class:`LiveError` at ``deadline``."""
        while True:
            if answers(self._port, deadline - time.monotonic()):
                return
            if not alive():
                raise LiveError(f"the {self.kind} on {self.url} ended before it accepted connections")
            if time.monotonic() >= deadline:
                raise LiveError(
                    f"the {self.kind} on {self.url} did not accept connections within {START_TIMEOUT_S:g} s"
                )
            time.sleep(POLL_S)

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def __repr__(self) -> str:
        return f"{type(self).__name__}(port={self._port}, running={self.running})"
