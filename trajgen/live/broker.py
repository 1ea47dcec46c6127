"""An MQTT broker for ``trajgen demo --live`` and the tests: amqtt in a thread, or a mosquitto process.

:class:`EmbeddedBroker` runs amqtt (MQTT 3.1.1, pure Python) on its own asyncio
event loop in a daemon thread of this process; :class:`MosquittoBroker` runs
an installed ``mosquitto`` as a child process. Both listen on ``127.0.0.1``
only, let anyone in without a password, keep their port across a
:meth:`~EmbeddedBroker.restart` and offer the same interface::

    with EmbeddedBroker() as broker:  # a free port, chosen at construction
        client.connect(broker.host, broker.port)
        broker.restart(down_for=0.5)  # every client drops, reconnects on the same port

Stopping a broker closes every client's connection (the clients see it drop,
as after a crash of the broker: their sessions are gone after a restart) and
its listening socket; a client whose connection breaks has its last will published.

amqtt (of the ``trajgen[live]`` extra) is imported when an embedded broker first starts
(paho never is). Its loggers are left as the application configured them; a stop or
restart logs no warning or traceback.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import threading
import time
from typing import Any, Self

from trajgen.errors import LiveError
from trajgen.live import broker_base
from trajgen.live.broker_base import (
    HOST,
    POLL_S,
    START_TIMEOUT_S,
    STOP_TIMEOUT_S,
    THREAD_NAME,
    Broker,
    wait_until_bindable,
)
from trajgen.live.mosquitto import MosquittoBroker, mosquitto_available
from trajgen.live.mqtt import require_live

__all__ = ["HOST", "THREAD_NAME", "EmbeddedBroker", "MosquittoBroker", "mosquitto_available"]

logger = logging.getLogger(__name__)


def _broker_config(port: int) -> dict[str, Any]:
    """The configuration of amqtt 0.12 (``BrokerConfig.from_dict``): one TCP listener, anonymous.

    The plugins named replace amqtt's defaults: no ``$SYS`` topics, no packet or event
    logging, no topic checks.
    """
    return {
        "listeners": {"default": {"type": "tcp", "bind": f"{HOST}:{port}", "max_connections": 0}},
        "timeout_disconnect_delay": 0,
        "plugins": {"amqtt.plugins.authentication.AnonymousAuthPlugin": {"allow_anonymous": True}},
    }


def _tracking_broker(config: dict[str, Any]) -> Any:
    """An amqtt broker on the running loop that keeps hold of its client connections, to end them on stop.

    A stop breaks every connection before amqtt's shutdown, as a lost network would:
    amqtt then sees each client go and ends its handling by itself. Left to amqtt, the
    shutdown cancels each connection's reader, and Python 3.11's ``asyncio.wait_for``
    loses that cancellation when a packet arrives at the same moment (a client's PUBACK,
    say): the shutdown then waits for that reader forever. amqtt's shutdown would also
    leave open a connection still before its CONNECT, or one arriving meanwhile.
    """
    from amqtt.adapters import StreamReaderAdapter, StreamWriterAdapter
    from amqtt.broker import Broker

    class Connection(StreamWriterAdapter):
        """amqtt's writer of one client connection, knowing its task; it drops what comes once cut.

        (Writes to a broken connection would each make asyncio log a warning.)
        """

        def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
            super().__init__(writer)
            self.trajgen_reader = reader
            self.trajgen_stream = writer
            self.trajgen_task = asyncio.current_task()
            self.trajgen_answered = False  # the broker has written to it: its CONNECT was read

        def write(self, data: bytes) -> None:
            if not self.trajgen_stream.transport.is_closing():
                self.trajgen_answered = True
                super().write(data)

        def trajgen_end(self) -> None:
            """Break the connection; one still before its CONNECT: cancel its handling instead.

            (Broken, it would make amqtt log an error that no CONNECT came.) What the
            client sent and amqtt has not read yet is dropped: read after its handling
            was stopped (acknowledgements, say), each packet would make amqtt log a warning.
            """
            if self.trajgen_answered or self.trajgen_task is None:
                self.trajgen_reader.set_exception(ConnectionResetError("the broker stops"))
                self.trajgen_stream.transport.abort()
            else:
                self.trajgen_task.cancel()

    class TrackingBroker(Broker):
        """amqtt's broker, knowing every open client connection."""

        def __init__(self) -> None:
            super().__init__(config, loop=asyncio.get_running_loop())
            self.trajgen_connections: set[Connection] = set()
            self.trajgen_closing = False

        async def stream_connected(
            self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, listener_name: str
        ) -> None:
            if self.trajgen_closing:
                writer.transport.abort()
                return
            connection = Connection(reader, writer)
            self.trajgen_connections.add(connection)
            try:
                # what amqtt's stream_connected does, with this writer; ended by a stop, the task
                # must not end cancelled, or asyncio 3.11's stream server logs a traceback (its
                # done callback asks a cancelled task for its exception)
                with contextlib.suppress(asyncio.CancelledError):
                    await self.external_connected(StreamReaderAdapter(reader), connection, listener_name)
            finally:
                self.trajgen_connections.discard(connection)
                if self.trajgen_closing:
                    writer.transport.abort()
                else:
                    writer.close()  # amqtt leaves a connection open that ended before its CONNECT

        async def trajgen_end_connections(self, timeout: float) -> None:
            """End every client connection and its handling; wait up to ``timeout`` s for amqtt."""
            self.trajgen_closing = True
            for attempt in range(2):  # the second: anything that did not end, cancelled and broken
                connections = list(self.trajgen_connections)
                for connection in connections:
                    if attempt and connection.trajgen_task is not None:
                        connection.trajgen_task.cancel()
                    connection.trajgen_end()
                tasks = [connection.trajgen_task for connection in connections]
                if any(task is not None for task in tasks):
                    await asyncio.wait([task for task in tasks if task is not None], timeout=timeout / 2)
            for _ in range(3):  # the sockets close, the readers see it, in the next turns of the loop
                await asyncio.sleep(0)

    return TrackingBroker()


