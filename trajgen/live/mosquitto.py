"""A mosquitto broker as a child process, for the tests and plants that have one installed.

:class:`MosquittoBroker` runs an installed ``mosquitto`` (Debian's package puts it in
``/usr/sbin``) with a configuration of one listener on 127.0.0.1, anonymous, and offers the
interface of :class:`~trajgen.live.broker.EmbeddedBroker` (:class:`~trajgen.live.broker_base.Broker`).
"""

from __future__ import annotations

import logging
import os
import shutil
import subprocess
import tempfile
import time
import weakref
from pathlib import Path
from typing import Self

from trajgen.errors import LiveError
from trajgen.live.broker_base import HOST, START_TIMEOUT_S, STOP_TIMEOUT_S, Broker, wait_until_bindable

__all__ = ["MOSQUITTO_FOLDERS", "MosquittoBroker", "mosquitto_available"]

logger = logging.getLogger(__name__)

#: Debian's and Homebrew's folders of mosquitto, looked in after the ``PATH`` (which often lacks them).
MOSQUITTO_FOLDERS = ("/usr/sbin", "/usr/local/sbin", "/opt/homebrew/sbin")


def mosquitto_available() -> bool:
    """Whether a ``mosquitto`` executable is installed (see :meth:`MosquittoBroker.executable`)."""
    return MosquittoBroker.executable() is not None


def _end_process(process: subprocess.Popen[bytes]) -> None:
    """Terminate ``process`` and wait for it (kill it after :data:`STOP_TIMEOUT_S` s)."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class MosquittoBroker(Broker):
    """An external ``mosquitto`` as a child process, on 127.0.0.1: the interface of :class:`EmbeddedBroker`.

    Its configuration file (``listener PORT 127.0.0.1``, ``allow_anonymous true``) and
    its log are written to a temporary folder, removed on :meth:`stop`.

    Parameters
    ----------
    port : int or None
        TCP port, 1 to 65535; ``None``: a free port chosen now, kept across restarts.

    Raises
    ------
    InputError
        A port out of range.
    """

    kind = "MQTT broker mosquitto"

    def __init__(self, *, port: int | None = None) -> None:
        super().__init__(port=port)
        self._process: subprocess.Popen[bytes] | None = None
        self._folder: tempfile.TemporaryDirectory[str] | None = None
        self._finalizer: weakref.finalize | None = None

    @staticmethod
    def executable() -> str | None:
        """The ``mosquitto`` executable: on the ``PATH``, else in :data:`MOSQUITTO_FOLDERS`; or ``None``."""
        return shutil.which("mosquitto") or shutil.which("mosquitto", path=os.pathsep.join(MOSQUITTO_FOLDERS))

    @property
    def running(self) -> bool:
        """Whether the broker is started (and not stopped since), its process alive."""
        return self._process is not None and self._process.poll() is None

    def start(self) -> Self:
        """Start ``mosquitto``; return once it accepts connections (at once if it runs already).

        Returns
        -------
        MosquittoBroker
            This broker.

        Raises
        ------
        LiveError
            ``mosquitto`` is not installed, the port stays taken for 2 s, or it does
            not accept connections within 10 s (the message quotes its log).
        """
        with self.lock:
            if self.running:
                return self
            self.stop()  # a process that ended by itself
            executable = self.executable()
            if executable is None:
                raise LiveError("mosquitto is not installed (PATH, sbin): expected the mosquitto broker")
            deadline = time.monotonic() + START_TIMEOUT_S
            wait_until_bindable(self.port, f"the {self.kind}")
            self._folder = tempfile.TemporaryDirectory(prefix="trajgen-mosquitto-")
            folder = Path(self._folder.name)
            config = folder / "mosquitto.conf"
            config.write_text(f"listener {self.port} {HOST}\nallow_anonymous true\n", encoding="utf-8")
            with open(folder / "mosquitto.log", "wb") as log:
                self._process = subprocess.Popen(
                    [executable, "-c", str(config)], stdin=subprocess.DEVNULL, stdout=log, stderr=log
                )
            # no mosquitto outlives this broker object or the interpreter, stopped or not
            self._finalizer = weakref.finalize(self, _end_process, self._process)
            try:
                self.wait_until_answering(deadline, lambda: self.running)
            except LiveError as error:
                text = self._log_tail()
                self.stop()
                raise LiveError(f"{error}; its log: {text}" if text else str(error)) from None
            logger.info("mosquitto listens on %s", self.url)
            return self

    def log(self) -> str:
        """Mosquitto's log so far (connections, disconnections, timeouts); empty once stopped."""
        if self._folder is None:
            return ""
        try:
            return (Path(self._folder.name) / "mosquitto.log").read_text(encoding="utf-8", errors="replace")
        except OSError:
            return ""

    def _log_tail(self, limit: int = 500) -> str:
        """The end of mosquitto's log, for a message."""
        return " ".join(self.log().split())[-limit:]

    def stop(self) -> None:
        """Terminate ``mosquitto`` (closing every client connection), wait for it to end; if running."""
        with self.lock:
            process, folder, finalizer = self._process, self._folder, self._finalizer
            self._process = self._folder = self._finalizer = None
            if finalizer is not None:
                finalizer.detach()
            if process is not None:
                _end_process(process)
                logger.info("mosquitto on %s stopped", self.url)
            if folder is not None:
                folder.cleanup()
