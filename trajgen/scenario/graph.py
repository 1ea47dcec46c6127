"""A planning problem on a track graph: several junctions, sidings, loops (docs/graphs.md).

A scenario file whose ``[track]`` has ``edges`` (not ``legs``) is read into a :class:`GraphScenario`
by :func:`trajgen.scenario.parse_scenario`; its :meth:`~GraphScenario.route` is the exact planner's
(:func:`topology.plan_graph`).
"""

from __future__ import annotations

from dataclasses import dataclass

from limits import Limits
from topology import EdgePoint, GraphRoute, TrackGraph, plan_graph
from trajgen.errors import InputError
from trajgen.scenario.naming import check_vehicle_names

__all__ = ["GraphScenario"]


@dataclass(frozen=True, slots=True)
class GraphScenario:
    """Two vehicles on a track graph: where they start, where they go, their limits.

    Attributes
    ----------
    track : TrackGraph
    limits : Limits
        Both vehicles' limits and the minimum separation (metres of track distance).
    names : tuple of 2 str
    start, goal : tuple of 2 EdgePoint
        Each vehicle's start and goal.
    source : str, optional
        Where it came from (file path; default ``<python>``).

    Examples
    --------
    >>> from limits import Limits, VehicleLimits
    >>> track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    >>> agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    >>> scenario = GraphScenario(
    ...     track, Limits((agv, agv), 1.5), ("agv1", "agv2"),
    ...     (track.point("A"), track.point("B")), (track.point("B"), track.point("A")),
    ... )
    >>> scenario.route().travel
    (15.0, 12.0)
    """

    track: TrackGraph
    limits: Limits
    names: tuple[str, str]
    start: tuple[EdgePoint, EdgePoint]
    goal: tuple[EdgePoint, EdgePoint]
    source: str = "<python>"

    def __post_init__(self) -> None:
        if not isinstance(self.track, TrackGraph):
            raise InputError(f"graph scenario track must be a TrackGraph, got {type(self.track).__name__}")
        if not isinstance(self.limits, Limits):
            raise InputError(f"scenario limits must be Limits, got {type(self.limits).__name__}")
        object.__setattr__(self, "names", check_vehicle_names(self.names))
        for what in ("start", "goal"):
            pair = tuple(self.track.point(p) for p in getattr(self, what))
            if len(pair) != 2:
                raise InputError(f"scenario {what} must be two positions, got {len(pair)}")
            object.__setattr__(self, what, pair)

    def route(self) -> GraphRoute:
        """The exact planner's route: the shortest collision-free one, one vehicle moving at a time.

        Raises
        ------
        InfeasibleError
            No collision-free route exists; the message names the vehicle and what blocks it.
        """
        return plan_graph(
            self.track, self.start, self.goal, min_separation=self.limits.min_separation, names=self.names
        )