def _run_loop(loop: asyncio.AbstractEventLoop) -> None:
    """The broker thread: run ``loop`` until stopped, then cancel what is left and close it."""
    asyncio.set_event_loop(loop)
    try:
        loop.run_forever()
    finally:
        try:
            tasks = asyncio.all_tasks(loop)
            for task in tasks:
                task.cancel()
            loop.run_until_complete(asyncio.gather(*tasks, return_exceptions=True))
            loop.run_until_complete(loop.shutdown_asyncgens())
            loop.run_until_complete(loop.shutdown_default_executor())
        except Exception:  # the broker is gone either way: say why at debug level only
            logger.debug("the embedded MQTT broker's event loop did not end cleanly", exc_info=True)
        finally:
            asyncio.set_event_loop(None)
            loop.close()


class EmbeddedBroker(Broker):
    """An MQTT 3.1.1 broker (amqtt) in a thread of this process, on 127.0.0.1.

    amqtt runs on its own asyncio event loop in a daemon thread named
    ``"trajgen-broker"``; each start makes a new loop, thread and broker, so a restart
    drops every session and retained message.

    Parameters
    ----------
    port : int or None
        TCP port, 1 to 65535; ``None``: a free port chosen now, kept across restarts.

    Raises
    ------
    InputError
        A port out of range.
    """

    kind = "embedded MQTT broker (amqtt)"

    def __init__(self, *, port: int | None = None) -> None:
        super().__init__(port=port)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._broker: Any = None

    @property
    def running(self) -> bool:
        """Whether the broker is started (and not stopped since)."""
        return self._broker is not None and self._thread is not None and self._thread.is_alive()

    def start(self) -> Self:
        """Start the broker; return once it accepts connections (at once if it runs already).

        Returns
        -------
        EmbeddedBroker
            This broker.

        Raises
        ------
        LiveError
            The port stays taken for 2 s, or the broker does not accept connections
            within 10 s.
        """
        with self.lock:
            if self.running:
                return self
            self.stop()  # a thread that ended by itself
            deadline = time.monotonic() + START_TIMEOUT_S
            # imported here, not on the broker's loop: an import would hold the loop up for 0.1 s
            require_live("amqtt", "the MQTT broker of this process (no mosquitto is installed)")
            import amqtt.broker
            import amqtt.plugins.authentication  # noqa: F401  (the plugin of _broker_config)

            wait_until_bindable(self.port, f"the {self.kind}")
            loop = asyncio.new_event_loop()
            thread = threading.Thread(target=_run_loop, args=(loop,), name=THREAD_NAME, daemon=True)
            thread.start()
            self._loop, self._thread = loop, thread
            try:
                self._broker = self._open(loop, deadline)
                self.wait_until_answering(deadline, thread.is_alive)
            except BaseException:
                self.stop()
                raise
            logger.info("the embedded MQTT broker listens on %s", self.url)
            return self

    def _open(self, loop: asyncio.AbstractEventLoop, deadline: float) -> Any:
        """Create and start amqtt's broker on ``loop``; retry while the port is taken (up to 2 s)."""
        rebind_deadline = time.monotonic() + broker_base.REBIND_TIMEOUT_S  # read now: tests shorten it
        while True:
            future = asyncio.run_coroutine_threadsafe(self._serve(), loop)
            try:
                return future.result(timeout=max(deadline - time.monotonic(), 0.0))
            except TimeoutError:
                future.cancel()
                raise LiveError(
                    f"the {self.kind} on {self.url} did not start within {START_TIMEOUT_S:g} s"
                ) from None
            except OSError as error:
                if error.errno != errno.EADDRINUSE or time.monotonic() >= min(rebind_deadline, deadline):
                    raise LiveError(f"the {self.kind} cannot listen on {self.url}: {error}") from None
            time.sleep(POLL_S)

    async def _serve(self) -> Any:
        """On the broker's loop: a started amqtt broker (``OSError`` if it cannot bind)."""
        from amqtt.errors import BrokerError

        broker = _tracking_broker(_broker_config(self.port))
        try:
            await broker.start()
        except BrokerError as error:
            cause = error.__cause__
            if isinstance(cause, OSError):
                raise cause from None
            raise LiveError(f"the {self.kind} on {self.url} did not start: {error}") from None
        return broker

    def stop(self) -> None:
        """Close every client connection and the listening socket; end the thread.

        Clients see their connection drop (no MQTT DISCONNECT is needed). Does nothing
        if the broker is not running.
        """
        with self.lock:
            loop, thread, broker = self._loop, self._thread, self._broker
            self._loop = self._thread = self._broker = None
            if loop is None or thread is None:
                return
            if broker is not None and thread.is_alive():
                future = asyncio.run_coroutine_threadsafe(self._close(broker), loop)
                try:
                    future.result(timeout=STOP_TIMEOUT_S)
                except Exception:  # stopped anyway below: the loop ends and cancels what is left
                    logger.debug("the embedded MQTT broker did not shut down cleanly", exc_info=True)
            if thread.is_alive():
                loop.call_soon_threadsafe(loop.stop)
                thread.join(STOP_TIMEOUT_S)
            if thread.is_alive():
                logger.warning("the embedded MQTT broker's thread did not end within %g s", STOP_TIMEOUT_S)
            else:
                logger.info("the embedded MQTT broker on %s stopped", self.url)

    @staticmethod
    async def _close(broker: Any) -> None:
        """On the broker's loop: end every connection, then shut amqtt down (its listener, its tasks)."""
        share = STOP_TIMEOUT_S / 4  # three shares at most: within the stop's wait
        await broker.trajgen_end_connections(share)
        try:
            await asyncio.wait_for(broker.shutdown(), share)
        except Exception:
            logger.debug("amqtt's shutdown failed; the broker's loop ends regardless", exc_info=True)
        await broker.trajgen_end_connections(share)  # none, unless the shutdown failed
