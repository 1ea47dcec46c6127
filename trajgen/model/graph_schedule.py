"""Schedules on a track graph: every vehicle's travel over time along its path (the data model).

A :class:`GraphSchedule` holds each vehicle's path (:class:`~trajgen.model.graph_paths.GraphPath`)
and every vehicle's travel ``p(t)`` as consecutive :class:`GraphSection` s, each piecewise cubic
(:class:`~trajgen.model.schedule.CubicKinematics`) or a TOPPRA section
(:class:`~trajgen.model.blended.ToppraKinematics`) in the plane of both travels.
The signed axis, velocity, acceleration and jerk a controller reads are the travel's, signed by the
path's heading (which flips only where the vehicle is at rest). Made by the timing methods'
:meth:`~trajgen.model.schedule.TimingMethod.schedule_graph`; checked by
:func:`trajgen.verification.verify`.
"""

from __future__ import annotations

import itertools
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
from trajgen.model.state import TrackState

__all__ = ["GraphSchedule", "GraphSection", "GraphState"]


#: A stretch of a schedule on a track graph: every vehicle's travel (metres along its path) over
#: the section's local time (``start_time``, ``kinematics``, ``duration``).
GraphSection = TimedSection


#: The states a track graph's schedule gives: the one :class:`~trajgen.model.state.TrackState`, with
#: each vehicle's ``travel``.
GraphState = TrackState


@dataclass(frozen=True, slots=True)
class GraphSchedule:
    """A timed motion of vehicles along a route on a track graph (any number: ``count``).

    Attributes
    ----------
    route : GraphRoute
        The planner's route; the schedule keeps its class (which vehicle passes first at each conflict).
    limits : Limits
    method : TimingMethod
        The method, with its options, that computed the motion.
    paths : tuple of GraphPath
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
    paths: tuple[GraphPath, ...]
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
        """Makespan: time until every vehicle is at rest at its goal, seconds."""
        last = self.sections[-1]
        return last.start_time + last.duration

    def travel(self, t) -> np.ndarray:
        """Every vehicle's travel (m), its velocity, acceleration and jerk at times ``t``, shape (V, 4, n).

        Travel never decreases; :meth:`state` signs its derivatives by each path's heading.
        """
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        starts = np.array([section.start_time for section in self.sections])
        index = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.sections) - 1)
        values = np.zeros((len(self.paths), 4, t.size))  # travel, its velocity, acceleration, jerk
        for k, section in enumerate(self.sections):
            mask = index == k
            if mask.any():
                local = np.clip(t[mask] - section.start_time, 0.0, section.duration)
                if k == len(self.sections) - 1:
                    local[t[mask] >= self.duration] = section.duration
                values[:, :, mask] = section.kinematics.evaluate(local)
        return values

    def state(self, t) -> TrackState:
        """States of every vehicle at times ``t`` (seconds, clipped to [0, duration])."""
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
        return TrackState(
            t,
            axis,
            heading * values[:, 1],
            heading * values[:, 2],
            heading * values[:, 3],
            edge,
            s,
            travel=travel,
        )

    @property
    def count(self) -> int:
        """How many vehicles the schedule moves."""
        return len(self.paths)

    def pair_distances(self, state: TrackState) -> np.ndarray:
        """Track distance of every pair of vehicles in ``state``, metres, shape (P, n).

        Pairs in the order of ``itertools.combinations(range(count), 2)``.
        """
        return np.array(
            [
                self.track.distances(state.edge[i], state.s[i], state.edge[j], state.s[j])
                for i, j in itertools.combinations(range(len(self.paths)), 2)
            ]
        ).reshape(-1, np.shape(state.t)[0])

    def distances(self, state: TrackState) -> np.ndarray:
        """The least track distance between any two vehicles in ``state`` (this schedule's), metres, (n,)."""
        pairs = self.pair_distances(state)
        return np.min(pairs, axis=0) if pairs.size else np.full(np.shape(state.t), np.inf)

    def sample(self, period: float) -> TrackState:
        """States every ``period`` seconds from t = 0, plus a last sample exactly at the goal."""
        period = check_period(period)
        return self.state(sample_block(self.duration, period, 0, sample_rows(self.duration, period)))
