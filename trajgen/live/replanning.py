"""Where a re-plan starts: every vehicle standing at its decision point, or where it restarted.

A new goal, or a vehicle back without its order, holds every release; once each vehicle stands, at
rest and online, at the decision point it was given (or at the place a restarted one reports),
:func:`replan_start` gives where the new plan starts and how each new path numbers its nodes. When
the plan is made, :func:`moved_since` says whether a vehicle moved meanwhile (then plan again).
"""

from __future__ import annotations

from trajgen.live.start_check import same_place

__all__ = ["moved_since", "replan_start"]


def replan_start(graph, views, released) -> tuple[tuple, tuple[int, ...]] | None:
    """Where every vehicle stands for a re-plan, and the ``sequenceId`` each new path starts at.

    Parameters
    ----------
    graph : StarGraph or TrackGraph
    views : sequence of VehicleView
    released : sequence of int
        Per vehicle, the index of its decision point on its path.

    Returns
    -------
    tuple or None
        ``(places, offsets)``; ``None`` while a vehicle still drives, is offline, or is short of its
        decision point. A vehicle restarted without its order numbers its new one from 0; the others
        go on from their last node.
    """
    for v, view in enumerate(views):
        at_base = view.restart is not None or view.node == released[v]
        if not at_base or view.driving or view.online is False:
            return None
    places = tuple(view.standing(graph) for view in views)
    offsets = tuple(0 if view.restart is not None else view.offset + 2 * view.node for view in views)
    return places, offsets


def moved_since(graph, views, places) -> bool:
    """Whether a vehicle drives, or stands elsewhere than at ``places`` (where a plan was made from)."""
    return any(
        view.driving or not same_place(graph, view.standing(graph), place)
        for view, place in zip(views, places, strict=True)
    )
