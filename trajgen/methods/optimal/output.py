"""CasADi's own messages, through this program's logging instead of bare lines on stderr.

CasADi writes its warnings (``CasADi - <date> WARNING("NLP is overconstrained ...")``) through
Python's ``sys.stderr``. While any CasADi call of the optimal method runs, :func:`casadi_output`
points ``sys.stderr`` at a writer that hands each complete line to the ``logging`` logger of
this package (``INFO``: what CasADi remarks is for a developer; the outcome of every solve is
reported by the method itself). Nested and concurrent uses share one redirection: the first in
installs it, the last out restores the stream it found. Logging's own handlers keep the stream
they were created with, so the program's log lines are not caught.
"""

from __future__ import annotations

import contextlib
import io
import logging
import sys
import threading
from collections.abc import Iterator

__all__ = ["casadi_output"]

logger = logging.getLogger("trajgen.methods.optimal")

_lock = threading.Lock()
_depth = 0
_saved = None


class _LineWriter(io.TextIOBase):
    """A text stream that logs each complete line it is given."""

    def __init__(self) -> None:
        super().__init__()
        self._partial = ""
        self._lock = threading.Lock()

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        with self._lock:
            lines = (self._partial + text).split("\n")
            self._partial = lines.pop()
        for line in lines:
            if line.strip():
                logger.info("optimal: casadi: %s", line.strip())
        return len(text)

    def flush(self) -> None:
        with self._lock:
            rest, self._partial = self._partial, ""
        if rest.strip():
            logger.info("optimal: casadi: %s", rest.strip())


_writer = _LineWriter()


@contextlib.contextmanager
def casadi_output() -> Iterator[None]:
    """While inside, what CasADi writes to ``sys.stderr`` is logged line by line."""
    global _depth, _saved
    with _lock:
        if _depth == 0:
            _saved = sys.stderr
            sys.stderr = _writer
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0:
                _writer.flush()
                if sys.stderr is _writer:  # unless somebody else replaced it meanwhile
                    sys.stderr = _saved
                _saved = None
