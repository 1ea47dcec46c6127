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

from collections.abc import Sequence

from topology import EdgePoint, GraphMove, GraphRoute, Route, TrackGraph
from trajgen.model.axes import route_axes, straight_pieces
from trajgen.model.graph_paths import path_through
from trajgen.model.summary import class_label

__all__ = ["junction_graph_route"]


def _part(
    track: TrackGraph, vehicle: int, places: list[EdgePoint], length: float, at_start, movers
) -> GraphMove:
    """The move of ``vehicle`` through ``places``, kept at its ends and at the nodes it passes."""
    path = path_through(track, [p.edge for p in places], [p.s for p in places])
    if path.edges.size == 0:  # it moves less than a path resolves (MOVE_RESOLUTION)
        return GraphMove(vehicle, (places[0], places[-1]), (places[-1].edge,), length, at_start, movers)
    passed = [
        track.canonical(EdgePoint(int(e), float(s)))
        for e, s in zip(path.edges[1:], path.s_from[1:], strict=True)
    ]
    edges = tuple(int(e) for e in path.edges)
    return GraphMove(vehicle, (places[0], *passed, places[-1]), edges, length, at_start, movers)


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
    places = [
        tuple(track.canonical(route.graph.edge_point(position)) for position in configuration)
        for configuration in route.waypoints
    ]
    axes = route_axes(route).axes
    count = len(places[0])
    moves: list[GraphMove] = []
    travel = [0.0] * count
    for first, last in straight_pieces(axes):
        lengths = [abs(float(axes[last, v] - axes[first, v])) for v in range(count)]
        movers = tuple(v for v in range(count) if lengths[v] > 0.0)
        for v in movers:
            stops = [places[k][v] for k in range(first, last + 1)]
            moves.append(_part(track, v, stops, lengths[v], places[first], movers))
            travel[v] += lengths[v]
    return GraphRoute(
        track,
        route.min_separation,
        places[0],
        places[-1],
        tuple(moves),
        tuple(travel),
        0,
        0,
        tuple(names),
        class_label(route),
    )
