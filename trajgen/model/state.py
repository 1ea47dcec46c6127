"""The vehicles' states at sample times, on a track graph: one type for every schedule and every track.

A :class:`TrackState` says where each vehicle is (edge number and metres along it, on the schedule's
:attr:`~trajgen.model.schedule.Schedule.track`) and how it moves (signed axis and its derivatives).
Every schedule's ``state(t)`` and ``sample(period)`` give one; rows, tables, plots and checks read it,
whatever the track was at the door (a star's legs are the edges of its track graph, the junction the
point ``s = 0`` of each).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from topology import JUNCTION_INDEX, TrackGraph
from trajgen.model.values import ArrayValue, frozen

__all__ = ["TrackState"]

_ARRAYS = ("t", "axis", "velocity", "acceleration", "jerk", "edge", "s")


@dataclass(frozen=True, slots=True, eq=False)
class TrackState(ArrayValue):
    """States of the vehicles at n sample times (read-only arrays; ``m`` vehicles).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times, seconds.
    axis, velocity, acceleration, jerk : ndarray, shape (m, n)
        Per vehicle: signed axis (m), its velocity (m/s), acceleration (m/s²), jerk (m/s³).
    edge : ndarray of int, shape (m, n)
        Edge number in the track's order (:meth:`edge_names` gives the names); on a star, the leg.
    s : ndarray, shape (m, n)
        Metres from the edge's ``from`` node (on a star, from the junction).
    travel : ndarray, shape (m, n), or None
        Metres each vehicle has driven along its path, where the schedule keeps it (a track graph's
        schedule); ``None`` where it does not.
    """

    t: np.ndarray
    axis: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    edge: np.ndarray
    s: np.ndarray
    travel: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in _ARRAYS:
            object.__setattr__(self, name, frozen(np.asarray(getattr(self, name))))
        if self.travel is not None:
            object.__setattr__(self, "travel", frozen(np.asarray(self.travel)))

    def of(self, vehicles) -> TrackState:
        """The states of ``vehicles`` only (indices, in that order), at the same times."""
        rows = list(vehicles)
        return TrackState(
            self.t,
            *(getattr(self, name)[rows] for name in _ARRAYS if name != "t"),
            travel=None if self.travel is None else self.travel[rows],
        )

    @property
    def leg(self) -> np.ndarray:
        """The edge, or ``JUNCTION_INDEX`` (-1) where a vehicle is at its edge's ``from`` node, shape (m, n).

        On a star that node is the junction: this is the leg index the star's rows number from 1
        (0 at the junction).
        """
        return frozen(np.where(self.s > 0.0, self.edge, JUNCTION_INDEX))

    def edge_names(self, track: TrackGraph) -> np.ndarray:
        """Each vehicle's edge by its name in ``track``, shape (m, n), read-only."""
        names = np.array([edge.name for edge in track.edges], dtype=object)
        return frozen(names[self.edge])

    def leg_names(self, track: TrackGraph) -> np.ndarray:
        """Each vehicle's edge by name, or its ``from`` node's name where ``s = 0``, shape (m, n), read-only.

        On a star's track that node is the junction ``O``: the names of :attr:`leg`.

        Examples
        --------
        >>> from trajgen import default_scenario, make_schedule
        >>> scenario = default_scenario()
        >>> schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
        >>> state = schedule.state([0.0, schedule.duration])
        >>> state.leg_names(schedule.track).tolist(), state.leg.tolist()
        ([['A', 'B'], ['B', 'A']], [[0, 1], [1, 0]])
        """
        edges = np.array([edge.name for edge in track.edges], dtype=object)
        nodes = np.array([edge.start for edge in track.edges], dtype=object)
        return frozen(np.where(self.s > 0.0, edges[self.edge], nodes[self.edge]))

    def xy(self, track: TrackGraph) -> np.ndarray | None:
        """Each vehicle's x/y in metres as the track draws it, shape (m, 2, n) (``None``: no x/y).

        ``start + s * direction`` of the vehicle's edge (:meth:`~topology.TrackGraph.xy_along`).
        """
        if track.coordinates is None:
            return None
        x, y = track.xy_along(self.edge, self.s)
        return frozen(np.stack([x, y], axis=1))

    def labels(self, track: TrackGraph) -> np.ndarray:
        """Where each vehicle is as rows write it, ASCII bytes, shape (m, n).

        The edge's name; on a track with numbered legs (a star's), the leg's number from 1, ``0`` at
        the junction.
        """
        if track.numbered_legs:
            numbers = np.array([str(k).encode("ascii") for k in range(len(track.edges) + 1)], dtype=object)
            return numbers[self.leg + 1]
        names = np.array([edge.name.encode("ascii") for edge in track.edges], dtype=object)
        return names[self.edge]
