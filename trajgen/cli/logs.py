"""The command's log lines on stderr: ``trajgen: <level>: <message>``, to the stream of the moment."""

from __future__ import annotations

import logging
import sys

__all__ = ["LogFormatter", "StderrHandler", "log_to_stderr"]


class LogFormatter(logging.Formatter):
    """The command's log lines: the program's name and the level first, as its error messages.

    Warnings, ``-v`` progress and the solvers' messages all read ``trajgen: warning: optimal: ...``.
    """

    def format(self, record: logging.LogRecord) -> str:
        """``trajgen: <level>: <message>``, the traceback below where there is one."""
        text = f"trajgen: {record.levelname.lower()}: {record.getMessage()}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


class StderrHandler(logging.StreamHandler):
    """A log handler on whatever ``sys.stderr`` is when a record is written (not when it was made).

    :func:`main` run twice in one process (tests, a host program redirecting ``sys.stderr``) logs to
    the stream of the moment, as ``print(..., file=sys.stderr)`` does.
    """

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(LogFormatter())

    @property
    def stream(self):
        """``sys.stderr`` as it is now."""
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:
        pass


def log_to_stderr(level: int) -> None:
    """Send log records of ``level`` and above to stderr as ``trajgen: <level>: ...`` lines.

    One handler on the root logger, added next to any there already (a host's, pytest's): the
    solvers' and libraries' records reach it too. Calling again only changes the level.
    """
    root = logging.getLogger()
    handler = next((each for each in root.handlers if isinstance(each, StderrHandler)), None)
    if handler is None:
        handler = StderrHandler()
        root.addHandler(handler)
    handler.setLevel(level)
    if root.getEffectiveLevel() > level:
        root.setLevel(level)
