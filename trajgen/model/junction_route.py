"""A junction's route as a route on its track graph: the door of the one model below the planners.

A Y or a star is a track graph (:meth:`~topology.StarGraph.track_graph`: the junction the node
``O``, each leg an edge from it named as the leg). Baldi's route (:func:`topology.plan`) is a list
of waypoints of both vehicles; on the track graph it is a :class:`~topology.GraphRoute` whose moves
are the route's *straight pieces* (:func:`~trajgen.model.axes.straight_pieces`: where neither
vehicle turns and both keep their share of the motion): a piece that moves one vehicle is a move of
it, a piece that moves both a joint move. The vehicles come to rest at the end of every piece, as
in ``exact``. The route keeps the paper's homotopy class as its label.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

from topology import JUNCTION_INDEX, JUNCTION_NAME, EdgePoint, GraphMove, GraphRoute, Route, TrackGraph
from trajgen.model.axes import route_axes, straight_pieces
from trajgen.model.summary import class_label

__all__ = ["junction_graph_route"]


def _point(track: TrackGraph, leg: int, s: float) -> EdgePoint:
    """The point ``s`` metres out on leg ``leg`` (the junction at ``JUNCTION_INDEX`` or 0 m)."""
    if leg == JUNCTION_INDEX or s == 0.0:
        return track.node_point(track.node(JUNCTION_NAME))
    return track.canonical(EdgePoint(leg, s))


def _part(
    track: TrackGraph, vehicle: int, places: list[tuple[int, float]], length: float, at_start, movers
) -> GraphMove:
    """The move of ``vehicle`` through ``places`` (leg, s), kept at its ends and at the nodes it passes."""
    junction = track.node_point(track.node(JUNCTION_NAME))
    points = [_point(track, *places[0])]
    edges: list[int] = []
    for (leg_a, s_a), (leg_b, s_b) in itertools.pairwise(places):
        if (leg_a, s_a) == (leg_b, s_b):
            continue
        target = _point(track, leg_b, s_b)
        on_a = leg_a != JUNCTION_INDEX and s_a > 0.0
        on_b = leg_b != JUNCTION_INDEX and s_b > 0.0
        if on_a and on_b and leg_a != leg_b:  # through the junction
            points.append(junction)
            edges.append(leg_a)
            edges.append(leg_b)
        else:
            edges.append(leg_a if on_a else leg_b)
        points.append(target)
    # one point per node passed: drop the route's waypoints between them
    kept = [0] + [k for k in range(1, len(points) - 1) if track.node_at(points[k]) is not None]
    kept.append(len(points) - 1)
    return GraphMove(
        vehicle,
        tuple(points[k] for k in kept),
        tuple(edges[k] for k in kept[:-1]),
        length,
        at_start,
        movers,
    )


def junction_graph_route(route: Route, *, names: Sequence[str] = ("vehicle 1", "vehicle 2")) -> GraphRoute:
    """``route`` (a junction's) on the junction's track graph, its straight pieces as moves.

    Parameters
    ----------
    route : Route
        From :func:`topology.plan`.
    names : sequence of 2 str
        The vehicles' names.

    Returns
    -------
    GraphRoute
        Its ``label`` the route's class (:func:`~trajgen.model.summary.class_label`); no roadmap was
        searched (``critical_points`` and ``searched`` 0).

    Notes
    -----
    A track graph holds a place within 1 nm (``POINT_TOLERANCE``) of a node as the node: a route
    that moves a vehicle less than that there (a start 5e-10 m out on a leg) gives a route the
    route verifier passes, but a schedule of it the verifier refuses (its path leaves out the
    move).
    """
    track = route.graph.track_graph()
    waypoints = route.indexed_waypoints
    axes = route_axes(route).axes
    count = len(waypoints[0]) // 2

    def places(k: int) -> tuple[EdgePoint, ...]:
        return tuple(_point(track, waypoints[k][2 * v], waypoints[k][2 * v + 1]) for v in range(count))

    moves: list[GraphMove] = []
    travel = [0.0] * count
    for first, last in straight_pieces(axes):
        lengths = [abs(float(axes[last, v] - axes[first, v])) for v in range(count)]
        movers = tuple(v for v in range(count) if lengths[v] > 0.0)
        at_start = places(first)
        for v in movers:
            stops = [(waypoints[k][2 * v], waypoints[k][2 * v + 1]) for k in range(first, last + 1)]
            moves.append(_part(track, v, stops, lengths[v], at_start, movers))
            travel[v] += lengths[v]
    return GraphRoute(
        track,
        route.min_separation,
        places(0),
        places(len(waypoints) - 1),
        tuple(moves),
        tuple(travel),
        0,
        0,
        tuple(names),
        class_label(route),
    )
