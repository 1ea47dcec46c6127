"""Schedules on a track graph: both vehicles' travel over time along their paths (the data model).

A :class:`GraphSchedule` holds each vehicle's path (:class:`~trajgen.model.graph_paths.GraphPath`)
and both vehicles' travel ``p(t)`` as consecutive :class:`GraphSection` s, each piecewise cubic
(:class:`~trajgen.model.schedule.CubicKinematics`) or a TOPPRA section
(:class:`~trajgen.model.blended.ToppraKinematics`) in the plane of both travels.
The signed axis, velocity, acceleration and jerk a controller reads are the travel's, signed by the
path's heading (which flips only where the vehicle is at rest). Made by the timing methods'
:meth:`~trajgen.model.schedule.TimingMethod.schedule_graph`; checked by
:func:`trajgen.verification.verify`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import GraphRoute, TrackGraph
from trajgen.errors import InputError
from trajgen.model.graph_paths import GraphPath
from trajgen.model.schedule import (
    FallbackReason,
    MethodInfo,
    TimedSection,
    check_period,
    sample_block,
    sample_rows,
)
from trajgen.model.values import ArrayValue, frozen

__all__ = ["GraphSchedule", "GraphSection", "GraphState"]


#: A stretch of a schedule on a track graph: both vehicles' travel (metres along their paths) over
#: the section's local time (``start_time``, ``kinematics``, ``duration``).
GraphSection = TimedSection


@dataclass(frozen=True, slots=True, eq=False)
class GraphState(ArrayValue):
    """States of both vehicles on a track graph at sample times (read-only arrays).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times, seconds.
    travel : ndarray, shape (2, n)
        Metres each vehicle has driven along its path (never decreasing).
    axis, velocity, acceleration, jerk : ndarray, shape (2, n)
        Per vehicle: signed axis (m), its velocity (m/s), acceleration (m/s²), jerk (m/s³).
    edge : ndarray of int, shape (2, n)
        Edge number in the track's order (:meth:`edge_names` gives the names).
    s : ndarray, shape (2, n)
        Metres from the edge's ``from`` node.
    """

    t: np.ndarray
    travel: np.ndarray
    axis: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    edge: np.ndarray
    s: np.ndarray

    def __post_init__(self) -> None:
        for name in ("t", "travel", "axis", "velocity", "acceleration", "jerk", "edge", "s"):
            object.__setattr__(self, name, frozen(np.asarray(getattr(self, name))))

    def edge_names(self, track: TrackGraph) -> np.ndarray:
        """Each vehicle's edge by its name in ``track``, shape (2, n), read-only."""
        names = np.array([edge.name for edge in track.edges], dtype=object)
        return frozen(names[self.edge])

    def xy(self, track: TrackGraph) -> np.ndarray | None:
        """Each vehicle's x/y on the line of its edge's nodes, metres, shape (2, 2, n) (``None``: no x/y)."""
        if track.coordinates is None:
            return None
        coordinates = np.asarray(track.coordinates, dtype=float)
        ends = np.array([track.ends(k) for k in range(len(track.edges))], dtype=int)
        lengths = np.array([edge.length for edge in track.edges])
        fraction = self.s / lengths[self.edge]
        start, end = coordinates[ends[self.edge, 0]], coordinates[ends[self.edge, 1]]  # (2, n, 2)
        points = start + fraction[..., None] * (end - start)
        return frozen(np.moveaxis(points, -1, 1))


