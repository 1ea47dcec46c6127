"""A route on a track graph drawn from above: the track, where each vehicle starts and ends, its moves.

The geometry is :class:`trajgen.plots.track_layout.TrackLayout`'s; this module only draws it. Each
move is a line in its vehicle's colour, numbered at its middle in the order of the route and
arrowed at its end; a hollow circle marks where a vehicle starts, a hollow square where it ends.
"""

from __future__ import annotations

from topology import GraphRoute
from trajgen.errors import InputError
from trajgen.plots.figure import drawing_axis, finished
from trajgen.plots.track_layout import TrackLayout

__all__ = ["VEHICLE_COLOURS", "plot_graph_route"]

#: Each vehicle's colour (the animation's).
VEHICLE_COLOURS = ("tab:blue", "tab:orange")


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
    size = layout.extent
    axis = drawing_axis(ax, figsize=(9, 7))
    for number, line in enumerate(layout.edges):
        axis.plot(line[:, 0], line[:, 1], color="0.6", linewidth=6, solid_capstyle="round", zorder=1)
        middle = line[len(line) // 2]
        axis.annotate(
            track.edges[number].name,
            middle,
            xytext=(0, -12),
            textcoords="offset points",
            ha="center",
            fontsize=8,
            color="0.35",
        )
    axis.plot(layout.nodes[:, 0], layout.nodes[:, 1], "o", color="0.3", markersize=5, zorder=2)
    for name, (x, y) in zip(track.nodes, layout.nodes, strict=True):
        axis.annotate(name, (x, y), xytext=(5, 5), textcoords="offset points", fontsize=9, weight="bold")
    shift = 0.012 * size  # the two vehicles' lines side by side where they share the track
    for number, move in enumerate(route.moves):
        colour = VEHICLE_COLOURS[move.vehicle]
        line = layout.move(route, number) + (shift if move.vehicle == 0 else -shift)
        axis.plot(line[:, 0], line[:, 1], color=colour, linewidth=2.2, zorder=3)
        if len(line) >= 2:
            axis.annotate(
                "",
                line[-1],
                xytext=line[-2],
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 2.2},
                zorder=4,
            )
        middle = line[len(line) // 2]
        axis.annotate(
            str(number + 1),
            middle,
            ha="center",
            va="center",
            fontsize=8,
            color="white",
            weight="bold",
            bbox={"boxstyle": "circle,pad=0.2", "facecolor": colour, "edgecolor": "none"},
            zorder=5,
        )
    for vehicle in (0, 1):
        colour = VEHICLE_COLOURS[vehicle]
        start, goal = layout.point(route.start[vehicle]), layout.point(route.goal[vehicle])
        axis.plot(
            *start,
            "o",
            markersize=12,
            markerfacecolor="none",
            markeredgecolor=colour,
            markeredgewidth=2,
            zorder=6,
            label=f"{names[vehicle]}: start {track.name(route.start[vehicle])}",
        )
        axis.plot(
            *goal,
            "s",
            markersize=12,
            markerfacecolor="none",
            markeredgecolor=colour,
            markeredgewidth=2,
            zorder=6,
            label=f"{names[vehicle]}: goal {track.name(route.goal[vehicle])}",
        )
    axis.set_aspect("equal", adjustable="datalim")
    axis.margins(0.08)
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
