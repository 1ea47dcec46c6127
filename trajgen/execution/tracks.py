"""What the executor needs to know about the track it runs on: a junction, or a track graph.

The executor's cycle (frontiers, Ruckig, the braking check, holds) is the same on every track; the
two peers here answer what differs: how a verified plan becomes paths in travel coordinates and a
plan player, how a measured state is checked and projected onto a path, where a vehicle at rest
stands and which way its axis runs there (for a re-plan), and how a new goal is checked and
planned. :func:`execution_track` picks the peer of a schedule.

On a junction a measured state's ``leg`` is a leg index (``JUNCTION_INDEX`` at the junction) and
``s`` the metres from the junction; on a track graph ``leg`` is an edge index and ``s`` the metres
from the edge's ``from`` node (a node may be given on any of its edges).
"""

from __future__ import annotations

import itertools

from limits import Limits
from topology import (
    JUNCTION_INDEX,
    Configuration,
    EdgePoint,
    GraphRoute,
    Position,
    Route,
    StarGraph,
    TrackGraph,
)
from trajgen.errors import InputError
from trajgen.execution.goals import goal_refusal, graph_schedule_from_rest, schedule_from_rest
from trajgen.execution.messages import VehicleState, check_measured_numbers, checked_state
from trajgen.execution.motion import GraphPlanPlayer, PlanPlayer
from trajgen.model.coordination import schedule_paths, schedule_times, schedule_waypoints
from trajgen.model.graph_paths import GraphPath, graph_paths
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.model.paths import VehiclePath
from trajgen.model.schedule import TimingMethod
from trajgen.model.summary import class_label
from trajgen.verification import VerifiedSchedule

__all__ = ["GraphTrack", "JunctionTrack", "LoadedPlan", "execution_track"]

#: A measured position this far past an edge's end is on it (round-off of the drive), metres.
_END_ROUND_OFF = 1e-6


class LoadedPlan:
    """A verified plan in the executor's form: paths, the diagram's paths, its instants, its player.

    Attributes
    ----------
    paths : tuple of 2 VehiclePath or 2 GraphVehiclePath
        Each vehicle's path, continuing its own axis.
    diagram_paths : tuple of 2
        The paths the coordination diagram takes: ``GraphPath`` s on the track graph (a junction's too).
    times : ndarray
        The plan's instants for the diagram (:func:`~trajgen.model.coordination.schedule_times`).
    player : PlanPlayer
    """

    __slots__ = ("diagram_paths", "paths", "player", "times")

    def __init__(self, paths, diagram_paths, times, player: PlanPlayer) -> None:
        self.paths, self.diagram_paths, self.times, self.player = paths, diagram_paths, times, player


