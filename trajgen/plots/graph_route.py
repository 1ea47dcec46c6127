"""A route on a track graph drawn from above: the track, where each vehicle starts and ends, its moves.

The geometry is :class:`trajgen.plots.track_layout.TrackLayout`'s, the track drawn as every picture
draws it (:func:`~trajgen.plots.track_drawing.draw_track`). Each move is a line in its vehicle's
colour, numbered at its middle in the order of the route and arrowed at its end; a hollow circle
marks where a vehicle starts, a hollow square where it ends.
"""

from __future__ import annotations

from topology import GraphRoute
from trajgen.errors import InputError
from trajgen.plots.figure import drawing_axis, finished
from trajgen.plots.speed import vehicle_colour
from trajgen.plots.track_drawing import draw_move, draw_track, fit_track, mark_end
from trajgen.plots.track_layout import TrackLayout

__all__ = ["plot_graph_route"]


def plot_graph_route(route: GraphRoute, *, names: tuple[str, str] = ("vehicle 1", "vehicle 2"), ax=None):
    """The track graph seen from above with the route's moves, numbered in order.

    Parameters
    ----------
    route : GraphRoute
        From :func:`topology.plan_graph` (or ``GraphScenario.route()``).
    names : tuple of 2 str, optional
        The vehicles' names, for the legend and the title.
    ax : matplotlib Axes, optional
        Where to draw (default: a new Figure of 9 x 7 inches).

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding the plot.

    Raises
    ------
    InputError
        ``route`` is not a GraphRoute.
    """
    if not isinstance(route, GraphRoute):
        raise InputError(f"plot_graph_route takes a GraphRoute, got {type(route).__name__}")
    track = route.track
    layout = TrackLayout.of(track)
    axis = drawing_axis(ax, figsize=(9, 7))
    fit_track(axis, layout)
    draw_track(axis, layout, width=6.0, fontsize=8.0)
    shift = 0.012 * layout.extent  # the two vehicles' lines side by side where they share the track
    for number, move in enumerate(route.moves, start=1):
        line = layout.move(route, number - 1) + (shift if move.vehicle == 0 else -shift)
        draw_move(axis, line, vehicle_colour(move.vehicle), number)
    for vehicle in range(route.count):
        colour = vehicle_colour(vehicle)
        for point, goal in ((route.start[vehicle], False), (route.goal[vehicle], True)):
            what = "goal" if goal else "start"
            label = f"{names[vehicle]}: {what} {track.name(point)}"
            mark_end(axis, layout.point(point), goal=goal, colour=colour, label=label)
    axis.set_aspect("equal", adjustable="box")
    axis.set_xlabel("x [m]" if layout.given else "laid out from the track distances [m]")
    axis.set_ylabel("y [m]" if layout.given else "")
    axis.set_title(
        f"shortest collision-free route, {route.min_separation:g} m apart: {names[0]} "
        f"{route.travel[0]:g} m, {names[1]} {route.travel[1]:g} m, {len(route.moves)} moves (numbered)",
        fontsize=10,
    )
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
    axis.grid(True, alpha=0.2)
    return finished(axis, laid_out=ax is None)
