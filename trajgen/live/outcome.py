"""What a live run did: its outcome and its figures (:class:`LiveRun`)."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["LiveOutcome", "LiveRun"]


class LiveOutcome(enum.Enum):
    """How a live run ended."""

    GOALS_REACHED = "goals-reached"  #: both vehicles stand at their goals
    TIMED_OUT = "timed-out"  #: the time limit passed first
    BROKER_FAILED = "broker-failed"  #: the broker connection failed for good (see ``LiveRun.error``)
    ORDER_NOT_TAKEN = "order-not-taken"  #: a vehicle kept reporting it lacks its order (``LiveRun.error``)
    #: the master would not drive (or go on): no plan starts where the vehicles stand, or a vehicle
    #: stood off its plan too long (``LiveRun.error``)
    REFUSED = "refused"
    INTERRUPTED = "interrupted"  #: stopped by a signal (SIGINT, SIGTERM); the vehicles were told


@dataclass(frozen=True, slots=True)
class LiveRun:
    """What a live run did.

    Attributes
    ----------
    outcome : LiveOutcome
    makespan : float
        Seconds of the run from the first order to both vehicles at their goals (or to the time out).
    planned : float
        When the first plan's releases bring both vehicles to their goals, seconds
        (:attr:`~trajgen.export.vda5050.release.OrderReleases.planned_duration`).
    orders : int
        Orders and order updates published, re-sends included.
    resent : int
        How many of them were re-sends (after a reconnection, or to a vehicle whose state lagged).
    ignored : int
        Messages logged and ignored.
    replans : int
        New goals taken.
    release_latency : numpy.ndarray
        Per release, wall seconds from taking the state that allowed it to publishing the update,
        shape (releases,), read-only.
    plan : dict
        Which method was asked for the first plan and which computed it
        (:func:`~trajgen.model.summary.provenance`: ``method``, ``computed_by``,
        ``fallback_reason``, ``time_limit_reached``).
    error : str or None
        Why the run ended early, in one sentence (a refused login, an untrusted certificate, an
        order a vehicle never took); ``None`` otherwise.
    waits : dict
        What came before the run's time 0, seconds of the run's clock: ``broker_wait_s`` from the
        master's start to its connection to the broker, ``vehicle_wait_s`` from there to every
        vehicle placed where the plan starts it and the first orders sent (``None``: not reached).
    closest : float
        The smallest track distance between two vehicles' latest reported places, taken at every
        state the master took, metres (``inf`` before two vehicles said where they are).
    planning : float
        Wall seconds the plans of the run took, the first and every re-plan (reported, never used
        to decide).
    told : tuple of str
        The vehicles whose states showed the master's ``cancelOrder`` when the run was stopped.
    """

    outcome: LiveOutcome
    makespan: float
    planned: float
    orders: int
    resent: int
    ignored: int
    replans: int
    release_latency: np.ndarray
    plan: dict = field(default_factory=dict)
    error: str | None = None
    waits: dict = field(default_factory=dict)
    closest: float = math.inf
    planning: float = 0.0
    told: tuple = ()

    def summary(self) -> dict:
        """A JSON-ready summary (``closest_m`` ``None`` before two vehicles said where they are)."""
        latency = self.release_latency
        return {
            "outcome": self.outcome.value,
            **self.plan,
            "makespan_s": self.makespan,
            "planned_s": self.planned,
            "orders": self.orders,
            "resent": self.resent,
            "ignored": self.ignored,
            "replans": self.replans,
            "releases": int(latency.size),
            "release_latency_median_ms": float(np.median(latency) * 1e3) if latency.size else None,
            "broker_wait_s": self.waits.get("broker_wait_s"),
            "vehicle_wait_s": self.waits.get("vehicle_wait_s"),
            "closest_m": self.closest if math.isfinite(self.closest) else None,
            "planning_s": self.planning,
            "told": list(self.told),
            "error": self.error,
        }