class JunctionTrack:
    """The executor's track for a junction (a Y or a star): legs measured from the junction.

    Parameters
    ----------
    graph : StarGraph
    """

    __slots__ = ("graph",)

    def __init__(self, graph: StarGraph) -> None:
        self.graph = graph

    def check_state(self, state: object, number: int) -> VehicleState:
        """``state`` if it is a measured state on the junction (:func:`checked_state`)."""
        return checked_state(state, number, self.graph)

    def load(self, verified: VerifiedSchedule, *, axis_start, orientation) -> LoadedPlan:
        """``verified`` as paths, a player and the diagram's input, continuing each vehicle's axis.

        ``axis_start``, ``orientation``: ``None``, or each vehicle's axis value and
        ``(leg, ds / d axis)`` where it stands.
        """
        schedule = verified.schedule
        player = PlanPlayer.of(verified)
        diagram_paths, times, _ = schedule_paths(schedule)  # on the junction's track graph
        waypoints = schedule_waypoints(schedule, times)
        paths = []
        for v in (0, 1):
            start = player.state(v, 0.0)[0] if axis_start is None else axis_start[v]
            sign = None
            if orientation[v] is not None:
                leg, sign = orientation[v]
                first = VehiclePath.from_waypoints(waypoints, v)
                if first.legs and first.legs[0] != leg:  # it leaves the junction on another leg: ds flips
                    sign = -sign
            paths.append(VehiclePath.from_waypoints(waypoints, v, axis_start=start, orientation=sign))
        return LoadedPlan((paths[0], paths[1]), diagram_paths, times, player)

    def project(self, path: VehiclePath, leg: int, s: float, near: float, slack: float) -> float | None:
        """The travel at which ``path`` passes ``(leg, s)`` nearest ``near`` (:meth:`VehiclePath.project`)."""
        return path.project(leg, s, near, slack)

    def position(self, state: VehicleState) -> Position:
        """Where a vehicle measured at ``state`` stands, as the planner takes it."""
        if state.leg == JUNCTION_INDEX or state.s <= 0.0:
            return Position(None, 0.0)
        return Position(self.graph.names[state.leg], min(state.s, self.graph.lengths[state.leg]))

    def orientation(self, path: VehiclePath, p: float) -> tuple[int, int] | None:
        """``(leg, ds / d axis)`` of a vehicle at travel ``p`` of ``path``.

        ``None`` at the junction, unmoved. An unmoved path keeps the orientation it was loaded with
        (:attr:`~trajgen.model.paths.VehiclePath.home_orientation`).
        """
        if not path.legs:
            leg = path.home[0]
            return None if leg == JUNCTION_INDEX else (leg, path.home_orientation)
        return path.legs[path.segment(p)], path.outward(p) * path.heading(p)

    def goal_with(self, goal: Configuration, vehicle: int, position) -> Configuration:
        """``goal`` with ``vehicle``'s goal replaced by ``position``.

        Raises
        ------
        InputError
            ``position`` is not on the junction.
        """
        goal = list(goal)
        goal[vehicle] = self.graph.check(position)
        return Configuration(*goal)

    def goal_refusal(self, goal: Configuration, required: float) -> str | None:
        """Why ``goal`` cannot be taken (closer than ``required`` metres), or ``None``."""
        return goal_refusal(self.graph, goal, required)

    def plan_from_rest(
        self, limits: Limits, start, goal, *, method: TimingMethod, margin: float, names: tuple[str, ...]
    ) -> VerifiedSchedule:
        """The verified plan from ``start`` to ``goal`` for execution (:func:`schedule_from_rest`)."""
        return schedule_from_rest(self.graph, limits, start, goal, method=method, margin=margin)

    def start_of(self, positions: tuple[Position, Position]) -> Configuration:
        """Both vehicles' positions as a start."""
        return Configuration(*positions)

    def name(self, what) -> str:
        """A position or a configuration as the events write it."""
        return str(what)

    def describe(self, route: Route) -> str:
        """The route's class, as every summary names it (``class planned (counterclockwise)``)."""
        return f"class {class_label(route)}"