@dataclass(frozen=True, slots=True)
class GraphSchedule:
    """A timed motion of both vehicles along a route on a track graph.

    Attributes
    ----------
    route : GraphRoute
        The planner's route; the schedule keeps its class (which vehicle passes first at each conflict).
    limits : Limits
    method : TimingMethod
        The method, with its options, that computed the motion.
    paths : tuple of 2 GraphPath
        Each vehicle's path along the route.
    sections : tuple of GraphSection
        Consecutive in time, the first at t = 0: each vehicle's travel from 0 to its path's length.
    jerk_limited : bool
    notes : tuple of str
    fallback_reason : FallbackReason or None
        Set when the requested method could not deliver and this is the ``exact`` schedule instead.
    info : MethodInfo or None
    smoothness : int or None
        Continuous derivatives of position: 2 (acceleration too) when jerk-limited, else 1
        (``None``: that default). A table read back sets its interpolation's.
    end_tolerance : float or None
        Metres a table read back may be off its start, goal and path ends (``None``: a computed
        schedule, held to round-off there and from piece to piece).
    checked_limits : int or None
        Derivatives (1 = velocity, ...) whose limits are checked on the pieces in closed form
        (``None``: all); a table read back has the others checked from its points.
    """

    route: GraphRoute
    limits: Limits
    method: object
    paths: tuple[GraphPath, GraphPath]
    sections: tuple[GraphSection, ...]
    jerk_limited: bool
    notes: tuple[str, ...] = ()
    fallback_reason: FallbackReason | None = None
    info: MethodInfo | None = None
    smoothness: int | None = None
    end_tolerance: float | None = None
    checked_limits: int | None = None

    def __post_init__(self) -> None:
        if self.smoothness is None:
            object.__setattr__(self, "smoothness", 2 if self.jerk_limited else 1)
        object.__setattr__(self, "sections", tuple(self.sections))
        object.__setattr__(self, "notes", tuple(self.notes))
        if not self.sections:
            raise InputError("a graph schedule needs at least one section: expected one at t = 0")

    def __repr__(self) -> str:
        """One line: method, makespan, moves, jerk."""
        jerk = "jerk-limited" if self.jerk_limited else "jerk not limited"
        return (
            f"<GraphSchedule: {self.method.name}, {self.duration:.3f} s over "
            f"{len(self.route.moves)} move(s), "
            f"{jerk}>"
        )

    @property
    def track(self) -> TrackGraph:
        """The track the route runs on."""
        return self.route.track

    @property
    def duration(self) -> float:
        """Makespan: time until both vehicles are at rest at their goals, seconds."""
        last = self.sections[-1]
        return last.start_time + last.duration

    def travel(self, t) -> np.ndarray:
        """Both vehicles' travel (m), its velocity, acceleration and jerk at times ``t``, shape (2, 4, n).

        Travel never decreases; :meth:`state` signs its derivatives by each path's heading.
        """
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        starts = np.array([section.start_time for section in self.sections])
        index = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.sections) - 1)
        values = np.zeros((2, 4, t.size))  # travel, its velocity, acceleration, jerk
        for k, section in enumerate(self.sections):
            mask = index == k
            if mask.any():
                local = np.clip(t[mask] - section.start_time, 0.0, section.duration)
                if k == len(self.sections) - 1:
                    local[t[mask] >= self.duration] = section.duration
                values[:, :, mask] = section.kinematics.evaluate(local)
        return values

    def state(self, t) -> GraphState:
        """States of both vehicles at times ``t`` (seconds, clipped to [0, duration])."""
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        values = self.travel(t)
        travel = values[:, 0]
        axis, heading = np.zeros_like(travel), np.zeros_like(travel)
        edge = np.zeros(travel.shape, dtype=int)
        s = np.zeros_like(travel)
        for vehicle, path in enumerate(self.paths):
            axis[vehicle] = path.axis(travel[vehicle])
            heading[vehicle] = path.heading(travel[vehicle])
            edge[vehicle], s[vehicle] = path.locate(travel[vehicle])
        return GraphState(
            t, travel, axis, heading * values[:, 1], heading * values[:, 2], heading * values[:, 3], edge, s
        )

    def distances(self, state: GraphState) -> np.ndarray:
        """Track distance between the vehicles in ``state`` (this schedule's, at some times), metres, (n,)."""
        return self.track.distances(state.edge[0], state.s[0], state.edge[1], state.s[1])

    def sample(self, period: float) -> GraphState:
        """States every ``period`` seconds from t = 0, plus a last sample exactly at the goal."""
        period = check_period(period)
        return self.state(sample_block(self.duration, period, 0, sample_rows(self.duration, period)))
