"""A route on a track graph: moves of the vehicles, one at a time or jointly (the data model).

The track-graph planner (:func:`topology.plan_graph`) moves one vehicle at a time. A junction's
planner (:func:`topology.plan`) moves two at once where its instructions do (retracting a start onto
the boundary of the configuration space, or a goal off it): such a *joint move* is written as one
:class:`GraphMove` per moving vehicle, consecutive in the route, every vehicle reaching its end at
once (a straight line in the space of their travels, each vehicle's share of it fixed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from topology.errors import PositionError
from topology.track_graph import EdgePoint, TrackGraph

__all__ = ["GraphMove", "GraphRoute", "class_signature"]


@dataclass(frozen=True, slots=True)
class GraphMove:
    """One vehicle's move along the track, alone or as its part of a joint move.

    Attributes
    ----------
    vehicle : int
        Which vehicle moves: its index in the route's vehicles.
    points : tuple of EdgePoint
        Where it starts, each node it passes, where it ends.
    edges : tuple of int
        The edge it runs along from each point to the next (``len(points) - 1`` of them).
    length : float
        Metres travelled.
    at_start : tuple of EdgePoint
        Every vehicle's point as the move begins, one per vehicle (the moving one's is
        ``points[0]``); the vehicles not in ``movers`` stand there throughout.
    movers : tuple of int
        Every vehicle that moves meanwhile, in vehicle order: ``(vehicle,)`` for a move alone (the
        default); for a joint move, the vehicles of its consecutive moves in the route, which all
        begin together and reach their ends together.
    """

    vehicle: int
    points: tuple[EdgePoint, ...]
    edges: tuple[int, ...]
    length: float
    at_start: tuple[EdgePoint, ...]
    movers: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not self.movers:
            object.__setattr__(self, "movers", (self.vehicle,))

    @property
    def joint(self) -> bool:
        """Whether other vehicles move at the same time (a part of a joint move)."""
        return len(self.movers) > 1

    def standing(self) -> tuple[tuple[int, EdgePoint], ...]:
        """``(vehicle, point)`` of each vehicle that stands during the move, in vehicle order."""
        return tuple((v, point) for v, point in enumerate(self.at_start) if v not in self.movers)


@dataclass(frozen=True, slots=True, eq=False)
class GraphRoute:
    """A collision-free route of vehicles on a track graph: its moves in order.

    Attributes
    ----------
    track : TrackGraph
    min_separation : float
        Metres of track distance kept at all times.
    start, goal : tuple of EdgePoint
        One per vehicle.
    moves : tuple of GraphMove
        In order. A new move starts where another vehicle takes over or the moving one turns back;
        the parts of a joint move are consecutive (:attr:`steps`).
    travel : tuple of float
        Metres each vehicle travels (the track-graph planner minimises their sum).
    critical_points : int
        Critical points of the roadmap before the search (nodes, starts, goals and the points at
        the separation from them); the search adds those at the separation from where a vehicle
        stands as it reaches them.
    searched : int
        Pairs of critical points the search expanded (how hard the planning was).
    names : tuple of str
        The vehicles' names the planner was given (for messages and summaries).
    label : str or None
        The route's class as its planner names it (a junction's homotopy class,
        ``"planned (counterclockwise)"``); ``None``: the class is the order of passing at each
        conflict, read off the moves.
    """

    track: TrackGraph
    min_separation: float
    start: tuple[EdgePoint, ...]
    goal: tuple[EdgePoint, ...]
    moves: tuple[GraphMove, ...]
    travel: tuple[float, ...]
    critical_points: int
    searched: int
    names: tuple[str, ...] = ("vehicle 1", "vehicle 2")
    label: str | None = None

    def __post_init__(self) -> None:
        counts = {len(self.start), len(self.goal), len(self.travel), len(self.names)}
        counts |= {len(move.at_start) for move in self.moves}
        if len(counts) != 1 or not all(0 <= move.vehicle < len(self.start) for move in self.moves):
            raise PositionError(
                f"a route of {len(self.start)} vehicle(s) has {len(self.goal)} goal(s), "
                f"{len(self.travel)} travel(s), {len(self.names)} name(s) and moves of "
                f"{sorted({len(m.at_start) for m in self.moves})} vehicle(s) by vehicles "
                f"{sorted({m.vehicle for m in self.moves})}: expected one of each per vehicle"
            )
        self._joint_moves()

    def _joint_moves(self) -> None:
        """Refuse parts of a joint move that are not consecutive, in vehicle order, from one place."""
        track, names = self.track, self.names
        k = 0
        while k < len(self.moves):
            first = self.moves[k]
            movers = tuple(first.movers)
            parts = self.moves[k : k + len(movers)]
            together = [names[v] if 0 <= v < len(names) else v for v in movers]
            where = f"move {k + 1} ({names[first.vehicle]}, of a joint move of {together})"
            problem = None
            if list(movers) != sorted(set(movers)) or first.vehicle not in movers:
                problem = "its movers are not distinct vehicles in order, its own among them"
            elif tuple(part.vehicle for part in parts) != movers:
                moved = [names[part.vehicle] for part in parts]
                problem = f"the {len(movers)} moves from it move {moved}, not one per vehicle in turn"
            elif any(tuple(part.movers) != movers for part in parts):
                problem = "the other parts name other movers"
            elif any(
                track.canonical(a) != track.canonical(b)
                for part in parts
                for a, b in zip(part.at_start, first.at_start, strict=True)
            ):
                problem = "its parts say the vehicles stand at different places as it begins"
            if problem is not None:
                raise PositionError(
                    f"{where}: {problem}: expected one move per vehicle of a joint move, consecutive, in "
                    f"vehicle order, all beginning where the vehicles stand together"
                )
            k += len(movers)

    @property
    def count(self) -> int:
        """How many vehicles the route moves."""
        return len(self.start)

    @property
    def length(self) -> float:
        """The route's cost, metres: every vehicle's travel."""
        return sum(self.travel)

    @property
    def steps(self) -> tuple[tuple[GraphMove, ...], ...]:
        """The moves grouped by what happens at once: a move alone, or the parts of a joint move."""
        steps, k = [], 0
        while k < len(self.moves):
            width = len(self.moves[k].movers)
            steps.append(self.moves[k : k + width])
            k += width
        return tuple(steps)

    def corners(self) -> np.ndarray:
        """Every vehicle's travel before the first step and after each that moves, metres.

        The route in the space of every vehicle's travel: a polyline through these corners, shape
        ``(m + 1, count)`` (steps that move nothing left out).
        """
        corners = [np.zeros(self.count)]
        for step in self.steps:
            if any(part.length > 0.0 for part in step):
                here = corners[-1].copy()
                for part in step:
                    here[part.vehicle] += part.length
                corners.append(here)
        return np.array(corners)


def class_signature(route: GraphRoute) -> tuple:
    """What makes a route's class: each move's vehicles and the edges it runs along, in order.

    Two routes whose moves run the same edges in the same order (parking in the same siding,
    passing a loop on the same side) differ only in how deep a vehicle waits: one class. A joint
    move's parts carry every vehicle of it (two vehicles driving an edge each at once are not one
    after the other).
    """
    return tuple((move.vehicle, move.edges, *((move.movers,) if move.joint else ())) for move in route.moves)
