"""What ``trajgen serve`` and ``trajgen demo --live`` say as a run goes: one line per event, timed.

Each line is an event of the run log (:mod:`trajgen.live.runlog`) as it is written: planning,
the broker, each vehicle's place and connection, the first orders of each plan, goals, restarts
and re-plans, every fault (a refusal, an order not taken, a vehicle off its plan, an ignored
message), a stop and the end. Order updates and states are left out (the log has them). The time
is seconds of the run's clock since the command started (planning and waits included), not the
log's ``t`` (which counts from the first orders).

While the timeline prints, the log lines that say the same (tagged ``timeline``) are kept off
stderr: each thing is said once.
"""

from __future__ import annotations

import contextlib
import logging
import sys
from collections.abc import Callable, Iterator

from trajgen.cli.logs import StderrHandler

__all__ = ["Timeline", "timeline_line"]


def _planned(record: dict) -> str:
    line = (
        f"planned {record['what']} in {record['planning_s']:.2f} s: {record['planned_s']:.2f} s, "
        f"{record['computed_by']}"
    )
    if record.get("fallback_reason"):
        line += f" (instead of {record['method']}: {record['fallback_reason']})"
    return line


def _order(record: dict) -> str | None:
    if record["resent"] or record["first"] != 0:  # updates and re-sends: the log has them
        return None
    return f"{record['vehicle']}: order, base to {record['frontier_m']:.2f} m along its path"


#: Each event the timeline says, as a line (``None``: left out).
_LINES: dict[str, Callable[[dict], str | None]] = {
    "planning": lambda r: f"planning {r['what']} ({r['method']})",
    "planned": _planned,
    "broker": lambda r: f"broker: {r['detail']}",
    "place": lambda r: f"{r['vehicle']} stands at {r['at']}" + (" (driving)" if r["driving"] else ""),
    "unplaced": lambda r: f"{r['vehicle']} says no place on the track: {r['reason']}",
    "off-start": lambda r: (
        f"{r['vehicle']} stands at {r['at']}, not at {r['start']} where the plan starts it: no order is sent"
    ),
    "connection": lambda r: f"{r['vehicle']} is {r['state']}",
    "order": _order,
    "cancel": lambda r: f"cancelOrder to {r['vehicle']}: {r['reason']}",
    "goal": lambda r: f"new goal {r['goal']}: holding every vehicle at its base",
    "restart": lambda r: f"{r['vehicle']} is back without its order at {r['at']}",
    "replan": lambda r: f"re-planned: new orders towards {r['goal']}",
    "vehicle-error": lambda r: f"{r['vehicle']} reports {r['type']}: {r['description']}",
    "order-not-taken": lambda r: f"{r['vehicle']} has not taken its order (it reports {r['reports']})",
    "off-plan": lambda r: f"{r['vehicle']} stands off its plan ({r['reason']}): nothing is released",
    "on-plan": lambda r: f"{r['vehicle']} is back on its plan",
    "ignored": lambda r: f"ignored a message on {r['topic']}: {r['reason']}",
    "stop": lambda r: (
        f"stopped by {r['reason']}: nothing more released, cancelOrder to "
        f"{', '.join(r['cancelled']) or 'no vehicle'}"
    ),
    "end": lambda r: f"end: {r['outcome']}",
}


def timeline_line(record: dict) -> str | None:
    """The line a run log record makes in the timeline, without its time; ``None``: not said."""
    line = _LINES.get(record.get("event"))
    return None if line is None else line(record)


class Timeline:
    """Print a run's events as they are logged (a :class:`~trajgen.live.runlog.RunLog` listener).

    Parameters
    ----------
    clock : RunClock
        The run's clock; the lines' times count from when the timeline was made.
    stream : file, optional
        Where the lines go (default: ``sys.stdout`` at each line).
    """

    def __init__(self, clock, *, stream=None) -> None:
        self.clock = clock
        self.stream = stream
        self._zero = clock.now()

    def __call__(self, record: dict) -> None:
        """Print ``record``'s line, if it makes one."""
        line = timeline_line(record)
        if line is not None:
            stream = self.stream if self.stream is not None else sys.stdout
            print(f"{self.clock.now() - self._zero:9.2f} s  {line}", file=stream, flush=True)

    @contextlib.contextmanager
    def quiet_duplicates(self) -> Iterator[None]:
        """While it prints: the stderr log lines tagged ``timeline`` (the same news) are left out."""
        handlers = [handler for handler in logging.getLogger().handlers if isinstance(handler, StderrHandler)]

        def said_elsewhere(record: logging.LogRecord) -> bool:
            return not getattr(record, "timeline", False)

        for handler in handlers:
            handler.addFilter(said_elsewhere)
        try:
            yield
        finally:
            for handler in handlers:
                handler.removeFilter(said_elsewhere)
