"""The run log of a live run: one JSON object per line, written to a file as the run goes.

Every line has ``t`` and ``event``. ``t`` is the run's time, seconds since the first order was
sent: the same zero as the makespan, the picture's axis and the vehicles' faults (records before
it say 0). Planning and the waits for the broker and the vehicles come before it and are reported
apart.

- ``planning``: a plan is being made (``what``: from where, ``method``); ``planned``: it is made
  (``planning_s`` wall seconds, ``planned_s``, ``method``, ``computed_by``, ...);
- ``plan``: the plan taken (``method``, ``planned_s``: when the releases would bring every vehicle
  to its goal, ``nodes``: each vehicle's node count); the first plan is logged at ``t`` = 0 with
  what came before it, run seconds: ``broker_wait_s`` (from the master's start to the broker) and
  ``vehicle_wait_s`` (from there to the first orders; ``null``: not reached);
- ``broker``: the master's connection changed (``state``, ``detail``: the sentence it says);
- ``place``: before the first orders, where a vehicle says it stands (``vehicle``, ``at``,
  ``driving``); ``unplaced``: its state names no place on the track (``reason``); ``off-start``: it
  stands elsewhere than the plan starts it (``at``, ``start``): the master plans again from there;
- ``order``: an order or order update was published (``vehicle``, ``update``, ``first`` and
  ``decision_point`` node indices, ``frontier_m``: the decision point's distance along the path,
  ``resent``); ``cancel``: ``cancelOrder`` was sent (``vehicle``, ``reason``);
- ``state``: a state was taken (``vehicle``, ``x``, ``y``, ``node``, ``along_m``: distance along its
  path, ``driving``);
- ``ignored``: a message was logged and ignored (``topic``, ``reason``); ``off-plan``: a vehicle's
  state puts it off its plan, nothing is released (``vehicle``, ``reason``); ``on-plan``: back on it;
- ``connection``: a vehicle's connection state changed (``vehicle``, ``state``);
- ``vehicle-error``: a vehicle reported a new error (``vehicle``, ``type``, ``description``: an order
  it refused, say); ``order-not-taken``: a vehicle still reports an older order after four sends
  (``vehicle``, ``reports``);
- ``restart``: a vehicle came back without its order (``vehicle``, ``at``: where it stands);
- ``goal``: a new goal was asked for; ``replan``: the vehicles stood at their bases and were
  re-planned; ``stop``: the run was stopped (``reason``: the signal, ``cancelled``: the vehicles sent
  ``cancelOrder``);
- ``end``: the run ended (``outcome``, ``makespan_s``, ``closest_m``: the closest approach of the
  reported places, and ``error`` when it ended early: the broker, a refusal, a vehicle given up, a
  stop).

The log grows with the run's length; it is kept on disk, not in memory, and
:func:`read_run_log` thins the states it returns to a bounded number.
"""

from __future__ import annotations

import itertools
import json
import logging
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

from trajgen.errors import OutputError

__all__ = ["EVENT_KINDS", "MAX_PLOTTED_STATES", "PARTIAL_SUFFIX", "RunLog", "read_run_log"]

logger = logging.getLogger(__name__)

#: The records :func:`read_run_log` hands the picture as events.
EVENT_KINDS = ("connection", "ignored", "goal", "replan", "restart", "off-plan", "stop")
#: What a log streamed for ``FILE`` is called while the run goes: ``FILE.partial``.
PARTIAL_SUFFIX = ".partial"

#: Most states per vehicle :func:`read_run_log` keeps (evenly spaced in time).
MAX_PLOTTED_STATES = 4000
_CHUNK = 1 << 16