class GraphTrack:
    """The executor's track for a track graph: edges measured from their ``from`` node.

    Parameters
    ----------
    track : TrackGraph
    """

    __slots__ = ("graph", "metric")

    def __init__(self, track: TrackGraph) -> None:
        self.graph = track
        self.metric = GraphMetric(track)

    def check_state(self, state: object, number: int) -> VehicleState:
        """``state`` if it is a measured state on the track, clamped to its edge's end by round-off (1 µm).

        Raises
        ------
        InputError
            Not a VehicleState, a number that is not finite, an unknown edge, or a position off it.
        """
        check_measured_numbers(state, number)
        count = self.graph.edge_count
        if isinstance(state.leg, bool) or not isinstance(state.leg, int) or not 0 <= state.leg < count:
            raise InputError(
                f"vehicle {number} measured edge must be an edge index 0 to {count - 1} of the track's "
                f"{count} edges, got {state.leg!r}"
            )
        top = self.graph.length(state.leg)
        if not -_END_ROUND_OFF <= state.s <= top + _END_ROUND_OFF:
            raise InputError(
                f"vehicle {number} measured s {state.s!r} m is off edge "
                f"{self.graph.edges[state.leg].name!r}: expected 0 to {top!r} m"
            )
        if not 0.0 <= state.s <= top:
            return VehicleState(state.leg, min(max(state.s, 0.0), top), state.velocity, state.acceleration)
        return state

    def load(self, verified: VerifiedSchedule, *, axis_start, orientation) -> LoadedPlan:
        """``verified`` as paths, a player and the diagram's input, continuing each vehicle's axis.

        ``axis_start``, ``orientation``: ``None``, or each vehicle's axis value and
        ``(edge, s, ds / d axis)`` where it stands.
        """
        schedule: GraphSchedule = verified.schedule
        player = GraphPlanPlayer(verified)
        plan_paths = graph_paths(schedule.route)
        paths = []
        for v, path in enumerate(plan_paths):
            start = player.state(v, 0.0)[0] if axis_start is None else axis_start[v]
            sign = None if orientation[v] is None else self._sign_on(path, *orientation[v])
            paths.append(GraphVehiclePath.from_path(path, self.graph, axis_start=start, orientation=sign))
        return LoadedPlan(tuple(paths), plan_paths, schedule_times(schedule), player)

    def _sign_on(self, path: GraphPath, edge: int, s: float, sign: int) -> int:
        """``ds / d axis`` on ``path``'s first edge, of a vehicle with ``ds / d axis = sign`` on ``edge``.

        At a node the new path may leave on another edge: moving away from the node on it is moving
        towards the node on ``edge``, and each edge measures ``s`` from its own ``from`` node.
        """
        if path.edges.size == 0 or int(path.edges[0]) == edge:
            return sign
        node = self.graph.node_at(EdgePoint(edge, s))
        if node is None:  # not at a node: the path starts on the vehicle's own edge
            return sign
        other = int(path.edges[0])
        away_here = 1 if self.graph.ends(edge)[0] == node else -1
        away_there = 1 if self.graph.ends(other)[0] == node else -1
        return -sign * away_here * away_there

    def project(self, path: GraphVehiclePath, edge: int, s: float, near: float, slack: float) -> float | None:
        """The travel at which ``path`` passes ``(edge, s)`` nearest ``near`` (its ``project``)."""
        return path.project(edge, s, near, self.metric, slack)

    def position(self, state: VehicleState) -> EdgePoint:
        """Where a vehicle measured at ``state`` stands, as the planner takes it."""
        return EdgePoint(state.leg, min(max(state.s, 0.0), self.graph.length(state.leg)))

    def orientation(self, path: GraphVehiclePath, p: float) -> tuple[int, float, int]:
        """``(edge, s, ds / d axis)`` of a vehicle at travel ``p`` of ``path``.

        An unmoved path keeps the orientation it was loaded with on its home edge
        (:attr:`~trajgen.model.graph_vehicle_path.GraphVehiclePath.home_orientation`).
        """
        if not path.edges:
            edge, s = path.home
            return edge, s, path.home_orientation
        k = path.segment(p)
        edge, s = path.locate(p)
        return edge, s, (1 if path.s_to[k] > path.s_from[k] else -1) * path.headings[k]

    def goal_with(self, goal: tuple[EdgePoint, ...], vehicle: int, position) -> tuple[EdgePoint, ...]:
        """``goal`` with ``vehicle``'s goal replaced by ``position`` (``"EDGE:s"``, a node, or an EdgePoint).

        Raises
        ------
        InputError
            ``position`` is not on the track.
        """
        goals = list(goal)
        goals[vehicle] = self.graph.point(position)
        return tuple(goals)

    def goal_refusal(self, goal: tuple[EdgePoint, ...], required: float) -> str | None:
        """Why ``goal`` cannot be taken (two vehicles closer than ``required`` metres), or ``None``."""
        for i, j in itertools.combinations(range(len(goal)), 2):
            apart = self.graph.distance(goal[i], goal[j])
            if apart < required:
                names = ", ".join(self.graph.name(point) for point in goal)
                between = "" if len(goal) == 2 else f" vehicles {i + 1} and {j + 1}"
                return (
                    f"goal ({names}) leaves the{between or ' vehicles'} {apart:.3f} m apart: expected at "
                    f"least {required:.3f} m"
                )
        return None

    def plan_from_rest(
        self, limits: Limits, start, goal, *, method: TimingMethod, margin: float, names: tuple[str, ...]
    ) -> VerifiedSchedule:
        """The verified plan from ``start`` to ``goal`` for execution (:func:`graph_schedule_from_rest`)."""
        return graph_schedule_from_rest(
            self.graph, limits, start, goal, method=method, margin=margin, names=names
        )

    def start_of(self, positions: tuple[EdgePoint, ...]) -> tuple[EdgePoint, ...]:
        """Every vehicle's position as a start."""
        return positions

    def name(self, what) -> str:
        """A position (EdgePoint) or a pair of them as the events write it (``"EDGE:s"`` or a node)."""
        if isinstance(what, EdgePoint):
            return self.graph.name(what)
        return "(" + ", ".join(self.graph.name(point) for point in what) + ")"

    def describe(self, route: GraphRoute) -> str:
        """The route's moves, as the events name it."""
        travel = " and ".join(f"{metres:.3f} m" for metres in route.travel)
        return f"{len(route.moves)} move(s), {travel} of travel"


def execution_track(schedule) -> JunctionTrack | GraphTrack:
    """The executor's track of ``schedule``: a :class:`GraphTrack` on a track graph, else a junction's."""
    if isinstance(schedule, GraphSchedule):
        return GraphTrack(schedule.track)
    return JunctionTrack(schedule.route.graph)
