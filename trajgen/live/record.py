"""What a live run did, kept as it goes: counts, latencies, the closest approach, waits, plans.

:class:`RunRecord` is the coordinator's tally; :meth:`RunRecord.live_run` turns it into the
:class:`~trajgen.live.outcome.LiveRun` the master returns, with the error that ended the run early.
"""

from __future__ import annotations

import math

import numpy as np

from trajgen.live.outcome import LiveOutcome, LiveRun
from trajgen.live.view import run_failure

__all__ = ["RunRecord", "stop_message"]


def stop_message(views, reason: str) -> str:
    """What a run stopped by ``reason`` (a signal's name) did: no more releases, whom it told."""
    sent = [view for view in views if view.cancelled is not None]
    shown = [view.name for view in sent if view.told]
    return (
        f"master: stopped by {reason}: nothing more released; cancelOrder sent to "
        f"{', '.join(view.name for view in sent) or 'no vehicle'}"
        + (f", shown by {', '.join(shown) or 'none of them'}" if sent else "")
    )


class RunRecord:
    """A live run's tally, from the master's start to its end (its caller holds the lock)."""

    def __init__(self) -> None:
        self.ignored = 0  # messages logged and ignored
        self.replans = 0
        self.latencies: list[float] = []  # wall seconds, state taken to release published
        self.closest = math.inf  # metres, between two vehicles' latest reported places
        self.planning_s = 0.0  # wall seconds of every plan made
        self.planned_s = 0.0  # the first plan's duration (its releases'), seconds
        self.provenance: dict = {}  # the first plan's method, as summaries give it
        self.began_at = 0.0  # run clock at the master's start
        self.broker_at: float | None = None  # run clock at the first connection to the broker
        self.started_at: float | None = None  # run clock at the first orders: the run's time 0
        self.end_time = 0.0  # run clock when every vehicle stood at its goal

    def near(self, graph, place, others) -> None:
        """A vehicle's new place: the closest approach to the ``others``' places (``None``: unknown)."""
        for other in others:
            if other is not None:
                self.closest = min(self.closest, graph.distance(place, other))

    def waits(self) -> dict:
        """Run seconds from the master's start to the broker, and from there to the first orders."""
        broker, began = self.broker_at, self.started_at
        return {
            "broker_wait_s": None if broker is None else broker - self.began_at,
            "vehicle_wait_s": None if began is None or broker is None else began - broker,
        }

    def live_run(
        self, outcome: LiveOutcome, *, now: float, orders: tuple[int, int], why, link, broker_url, views
    ) -> LiveRun:
        """The :class:`LiveRun` of the run ending ``now`` (run clock) with ``outcome``.

        ``orders``: orders published and how many of them were re-sent; ``why``: the master's reason
        for an early end; ``link``: its BrokerLink; ``views``: the vehicles'.
        """
        began = self.started_at if self.started_at is not None else now
        latency = np.array(self.latencies, dtype=float)
        latency.flags.writeable = False
        return LiveRun(
            outcome,
            (self.end_time if outcome is LiveOutcome.GOALS_REACHED else now) - began,
            self.planned_s,
            orders[0],
            orders[1],
            self.ignored,
            self.replans,
            latency,
            dict(self.provenance),
            run_failure(outcome, link, why=why, broker_url=broker_url),
            self.waits(),
            closest=self.closest,
            planning=self.planning_s,
            told=tuple(view.name for view in views if view.told),
        )
