"""The order a verified plan keeps between every pair of vehicles: its conflicts, frontiers and followers.

Each pair of vehicles has its coordination diagram (:class:`~trajgen.model.coordination.CoordinationDiagram`):
its conflicts and, at each, which of the two the plan lets pass first. A vehicle may come to rest
no farther than its **frontier**: the least, over the pairs it is in, of its frontier in that pair's
diagram from the other vehicle's earliest rest point (docs/online.md, 'The executor'). What the
executor holds first when the braking check fails is read here too: the vehicles that follow at a
conflict their leader has not yet passed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from trajgen.model.coordination import pair_diagrams

__all__ = ["PlanConflicts"]


class PlanConflicts:
    """The coordination diagram of every pair of a plan's vehicles.

    Parameters
    ----------
    schedule : Schedule or GraphSchedule
        The verified plan: it decides who passes each conflict first.
    paths : sequence of GraphPath
        Each vehicle's path on the schedule's track graph, in travel coordinates (a junction's
        too: :func:`~trajgen.model.coordination.schedule_paths`).
    times : ndarray
        The plan's instants between which no vehicle turns
        (:func:`~trajgen.model.coordination.schedule_times`).
    separation : float
        Track distance the conflicts keep, metres.
    """

    __slots__ = ("count", "diagrams")

    def __init__(self, schedule, paths: Sequence, times, separation: float) -> None:
        self.count = len(paths)
        #: ``((i, j), diagram)`` for every pair of vehicles, in the order of ``itertools.combinations``
        self.diagrams = pair_diagrams(schedule, tuple(paths), separation, times)

    def frontiers(self, earliest: Sequence[float]) -> tuple[float, ...]:
        """Each vehicle's frontier, metres of its travel (``inf``: nothing binds it).

        Parameters
        ----------
        earliest : sequence of float
            Each vehicle's earliest rest point, metres of its travel
            (:func:`~trajgen.model.coordination.earliest_rest`).
        """
        out = [math.inf] * self.count
        for (i, j), diagram in self.diagrams:
            out[i] = min(out[i], diagram.frontier(0, earliest[j]))
            out[j] = min(out[j], diagram.frontier(1, earliest[i]))
        return tuple(out)

    def followers(self, travel: Sequence[float]) -> list[int]:
        """The vehicles that follow at a conflict their leader has not yet passed, in vehicle order.

        Parameters
        ----------
        travel : sequence of float
            Each vehicle's travel now, metres.
        """
        found: set[int] = set()
        for pair, diagram in self.diagrams:
            for side, vehicle in enumerate(pair):
                leader = pair[1 - side]
                if any(c.follower == side for c in diagram.leading(1 - side, travel[leader])):
                    found.add(vehicle)
        return sorted(found)
