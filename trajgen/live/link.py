"""A watched connection to the MQTT broker: every change said once, retries that back off, final errors.

The master and each vehicle hold their paho client through a :class:`BrokerLink`. It makes the
first connection itself, in a thread of its own, and classifies what goes wrong:

* **the broker cannot be reached** (nothing listens, a host that does not answer, a name that does
  not resolve): retried, 0.5 s after the first failure and then twice as long each time, at most
  :data:`RETRY_MAX_S` apart, said once (``cannot reach mqtt://...: <reason>; retrying every ...``);
* **final** (retrying cannot help): the broker refused the login (wrong password, no username, not
  authorized), the broker's TLS certificate is not trusted (a wrong CA), TLS spoken to a plain
  listener, or a plain client on a TLS listener (the broker closes the connection before its
  CONNACK, twice in a row). The link then stops, ``BrokerLink.failure`` says why in one plain
  sentence and ``BrokerLink.failed`` is set: the owner ends its run (exit status 1).

Once connected, paho's own thread keeps the connection and reconnects after a loss; the link says
``lost the broker`` once, and ``connected again`` when it is back. A login refused on reconnection
is final too.
"""

from __future__ import annotations

import enum
import logging
import ssl
import threading
import time
from collections.abc import Callable

__all__ = ["RETRY_MAX_S", "BrokerLink", "LinkState"]

logger = logging.getLogger(__name__)

#: Seconds before the first retry of an unreachable broker; each retry waits twice as long, at most
#: :data:`RETRY_MAX_S`.
RETRY_MIN_S = 0.5
RETRY_MAX_S = 5.0
#: Seconds a connection waits for the broker's CONNACK before it counts as unanswered.
CONNACK_TIMEOUT_S = 3.0
#: Connections closed (or unanswered) before a CONNACK, in a row, after which the link gives up: a
#: plain client on a TLS listener (the broker cannot read its CONNECT and hangs up).
_UNANSWERED_LIMIT = 2
#: MQTT keep-alive, seconds: a lost broker is noticed within about 1.5 times this.
KEEPALIVE_S = 5


class LinkState(enum.Enum):
    """Where a :class:`BrokerLink` stands."""

    CONNECTING = "connecting"  #: the first attempt is under way
    UNREACHABLE = "unreachable"  #: the broker could not be reached; retrying
    CONNECTED = "connected"
    LOST = "lost"  #: connected before, the connection broke; paho reconnects
    FAILED = "failed"  #: a final error (see ``BrokerLink.failure``); no more attempts
    CLOSED = "closed"  #: closed by its owner


