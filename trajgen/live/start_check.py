"""Before the first orders: whether the vehicles stand where the plan starts them, and what then.

:func:`start_decision` reads what the vehicles reported (their views) against the plan's starts and
says what the master does next: wait, tell a vehicle to cancel an earlier run's order, send the
first orders, plan again from where the vehicles stand, or refuse. It decides only; the coordinator
(:mod:`trajgen.live.coordinator`) acts.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

from trajgen.live.plans import START_TOLERANCE
from trajgen.live.view import VehicleView, never_heard_message

__all__ = ["CANCEL_RESEND_S", "StartDecision", "not_begun", "same_place", "start_decision"]

#: Wall seconds between two ``cancelOrder`` to a vehicle whose states do not show it yet.
CANCEL_RESEND_S = 0.5


def same_place(graph, place, other) -> bool:
    """Whether two places on ``graph`` are one, within :data:`~trajgen.live.plans.START_TOLERANCE`."""
    return graph.distance(place, other) <= START_TOLERANCE


@dataclass(frozen=True, slots=True)
class StartDecision:
    """What the master does next before the first orders.

    Attributes
    ----------
    action : str
        ``"wait"`` (for a place, a vehicle to stand, a cancel to show), ``"cancel"`` (send
        ``cancelOrder`` to ``vehicles``; ``again``: the same action once more), ``"begin"`` (send the
        first orders), ``"plan"`` (plan from ``places``; ``off``: the vehicles not at the plan's start)
        or ``"refuse"`` (``why``).
    vehicles : tuple of int
        The vehicles to send ``cancelOrder``.
    again : bool
    places : tuple
        Where every vehicle stands (for ``"plan"``).
    off : tuple of int
        The vehicles not where the plan starts them (for ``"plan"``).
    why : str
        Why the master refuses (``"refuse"``), naming the vehicles and places; or why it cancels.
    """

    action: str
    vehicles: tuple[int, ...] = ()
    again: bool = False
    places: tuple = ()
    off: tuple[int, ...] = ()
    why: str = ""


def start_decision(
    graph, track, views: list[VehicleView], starts, *, separation: float, planned_from, goal_pending: bool
) -> StartDecision:
    """What to do before the first orders, from the vehicles' views (the plan made, the broker there).

    Parameters
    ----------
    graph : StarGraph or TrackGraph
    track : JunctionTrack or GraphTrack
        How places are named.
    views : list of VehicleView
    starts : sequence
        Where the plan starts each vehicle.
    separation : float
        The scenario's minimum separation, metres.
    planned_from : tuple or None
        The places the plan was made from, when it was made from reported places.
    goal_pending : bool
        A new goal was asked for before the first orders: plan for it from where they stand.

    Returns
    -------
    StartDecision
    """
    if any(view.place is None or view.driving for view in views):
        return StartDecision("wait")
    foreign = [v for v, view in enumerate(views) if view.foreign is not None]
    if foreign:
        new = tuple(
            v for v in foreign if views[v].cancelled is None or views[v].cancelled_order != views[v].foreign
        )
        if new:
            held = ", ".join(repr(views[v].foreign) for v in new)
            return StartDecision("cancel", vehicles=new, why=f"it still holds order {held} of an earlier run")
        due = tuple(
            v
            for v in foreign
            if not views[v].told and time.monotonic() - views[v].cancel_sent_at >= CANCEL_RESEND_S
        )
        if not due:
            return StartDecision("wait")
        return StartDecision("cancel", vehicles=due, again=True, why="sent again: not yet shown in its state")
    places = tuple(view.place for view in views)
    off = tuple(v for v in range(len(views)) if not same_place(graph, places[v], starts[v]))
    if not off and not goal_pending:
        return StartDecision("begin")
    again = planned_from is not None and all(map(same_place, [graph] * len(places), places, planned_from))
    if off and again:
        at = track.name(track.start_of(places))
        why = f"master: the plan made from {at} does not start there; no order was sent"
        return StartDecision("refuse", why=why)
    for v, w in itertools.combinations(range(len(places)), 2):
        apart = graph.distance(places[v], places[w])
        if apart < separation:
            return StartDecision(
                "refuse",
                off=off,
                why=f"master: {views[v].name} at {track.name(places[v])} and {views[w].name} at "
                f"{track.name(places[w])} stand {apart:.3f} m apart, closer than the separation "
                f"{separation:g} m: no plan starts there (move them apart and start again); no order "
                "was sent",
            )
    return StartDecision("plan", places=places, off=off)


def not_begun(views: list[VehicleView], planning: str | None) -> str:
    """What the first orders still waited for, in words (``planning``: the plan being made, if any)."""
    if planning is not None:
        return f"the plan ({planning}) was still being made"
    parts = []
    silent = [view for view in views if not view.heard]
    if silent:
        parts.append(never_heard_message(silent))
    for view in views:
        if view.heard and view.place is None:
            said = view.unplaced or "its states give no lastNodeId and no agvPosition"
            parts.append(f"{view.name} did not say where it stands ({said})")
        elif view.foreign is not None:
            parts.append(f"{view.name} still held order {view.foreign!r} of an earlier run (told to cancel)")
        elif view.driving:
            parts.append(f"{view.name} was driving")
    return "; ".join(parts) or "nothing (it was about to)"
