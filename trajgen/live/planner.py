"""Planning beside the network: each plan of a live run is made in a thread of its own.

The MQTT client's thread must keep pumping while a plan is made (its keep-alive, the states that
come in meanwhile); a plan can take seconds. :class:`PlanJob` runs one planning call in a daemon
thread and hands its result, or the error that ended it, to a callback. The master keeps at most
one job it waits for; a job it no longer waits for (a newer goal came, the run was stopped) is
dropped when it ends: its result is never used.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

__all__ = ["PlanJob"]

logger = logging.getLogger(__name__)


class PlanJob:
    """One planning call run in a thread of its own.

    Parameters
    ----------
    plan : callable
        Makes the plan (no arguments); what it returns is the job's result.
    done : callable
        Called in the job's thread with the job when the call has returned or raised; the job's
        :attr:`result` or :attr:`error` holds what it gave.
    what : str
        What is planned, in words (for the log and the thread's name).
    context : object
        What the owner needs to take the result up (where the plan starts, say).
    """

    def __init__(
        self, plan: Callable[[], object], done: Callable[[PlanJob], None], *, what: str, context=None
    ):
        self.what = what
        self.context = context
        self.result = None
        self.error: BaseException | None = None
        #: wall seconds the call took (reported, never used to decide)
        self.seconds = 0.0
        self._plan = plan
        self._done = done
        self._thread = threading.Thread(target=self._run, name=f"trajgen-plan: {what}", daemon=True)

    def start(self) -> PlanJob:
        """Start the call in its thread; returns the job at once."""
        self._thread.start()
        return self

    def _run(self) -> None:
        began = time.perf_counter()
        try:
            self.result = self._plan()
        except Exception as error:  # handed to the owner, which says it in its words
            self.error = error
        self.seconds = time.perf_counter() - began
        try:
            self._done(self)
        except Exception:  # the owner's callback must never die silently in this thread
            logger.exception("live: taking up the plan (%s) raised", self.what)