class BrokerLink:
    """The connection of one paho client (its owner's) to the broker, watched.

    Parameters
    ----------
    client : paho.mqtt.client.Client
        Made by :func:`~trajgen.live.mqtt.make_client`, not connected; the link sets its
        ``on_connect`` and ``on_disconnect``.
    settings : BrokerSettings
    who : str
        The owner in messages: ``"master"``, ``"vehicle agv1"``.
    on_connected : callable, optional
        Called with the client on every accepted connection (the first and each reconnection), in
        paho's thread, before :attr:`connected` turns true: subscribe and say hello there, and
        publish anything else only while :attr:`connected`.
    on_change : callable, optional
        Called with the new :class:`LinkState` and the sentence the link says of it, on each change it
        says (connected, connected again, lost, unreachable, failed): the owner's run log. Its log
        records then carry ``timeline=True`` (a command printing the owner's log lines leaves them out).
    """

    def __init__(
        self,
        client,
        settings,
        *,
        who: str,
        on_connected: Callable[[object], None] | None = None,
        on_change: Callable[[LinkState, str], None] | None = None,
    ) -> None:
        self.client = client
        self.settings = settings
        self.who = who
        self.failed = threading.Event()
        self.failure: str | None = None
        self._on_connected = on_connected
        self._on_change = on_change
        self._extra = {"timeline": on_change is not None}
        self._state = LinkState.CONNECTING
        self._lock = threading.Lock()
        self._closing = threading.Event()
        self._answered = threading.Event()  # a CONNACK (either way) or a close came for this attempt
        self._connections = 0
        self._pumping = False  # the first connection's loop runs in the link's thread
        self._accepted = False  # the CONNACK of the connection being pumped accepted it
        self._thread: threading.Thread | None = None
        client.on_connect = self._on_connect
        client.on_disconnect = self._on_disconnect

    @property
    def state(self) -> LinkState:
        """Where the link stands now."""
        with self._lock:
            return self._state

    @property
    def ever_connected(self) -> bool:
        """Whether the broker accepted a connection at least once."""
        return self._connections > 0

    @property
    def connected(self) -> bool:
        """Whether the broker accepted the connection and it has not been lost since."""
        return self.state is LinkState.CONNECTED

    def start(self) -> BrokerLink:
        """Connect in a thread of the link's own; returns at once (see :attr:`state`)."""
        self._thread = threading.Thread(
            target=self._connect_first, name=f"trajgen-link-{self.who}", daemon=True
        )
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop retrying, disconnect and stop paho's thread (the owner publishes its goodbyes first)."""
        self._closing.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(CONNACK_TIMEOUT_S + 1.0)
        self._change(LinkState.CLOSED)
        self.client.disconnect()
        self.client.loop_stop()

    # ----------------------------------------------------------------- the first connection
    def _connect_first(self) -> None:
        delay = RETRY_MIN_S
        unanswered = 0
        while not self._closing.is_set():
            self._answered.clear()
            try:
                self.client.connect(self.settings.host, self.settings.port, keepalive=KEEPALIVE_S)
            except ssl.SSLCertVerificationError as error:
                self._fail(
                    f"the TLS certificate of the broker {self.settings.url} is not trusted "
                    f"({error.verify_message or error.reason}): expected one signed by the CA given "
                    "with --cafile"
                )
                return
            except ssl.SSLError as error:
                self._fail(
                    f"TLS with the broker {self.settings.url} failed ({error.reason or error}): expected a "
                    "TLS listener there (use mqtt:// without --tls for a plain one)"
                )
                return
            except (ConnectionResetError, ConnectionAbortedError, BrokenPipeError) as error:
                # reached, then hung up on: a listener that cannot speak this client's language
                logger.debug("%s: %s hung up: %s", self.who, self.settings.url, error)
            except OSError as error:
                self._unreachable(_reason(error), delay)
                if self._closing.wait(delay):
                    return
                delay = min(2.0 * delay, RETRY_MAX_S)
                continue
            else:
                if self._pump_until_answered() or self.failed.is_set() or self._closing.is_set():
                    return
            # hung up on, or no CONNACK: unanswered
            unanswered += 1
            if unanswered >= _UNANSWERED_LIMIT:
                self._fail(self._hung_up(unanswered))
                return
            if self._closing.wait(delay):
                return

    def _pump_until_answered(self) -> bool:
        """Run the client's loop here until the CONNACK; hand over to paho's thread once accepted.

        The link says it is connected only after the hand-over: while this thread runs the loop, a
        publish from another thread would write to the socket beside it (paho writes at once when
        no loop thread runs), and interleaved packets make the broker drop the connection.
        """
        deadline = time.monotonic() + CONNACK_TIMEOUT_S
        self._pumping, self._accepted = True, False
        try:
            while not self._answered.is_set() and time.monotonic() < deadline and not self._closing.is_set():
                self.client.loop(timeout=0.05)
        finally:
            self._pumping = False
        if self._accepted:
            self.client.loop_start()  # paho's thread from here: keep-alive and reconnection
            self._now_connected()
            return True
        if not self._answered.is_set():  # no CONNACK in time: as unanswered as a close
            self.client.disconnect()
        return False

    # ----------------------------------------------------------------- paho's callbacks
    def _on_connect(self, client, userdata, flags, reason_code, properties) -> None:
        self._answered.set()
        if reason_code.is_failure:
            self._fail(
                f"the broker {self.settings.url} refused the login ({reason_code}): expected a username "
                "and password it accepts (--username, --password-file)"
            )
            client.disconnect()
            return
        self._connections += 1
        if self._on_connected is not None:  # first: the owner's hello goes out before anything else
            self._on_connected(client)
        if self._pumping:
            self._accepted = True  # connected once paho's thread has the loop (_pump_until_answered)
            return
        self._now_connected()

    def _now_connected(self) -> None:
        again = self._connections > 1
        before = self._change(LinkState.CONNECTED)
        level = logging.WARNING if before in (LinkState.UNREACHABLE, LinkState.LOST) else logging.INFO
        text = f"connected{' again' if again else ''} to {self.settings.url}"
        logger.log(level, "%s: %s", self.who, text, extra=self._extra)
        self._said(LinkState.CONNECTED, text)

    def _said(self, state: LinkState, text: str) -> None:
        if self._on_change is not None:
            self._on_change(state, text)

    def _on_disconnect(self, client, userdata, flags, reason_code, properties) -> None:
        self._answered.set()
        if self._closing.is_set() or self.failed.is_set():
            return
        with self._lock:
            lost = self._state is LinkState.CONNECTED
            if lost:
                self._state = LinkState.LOST
        if lost:
            text = f"lost the broker {self.settings.url} ({reason_code}); reconnecting"
            logger.warning("%s: %s", self.who, text, extra=self._extra)
            self._said(LinkState.LOST, text)

    def _hung_up(self, times: int) -> str:
        if self.settings.tls:
            return (
                f"the broker {self.settings.url} closed the connection during the TLS handshake ({times} "
                "times): expected a TLS listener there (use mqtt:// without --tls for a plain one)"
            )
        return (
            f"the broker {self.settings.url} closed the connection without answering its CONNECT ({times} "
            "times): expected an MQTT listener without TLS there (a TLS listener needs mqtts:// or --tls)"
        )

    # ----------------------------------------------------------------- states
    def _change(self, state: LinkState) -> LinkState:
        """Enter ``state``; returns the state before."""
        with self._lock:
            before, self._state = self._state, state
            return before

    def _unreachable(self, reason: str, delay: float) -> None:
        if self._change(LinkState.UNREACHABLE) is not LinkState.UNREACHABLE:
            text = f"cannot reach {self.settings.url}: {reason}; retrying, every {RETRY_MAX_S:g} s at most"
            logger.warning("%s: %s", self.who, text, extra=self._extra)
            self._said(LinkState.UNREACHABLE, text)
        else:
            logger.debug(
                "%s: %s still unreachable: %s; next try in %g s", self.who, self.settings.url, reason, delay
            )

    def _fail(self, message: str) -> None:
        if self.failed.is_set():
            return
        self.failure = f"{self.who}: {message}"
        self._change(LinkState.FAILED)
        logger.debug("%s", self.failure)  # the owner reports it: the run's end, the command's error line
        self._said(LinkState.FAILED, message)
        self.failed.set()


def _reason(error: OSError) -> str:
    """An OS error in a few words: ``connection refused``, ``timed out``, ``name not known``."""
    text = error.strerror or str(error) or type(error).__name__
    return text[0].lower() + text[1:] if text else type(error).__name__
