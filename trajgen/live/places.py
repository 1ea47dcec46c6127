"""Where live vehicles stand and go, on a junction or a track graph: goals, restarts, start nodes.

On a junction a vehicle says where it is by its map x/y (``agvPosition``: the legs drawn at their
angles, :mod:`trajgen.live.geometry`); on a track graph, whose edges may curve and whose nodes may
have no coordinates, by its ``lastNodeId``: a node's name or ``"EDGE:s"``, a position on the track
(:func:`~trajgen.export.vda5050.graph_path.point_id`).
"""

from __future__ import annotations

from topology import JUNCTION_INDEX, Configuration, EdgePoint, Position, StarGraph, TrackGraph
from trajgen.errors import InputError
from trajgen.export.vda5050.graph_path import GraphOrderPath, point_id
from trajgen.live.geometry import position_xy, track_position

__all__ = [
    "live_goal",
    "path_place",
    "reported_place",
    "restart_place",
    "scenario_starts",
    "snapshot_point",
    "start_place",
]


def live_goal(graph: StarGraph | TrackGraph, goal, count: int) -> Configuration | tuple[EdgePoint, ...]:
    """``goal`` checked on the track: a Configuration on a junction, an EdgePoint per vehicle on a graph.

    Raises
    ------
    InputError
        Not a goal for each of the ``count`` vehicles, or a position not on the track.
    """
    if isinstance(graph, TrackGraph):
        if not isinstance(goal, tuple | list) or len(goal) != count:
            raise InputError(
                f"live goal must be {count} positions on the track, one per vehicle, got {goal!r:.80}"
            )
        return tuple(graph.point(point) for point in goal)
    if not isinstance(goal, Configuration):
        raise InputError(f"live goal must be a Configuration, got {type(goal).__name__}")
    return Configuration(graph.check(goal.first), graph.check(goal.second))


def restart_place(graph: StarGraph | TrackGraph, state):
    """Where a vehicle back without its order stands (its VDA 5050 ``state``).

    Raises
    ------
    InputError
        Its ``lastNodeId`` names no place on the track graph.
    """
    if isinstance(graph, TrackGraph):
        return graph.point(state.last_node_id)
    return track_position(graph, state.agv_position.x, state.agv_position.y)


def reported_place(graph: StarGraph | TrackGraph, state) -> Position | EdgePoint | None:
    """Where a vehicle's VDA 5050 ``state`` says it is; ``None`` when it says nothing of it.

    On a track graph: ``lastNodeId`` (a node's name or ``"EDGE:s"``), ``distanceSinceLastNode``
    metres towards the first of its ``nodeStates``. On a junction: ``agvPosition`` (map x/y), or else
    ``lastNodeId`` (``"O"`` or ``"LEG:s"``).

    Raises
    ------
    InputError
        It names a place that is not on the track (naming it).
    """
    if isinstance(graph, TrackGraph):
        if not state.last_node_id:
            return None
        following = state.node_states[0].node_id if state.node_states else ""
        try:
            return snapshot_point(graph, state.last_node_id, following, state.distance_since_last_node or 0.0)
        except InputError as error:
            raise InputError(
                f"lastNodeId {state.last_node_id!r} is not a place on the track: {error}"
            ) from None
    if state.agv_position is not None:
        return track_position(graph, state.agv_position.x, state.agv_position.y)
    if not state.last_node_id:
        return None
    if state.last_node_id == "O":
        return Position(None, 0.0)
    try:
        return graph.check(Position.parse(state.last_node_id))
    except (InputError, ValueError):
        raise InputError(
            f"lastNodeId {state.last_node_id!r} is not a place on the junction: expected O or LEG:s"
        ) from None


def path_place(graph: StarGraph | TrackGraph, path, j: int, along: float) -> Position | EdgePoint:
    """The place ``along`` metres past node ``j`` of an order path, towards node ``j + 1``.

    ``path``: a :class:`~trajgen.export.vda5050.path.OrderPath` on a junction, a
    :class:`~trajgen.export.vda5050.graph_path.GraphOrderPath` on a track graph.
    """
    last = len(path.nodes) - 1
    if isinstance(path, GraphOrderPath):
        here = path.nodes[j].point
        if j >= last or along <= 0.0:
            return here
        return _point_between(graph, here, path.nodes[j + 1].point, along)
    node = path.nodes[j]
    if j >= last or along <= 0.0:
        return Position(None, 0.0) if node.leg == JUNCTION_INDEX else Position(graph.names[node.leg], node.s)
    following = path.nodes[j + 1]
    leg = path.edges[j].leg
    if leg == JUNCTION_INDEX:
        return Position(None, 0.0)
    step = min(along, abs(following.s - node.s))
    s = node.s + step if following.s >= node.s else node.s - step
    return Position(None, 0.0) if s <= 0.0 else Position(graph.names[leg], s)


def scenario_starts(scenario) -> tuple:
    """Both vehicles' starts in ``scenario``: Positions on a junction, EdgePoints on a track graph."""
    start = scenario.start
    return (start.first, start.second) if isinstance(start, Configuration) else tuple(start)


def start_place(graph: StarGraph | TrackGraph, position) -> tuple[tuple[float, float] | None, str]:
    """What a simulated vehicle standing at ``position`` knows: its map x/y and its node's id.

    On a junction its x/y (and no node id); on a track graph its node id alone (no x/y: the
    first order's first node must be that node, as VDA 5050 takes it).
    """
    if isinstance(graph, TrackGraph):
        # the id of the place its id reads back as: 0.4 µm from a node reads as the node, and the
        # master's order from there starts at the node's name
        written = point_id(graph, graph.point(position))
        return None, point_id(graph, graph.point(written))
    return position_xy(graph, position), ""


def snapshot_point(track: TrackGraph, node: str, next_node: str, along: float) -> EdgePoint:
    """The point ``along`` metres past node id ``node`` towards ``next_node`` on ``track``.

    Consecutive nodes of a path lie on one track edge (every track node a path passes is a node of
    it). Of parallel edges joining two track nodes, the first long enough is taken: the release
    nodes split every edge longer than their spacing, so only edges that short are ambiguous.

    Raises
    ------
    InputError
        A node id that names no place on the track.
    """
    here = track.point(node)
    if not next_node or along <= 0.0:
        return here
    return _point_between(track, here, track.point(next_node), along, names=(node, next_node))


def _point_between(
    track: TrackGraph, here: EdgePoint, there: EdgePoint, along: float, *, names: tuple[str, str] = ("", "")
) -> EdgePoint:
    """The point ``along`` metres from ``here`` towards ``there``, two places on one edge of ``track``."""
    node, next_node = names if names[0] else (track.name(here), track.name(there))
    edges = [here.edge] if here.edge == there.edge else []
    edges += [
        k
        for k in range(track.edge_count)
        if track.position_on(here, k) is not None and track.position_on(there, k) is not None
    ]
    if not edges:
        raise InputError(f"nodes {node!r} and {next_node!r} share no edge of the track")
    spans = [(k, track.position_on(here, k), track.position_on(there, k)) for k in edges]
    k, low, high = next((span for span in spans if abs(span[2] - span[1]) >= along - 1e-9), spans[0])
    step = min(along, abs(high - low))
    return track.point(EdgePoint(k, low + step if high >= low else low - step))
