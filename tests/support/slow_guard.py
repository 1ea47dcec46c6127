"""The fast set starts nothing: a test that starts a process or listens on a socket is marked slow.

A process is a command, a ``trajgen`` run, a build of the docs (``python -m sphinx``), a mosquitto; a
listening socket is a broker (amqtt in the test's process) or a port found for one. Both are seen
through Python's audit events (:func:`sys.addaudithook`), whichever code starts them: the test's,
a fixture's, the library's. ``tests/conftest.py`` installs one :class:`SlowGuard` per process,
watches each test not marked ``slow`` from its setup to its teardown, and fails it naming what it
started.

What it cannot see: a process started without an audit event (``multiprocessing`` with the
``spawn`` context, ``system()`` called from C); no test does that. What it does not hold against a
test: events of threads already running when the test began. matplotlib's font cache, built with
``fc-list`` on a cold cache, is warmed before any test runs (``pytest_configure``).
"""

from __future__ import annotations

import threading

__all__ = ["EVENTS", "SlowGuard"]

#: Audit events that make a test slow, and what they mean in the message.
EVENTS = {
    "subprocess.Popen": "starts a process",
    "os.system": "starts a process",
    "os.posix_spawn": "starts a process",
    "os.spawn": "starts a process",
    "os.exec": "replaces its process",
    "os.fork": "forks its process",
    "os.forkpty": "forks its process",
    "socket.bind": "binds a socket (a broker, or a port for one)",
}


class SlowGuard:
    """Records the first slow event while a fast test runs (thread-safe; one per process)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._watching = False
        self._found: str | None = None
        self._older: frozenset[int] = frozenset()

    def watch(self, fast: bool) -> None:
        """Begin watching a test that is not marked slow (``fast``), or stop watching.

        Threads other than the main one that run already when a test begins are not the test's
        (a thread left by an earlier test): their events are not held against it.
        """
        with self._lock:
            self._watching = fast
            self._found = None
            main = threading.main_thread().ident
            self._older = frozenset(t.ident for t in threading.enumerate() if t.ident != main)

    def take(self) -> str | None:
        """What the test did that a fast test may not (``None``: nothing), forgotten once taken."""
        with self._lock:
            found, self._found = self._found, None
            return found

    def audit(self, event: str, args: tuple) -> None:
        """The audit hook: note ``event`` if it is one of :data:`EVENTS` and a fast test runs."""
        what = EVENTS.get(event)
        if what is None or not self._watching or threading.get_ident() in self._older:
            return
        with self._lock:
            if self._watching and self._found is None:
                shown = repr(args[1] if event == "subprocess.Popen" and len(args) > 1 else args[-1:])
                self._found = f"{what} ({event} {shown[:120]})"
