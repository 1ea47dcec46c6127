"""A planning problem on a track graph: several junctions, sidings, loops (docs/graphs.md).

A scenario file whose ``[track]`` has ``edges`` (not ``legs``) is read into a :class:`GraphScenario`
by :func:`trajgen.scenario.parse_scenario`; its :meth:`~GraphScenario.route` is the exact planner's
(:func:`topology.plan_graph`).
"""

from __future__ import annotations

from dataclasses import dataclass

from limits import Limits
from topology import EdgePoint, GraphRoute, TrackGraph, check_vehicle_count, plan_graph
from trajgen.errors import InputError
from trajgen.scenario.naming import check_vehicle_names

__all__ = ["GraphScenario"]


@dataclass(frozen=True, slots=True)
class GraphScenario:
    """Vehicles on a track graph: where they start, where they go, their limits.

    Any number of vehicles is read and held; the planner (:meth:`route`) takes two today.

    Attributes
    ----------
    track : TrackGraph
    limits : Limits
        Each vehicle's limits and the minimum separation (metres of track distance).
    names : tuple of str
        One per vehicle.
    start, goal : tuple of EdgePoint
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
    names: tuple[str, ...]
    start: tuple[EdgePoint, ...]
    goal: tuple[EdgePoint, ...]
    source: str = "<python>"

    def __post_init__(self) -> None:
        if not isinstance(self.track, TrackGraph):
            raise InputError(f"graph scenario track must be a TrackGraph, got {type(self.track).__name__}")
        if not isinstance(self.limits, Limits):
            raise InputError(f"scenario limits must be Limits, got {type(self.limits).__name__}")
        object.__setattr__(self, "names", check_vehicle_names(self.names, count=self.limits.count))
        for what in ("start", "goal"):
            points = tuple(self.track.point(p) for p in getattr(self, what))
            if len(points) != self.limits.count:
                raise InputError(
                    f"scenario {what} must be {self.limits.count} positions, one per vehicle, "
                    f"got {len(points)}"
                )
            object.__setattr__(self, what, points)

    def check_planned(self) -> None:
        """Refuse, naming :attr:`source`, a number of vehicles the planner does not plan (two, today).

        Raises
        ------
        VehicleCountError
        """
        check_vehicle_count(self.limits.count, "the track-graph planner", source=self.source)

    def route(self) -> GraphRoute:
        """The exact planner's route: the shortest collision-free one, one vehicle moving at a time.

        Raises
        ------
        InfeasibleError
            No collision-free route exists; the message names the vehicle and what blocks it.
        VehicleCountError
            Not two vehicles (the planner takes two today); the message names the scenario's source.
        """
        self.check_planned()
        return plan_graph(
            self.track, self.start, self.goal, min_separation=self.limits.min_separation, names=self.names
        )