class RunLog:
    """A JSON-lines log written to a file as the run goes (thread-safe); :meth:`chunks` reads it back.

    Each record is handed to the operating system as it is written, so a process killed even with
    SIGKILL leaves every record it wrote on disk. :meth:`streamed` writes beside the file the run
    commits at its end (``<file>.partial``); without a path the log is a temporary file.

    Parameters
    ----------
    listener : callable, optional
        Called with each record after it is written (in the writer's thread).
    """

    def __init__(self, *, listener: Callable[[dict], None] | None = None) -> None:
        # open for the log's life, closed by close()
        self._file: IO[bytes] = tempfile.TemporaryFile(prefix="trajgen-live-", suffix=".jsonl")  # noqa: SIM115
        self._lock = threading.Lock()
        self.lines = 0
        #: the file the records are appended to as they come (``None``: a temporary file)
        self.partial: Path | None = None
        #: called with each record once written (a command line's progress display)
        self.listener = listener

    @classmethod
    def streamed(cls, path: str | Path, *, listener: Callable[[dict], None] | None = None) -> RunLog:
        """A log appended to ``<path>.partial`` record by record, for ``path`` committed at the run's end.

        A ``<path>.partial`` left by a run that was killed is kept: it is renamed
        ``<path>.partial.1`` (``.2``, ... if that is taken) before the new run writes.

        Raises
        ------
        OutputError
            The partial file cannot be made (naming it and why).
        """
        log = cls(listener=listener)
        log._file.close()
        partial = Path(path).with_name(Path(path).name + PARTIAL_SUFFIX)
        try:
            partial.parent.mkdir(parents=True, exist_ok=True)
            if partial.exists():
                kept = next(
                    candidate
                    for number in itertools.count(1)
                    if not (candidate := partial.with_name(f"{partial.name}.{number}")).exists()
                )
                partial.rename(kept)
                logger.warning("the log of an earlier run that did not end (%s) is kept as %s", partial, kept)
            log._file = open(partial, "w+b")  # noqa: SIM115 (open for the log's life, closed by close())
        except OSError as error:
            raise OutputError(
                f"cannot write the run log {str(partial)!r} as the run goes: {error.strerror or error}"
            ) from None
        log.partial = partial
        return log

    def write(self, record: dict) -> None:
        """Append one record (its values JSON numbers, text, booleans, lists or ``None``)."""
        line = json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"
        with self._lock:
            self._file.write(line.encode("utf-8"))
            self._file.flush()  # in the operating system's hands: a killed process keeps it
            self.lines += 1
        if self.listener is not None:
            self.listener(record)

    def chunks(self) -> Iterator[bytes]:
        """The log so far, in pieces of 64 KiB (for a streamed commit)."""
        with self._lock:
            self._file.flush()
            size = self._file.tell()
        offset = 0
        while offset < size:
            with self._lock:
                self._file.seek(offset)
                chunk = self._file.read(min(_CHUNK, size - offset))
                self._file.seek(0, 2)
            if not chunk:
                break
            offset += len(chunk)
            yield chunk

    def records(self) -> Iterator[dict]:
        """Every record so far, in order."""
        rest = b""
        for chunk in self.chunks():
            lines = (rest + chunk).split(b"\n")
            rest = lines.pop()
            for line in lines:
                if line:
                    yield json.loads(line)

    def close(self, *, keep: bool = False) -> None:
        """Close the log: a temporary file is removed, a partial file too unless ``keep``.

        The caller keeps the partial file when the log could not be committed: it is then the
        run's only log.
        """
        with self._lock:
            self._file.close()
        if self.partial is not None and not keep:
            self.partial.unlink(missing_ok=True)


def read_run_log(records) -> dict:
    """What a run picture needs from a log's records, with states thinned per vehicle.

    Parameters
    ----------
    records : iterable of dict

    Returns
    -------
    dict
        ``states``: per vehicle name, a list of ``(t, along_m, driving)``; ``orders``: per vehicle,
        ``(t, frontier_m)``; ``events``: ``(t, event, vehicle or None, detail)`` of connection
        changes, ignored messages, goals and re-plans; ``end``: the ``end`` record or ``None``.
    """
    states: dict[str, list] = {}
    orders: dict[str, list] = {}
    events: list = []
    end = None
    for record in records:
        kind = record.get("event")
        if kind == "state":
            rows = states.setdefault(record["vehicle"], [])
            rows.append((record["t"], record["along_m"], record["driving"]))
            if len(rows) > 2 * MAX_PLOTTED_STATES:
                del rows[1::2]  # halve: evenly thinned, bounded memory
        elif kind == "order":
            orders.setdefault(record["vehicle"], []).append((record["t"], record["frontier_m"]))
        elif kind in EVENT_KINDS:
            detail = next((record[key] for key in ("state", "reason", "goal", "at") if record.get(key)), "")
            events.append((record["t"], kind, record.get("vehicle"), str(detail)))
        elif kind == "end":
            end = record
    return {"states": states, "orders": orders, "events": events, "end": end}
