"""The run log of a live run: one JSON object per line, streamed to a temporary file as the run goes.

Every line has ``t`` and ``event``. ``t`` is the run's time, seconds since the first order was
sent: the same zero as the makespan, the picture's axis and the vehicles' faults. Planning and
the wait for the broker come before it and are reported apart.

- ``plan``: a verified plan was made (``method``, ``planned_s``: when the releases would bring both
  vehicles to their goals, ``nodes``: each vehicle's node count); the first plan is logged at
  ``t`` = 0 with what came before it, run seconds: ``broker_wait_s`` (from the master's start to
  the broker) and ``vehicle_wait_s`` (from there to both vehicles heard; ``null``: not reached);
- ``order``: an order or order update was published (``vehicle``, ``update``, ``first`` and
  ``decision_point`` node indices, ``frontier_m``: the decision point's distance along the path,
  ``resent``);
- ``state``: a state was taken (``vehicle``, ``x``, ``y``, ``node``, ``along_m``: distance along its
  path, ``driving``);
- ``ignored``: a message was logged and ignored (``topic``, ``reason``);
- ``connection``: a vehicle's connection state changed (``vehicle``, ``state``);
- ``vehicle-error``: a vehicle reported a new error (``vehicle``, ``type``, ``description``: an order
  it refused, say); ``order-not-taken``: a vehicle still reports an older order after four sends
  (``vehicle``, ``reports``);
- ``restart``: a vehicle came back without its order (``vehicle``, ``at``: where it stands);
- ``goal``: a new goal was asked for; ``replan``: both vehicles stood at their bases and were
  re-planned; ``end``: the run ended (``outcome``, ``makespan_s``, and ``error`` when the broker
  connection failed for good or was never made, or a vehicle never took its order).

The log grows with the run's length; it is kept on disk, not in memory, and
:func:`read_run_log` thins the states it returns to a bounded number.
"""

from __future__ import annotations

import json
import tempfile
import threading
from collections.abc import Callable, Iterator
from typing import IO

__all__ = ["MAX_PLOTTED_STATES", "RunLog", "read_run_log"]

#: Most states per vehicle :func:`read_run_log` keeps (evenly spaced in time).
MAX_PLOTTED_STATES = 4000
_CHUNK = 1 << 16


class RunLog:
    """A JSON-lines log written to a temporary file (thread-safe); :meth:`chunks` reads it back.

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
        #: called with each record once written (a command line's progress display)
        self.listener = listener

    def write(self, record: dict) -> None:
        """Append one record (its values JSON numbers, text, booleans, lists or ``None``)."""
        line = json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"
        with self._lock:
            self._file.write(line.encode("utf-8"))
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

    def close(self) -> None:
        """Remove the temporary file."""
        self._file.close()


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
        elif kind in ("connection", "ignored", "goal", "replan"):
            detail = record.get("state") or record.get("reason") or record.get("goal") or ""
            events.append((record["t"], kind, record.get("vehicle"), str(detail)))
        elif kind == "end":
            end = record
    return {"states": states, "orders": orders, "events": events, "end": end}
