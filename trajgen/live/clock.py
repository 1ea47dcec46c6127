"""The run's clock: simulated seconds that may run faster than the wall clock."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from datetime import UTC, datetime, timedelta

from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = ["LEAD", "TIME_SCALE_RANGE", "RunClock"]

#: Seconds of the run a clock runs ahead of the slowest simulated vehicle it follows, at most.
LEAD = 0.1
#: Time scales a run takes: at most 100 times faster than the wall clock.
TIME_SCALE_RANGE = (0.01, 100.0)


class RunClock:
    """Seconds of the run since it started, ``time_scale`` times the wall clock's.

    Parameters
    ----------
    time_scale : float
        How many seconds of the run pass per wall-clock second (1: real time).

    Raises
    ------
    InputError
        ``time_scale`` outside :data:`TIME_SCALE_RANGE`.
    """

    __slots__ = ("_began", "_followers", "_lock", "_lost", "_started_at", "time_scale")

    def __init__(self, time_scale: float = 1.0) -> None:
        low, high = TIME_SCALE_RANGE
        if (
            isinstance(time_scale, bool)
            or not isinstance(time_scale, int | float)
            or not math.isfinite(time_scale)
            or not low <= time_scale <= high
        ):
            raise InputError(
                f"time scale {short_repr(time_scale)} is out of range: expected a number from {low} to {high}"
            )
        self.time_scale = float(time_scale)
        self._began = time.monotonic()
        self._started_at = datetime.now(UTC)
        self._followers: list[Callable[[], float]] = []
        self._lost = 0.0
        self._lock = threading.Lock()

    def follow(self, simulated_time: Callable[[], float]) -> None:
        """Never run more than :data:`LEAD` seconds ahead of ``simulated_time()`` (a simulated vehicle's).

        Vehicles simulated in one process share a clock; one whose thread was kept from running
        (a loaded machine) would otherwise fall behind the others and the master in the run's time.
        The clock waits for it instead: the time it waited is not the run's.
        """
        with self._lock:
            self._followers.append(simulated_time)

    def now(self) -> float:
        """Seconds of the run so far."""
        with self._lock:
            raw = (time.monotonic() - self._began) * self.time_scale - self._lost
            if self._followers:
                cap = min(follower() for follower in self._followers) + LEAD
                if raw > cap:
                    self._lost += raw - cap
                    raw = cap
            return raw

    def wall_seconds(self, run_seconds: float) -> float:
        """Wall-clock seconds that ``run_seconds`` of the run take."""
        return run_seconds / self.time_scale

    def sleep(self, run_seconds: float) -> None:
        """Wait ``run_seconds`` of the run."""
        time.sleep(max(0.0, run_seconds) / self.time_scale)

    def timestamp(self, run_seconds: float | None = None) -> str:
        """ISO 8601 UTC time of a moment of the run (default: now), milliseconds, as VDA 5050 writes it."""
        seconds = self.now() if run_seconds is None else run_seconds
        moment = self._started_at + timedelta(seconds=seconds)
        return moment.strftime("%Y-%m-%dT%H:%M:%S.") + f"{moment.microsecond // 1000:03d}Z"
