"""``configuration.png`` drawn: where the two vehicles of a Y can be at once, laid flat, with a route.

The picture is drawn on :class:`trajgen.plots.configuration_layout.ConfigurationLayout`
(where everything lies, computed apart from the drawing): the regions and the
boundary circle, the too-close parts, the route, a schedule's path, retraction
traces and the motion retracted onto the circle. Its words are plain: each point is
(position of vehicle 1, position of vehicle 2), a quadrangle ``Q(A,B)`` is the area
"agv1 on A, agv2 on B", the boundary circle the rim, the retraction moving out to the rim;
the paper's notation is mapped to them in docs/planner.md, 'Reading configuration.png'. A
junction of four or more legs has no flat drawing: it is handed to
:func:`trajgen.plots.star_configuration.plot_retract_graph`.
"""

from __future__ import annotations

import numpy as np

from topology import JUNCTION_INDEX, RegionKey, Route, WayRound, YGraph
from topology.indexed import IndexedConfiguration
from trajgen.plots.configuration_layout import ConfigurationLayout, rotate, route_samples, schedule_samples
from trajgen.plots.figure import drawing_area, finished, untangle, wrapped
from trajgen.plots.star_configuration import configuration_subject, plot_retract_graph
from trajgen.verification import VerifiedSchedule

__all__ = ["plot_configuration"]


#: Fill colours of the quadrangles and the triangles; colours of the route, the schedule and the retraction.
_QUADRANGLE_COLOUR = "#dce9f5"
_TRIANGLE_COLOUR = "#f6e7cc"
_ROUTE_COLOUR = "tab:blue"
_SCHEDULE_COLOUR = "tab:red"
_RETRACTION_COLOUR = "tab:orange"
#: The retracted motion is drawn this much outside the boundary circle, so both stay visible.
_OUTSET = 1.07
#: Retraction traces drawn from the motion.
_TRACES = 14
#: The smallest font the labels in the drawing shrink to, points.
_SMALLEST_LABEL = 5.5
#: Width of the note under the picture, inches.
_FOOTNOTE_IN = 7.7
#: The retraction traces in the legend, in plain words.
_TRACES_LABEL = "moved out to the rim (the vehicles driven apart)"
#: How far beyond its triangle a triangle's words are written, outwards, drawing units.
_GAP = 0.03
#: Behind the words in the drawing: they stay legible over the lines.
_TEXT_BOX = {"boxstyle": "round,pad=0.1", "facecolor": "white", "edgecolor": "none", "alpha": 0.7}


def _region_text(graph: YGraph, key: RegionKey, who: tuple[str, str]) -> str:
    """A region in words: where each vehicle is in it."""
    names = graph.names
    if key.nearer:
        return f"both on {names[key.first_leg]},\n{who[key.nearer - 1]} nearer O"
    return f"{who[0]} on {names[key.first_leg]}\n{who[1]} on {names[key.second_leg]}"


def _corner_text(graph: YGraph, c: IndexedConfiguration) -> str:
    """A corner of the rim: ``(where vehicle 1 is, where vehicle 2 is)``, O or the end of a leg."""
    names = graph.names
    return "({}, {})".format(*("O" if c[k] == JUNCTION_INDEX else names[c[k]] for k in (0, 2)))


def _alignment(direction: np.ndarray) -> tuple[str, str]:
    """How a label is aligned to its anchor so that it lies in ``direction`` (a unit vector) of it."""
    across = "left" if direction[0] > 0.3 else "right" if direction[0] < -0.3 else "center"
    return across, "bottom" if direction[1] > 0.3 else "top" if direction[1] < -0.3 else "center"


def _draw_space(axis, layout: ConfigurationLayout, who: tuple[str, str]) -> list:
    """The regions, the too-close parts, the rays, the rim and the labels in plain words (returned)."""
    graph = layout.graph
    labels = []
    for key in layout.regions:
        polygon = layout.region_polygon(key)
        colour = _TRIANGLE_COLOUR if key.nearer else _QUADRANGLE_COLOUR
        axis.fill(*polygon.T, facecolor=colour, edgecolor="0.55", linewidth=0.8, zorder=1)
        if key.nearer:  # beside its triangle, outwards, clear of it: the triangle is too small for the words
            out = polygon.mean(axis=0) / np.hypot(*polygon.mean(axis=0))
            place = polygon.mean(axis=0) + (np.max((polygon - polygon.mean(axis=0)) @ out) + _GAP) * out
            size, align = 7, _alignment(out)
        else:
            place, size, align = 0.55 * layout.peak(key.first_leg, key.second_leg), 8.5, ("center", "center")
        text = axis.text(
            *place,
            _region_text(graph, key, who),
            ha=align[0],
            va=align[1],
            fontsize=size,
            color="0.25",
            zorder=2,
            bbox=_TEXT_BOX,
        )
        labels.append(text)
    for k, polygon in enumerate(layout.too_close_polygons()):
        axis.fill(
            *polygon.T,
            facecolor="tab:red",
            alpha=0.3,
            edgecolor="none",
            hatch="////",
            zorder=2,
            label=f"too close: under {layout.min_separation:g} m apart along the track" if k == 0 else None,
        )
    for k, c in enumerate(graph.cycle.vertex_tuples):
        vertex = layout.vertices[k]
        if JUNCTION_INDEX in (c[0], c[2]):
            axis.plot(
                *np.array([[0.0, 0.0], vertex]).T,
                color="0.45",
                linewidth=0.9,
                linestyle="--",
                zorder=2,
                label="one vehicle at the junction O" if k == 1 else None,
            )
            place = vertex + 0.17 * rotate(vertex / np.hypot(*vertex), -0.6)
        else:
            place = 1.1 * vertex
        labels.append(
            axis.text(*place, _corner_text(graph, c), ha="center", va="center", fontsize=8, zorder=3)
        )
    star = np.vstack([layout.vertices, layout.vertices[:1]])
    axis.plot(
        *star.T,
        color="black",
        linewidth=2.0,
        zorder=3,
        label=f"the rim: a vehicle at a leg's end ({graph.perimeter:g} m round)",
    )
    axis.plot([0.0], [0.0], "o", markersize=11, markerfacecolor="white", markeredgecolor="black", zorder=6)
    centre = axis.annotate(
        "both at O:\nnever allowed",
        (0.0, 0.0),
        xytext=(0, -14),
        textcoords="offset points",
        ha="center",
        va="top",
        fontsize=8,
        zorder=6,
        bbox=_TEXT_BOX,
    )
    return [*labels, centre]


def _draw_paths(
    axis, lines: list[np.ndarray], *, colour: str, width: float, label: str, style: str = "-"
) -> None:
    for k, line in enumerate(lines):
        axis.plot(
            *line.T, color=colour, linewidth=width, linestyle=style, zorder=5, label=label if k == 0 else None
        )
        if k:  # the same configuration, drawn in the base and in a folded-out triangle
            axis.plot(
                *np.array([lines[k - 1][-1], line[0]]).T, color=colour, linewidth=0.8, linestyle=":", zorder=5
            )


def _draw_retraction(
    axis, layout: ConfigurationLayout, configurations: list, regions: list, label: str
) -> None:
    """Traces of the retraction from some configurations of the motion, and the motion retracted."""
    picks = np.unique(np.linspace(0, len(configurations) - 1, _TRACES + 2).round().astype(int))
    first = True
    for index in picks:
        c = configurations[int(index)]
        trace = layout.retraction(c, regions[int(index)])
        if len(trace) < 2:
            continue
        axis.plot(*trace.T, color="0.35", linewidth=0.8, zorder=4, label=_TRACES_LABEL if first else None)
        axis.annotate(
            "",
            xy=trace[-1],
            xytext=trace[-2],
            arrowprops={"arrowstyle": "->", "color": "0.35", "linewidth": 0.8},
            zorder=4,
        )
        first = False
    images = np.array([layout.boundary_image(c) for c in configurations]) * _OUTSET
    axis.plot(
        *images.T,
        color=_RETRACTION_COLOUR,
        linewidth=4,
        alpha=0.75,
        solid_capstyle="round",
        zorder=4,
        label=label,
    )
    if len(images) > 1 and np.hypot(*(images[-1] - images[-2])) > 0.0:
        axis.annotate(
            "",
            xy=images[-1],
            xytext=images[-2],
            arrowprops={"arrowstyle": "-|>", "color": _RETRACTION_COLOUR, "mutation_scale": 18},
            zorder=4,
        )


def plot_configuration(
    subject: Route | VerifiedSchedule, *, names: tuple[str, str] | None = None, figure=None
):
    """Where the two vehicles can be at once, drawn flat, with the route, the motion and the rim.

    Four or more legs: the places where the vehicles wait, with the route between them, instead
    (:func:`trajgen.plots.star_configuration.plot_retract_graph`): the space has no flat drawing.

    Each point of the drawing is a pair (where vehicle 1 is, where vehicle 2 is): the paper's
    configuration space (docs/planner.md, 'Reading configuration.png', names its parts). Drawn, in
    plain words: six areas, each vehicle on another leg (folded out beside them: six small
    triangles, both on one leg), round the centre where both would be at the junction; the too-close
    parts; the dashed lines where one vehicle is at the junction; the rim, where a vehicle is at
    the end of a leg, its corners named as pairs of places (``(A, B)``: vehicle 1 at the end of
    ``A``, vehicle 2 at the end of ``B``; ``O`` is the junction); the route (the planner's
    waypoints), for a schedule also its path, the start (hollow) and goal (solid); grey arrows from
    some points of the motion (the schedule's path, else the route) moved out to the rim, and the
    whole motion moved out to the rim (drawn just outside it, with its direction): which way round
    the centre the route goes. The title and the legend say what each means for the vehicles; no
    two of the words overlap.

    Parameters
    ----------
    subject : Route or VerifiedSchedule
        A route from :func:`topology.plan`, or a schedule from :func:`trajgen.certify`
        (its route and its path are drawn).
    names : pair of str, optional
        The vehicles' names, used throughout (default: "vehicle 1", "vehicle 2").
    figure : matplotlib Figure or SubFigure, optional
        Where to draw (default: a new Figure of 8.6 x 9.6 inches).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    UnverifiedScheduleError
        ``subject`` is a schedule that has not been certified.
    InputError
        ``subject`` is neither a Route nor a VerifiedSchedule, or ``names`` is not two strings.
    """
    route, verified = configuration_subject(subject, names)
    required = route.min_separation
    if verified is not None:
        required = max(verified.schedule.limits.min_separation, required)
    graph = route.graph
    if graph.cycle is None:  # four or more legs: no flat drawing, the retract graph G_k instead
        return plot_retract_graph(subject, names=names, figure=figure)
    layout = ConfigurationLayout.of(graph, min_separation=required)
    who = ("vehicle 1", "vehicle 2") if names is None else (names[0], names[1])
    area = drawing_area(figure, figsize=(8.6, 9.6))
    axis = area.add_axes((0.02, 0.255, 0.96, 0.645))
    axis.set_aspect("equal")
    axis.set_axis_off()
    axis.set_xlim(-1.32, 1.32)
    axis.set_ylim(-1.22, 1.22)
    labels = _draw_space(axis, layout, who)
    route_configurations, route_regions = route_samples(route)
    _draw_paths(
        axis,
        layout.paths(route_configurations, route_regions),
        colour=_ROUTE_COLOUR,
        width=2.6,
        label=f"route (the planner's waypoints), {route.length:.4g} m of travel",
    )
    motion, motion_regions = route_configurations, route_regions
    if verified is not None:
        configurations, regions = schedule_samples(verified)
        _draw_paths(
            axis,
            layout.paths(configurations, regions),
            colour=_SCHEDULE_COLOUR,
            width=1.8,
            style="--",
            label=f"{verified.schedule.method.name} schedule's path ({verified.schedule.duration:.2f} s)",
        )
        motion, motion_regions = configurations, regions
    what = "schedule's path" if verified is not None else "route"
    way = route.way_round.value if route.arc_length else "not"
    _draw_retraction(
        axis,
        layout,
        motion,
        motion_regions,
        f"the {what} moved out to the rim: {abs(route.arc_length):.4g} m {way} round",
    )
    start, goal = route.indexed_waypoints[0], route.indexed_waypoints[-1]
    start_region = route.region_keys[0] if route.region_keys else None
    goal_region = route.region_keys[-1] if route.region_keys else None
    axis.plot(
        *layout.point(start, start_region),
        "o",
        markersize=11,
        markerfacecolor="white",
        markeredgecolor="black",
        markeredgewidth=2,
        zorder=7,
        label=f"start {route.start}",
    )
    axis.plot(
        *layout.point(goal, goal_region),
        "o",
        markersize=8,
        color="black",
        zorder=7,
        label=f"goal {route.goal}",
    )
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.01), ncols=2, fontsize=8.5, frameon=False)
    round_the_centre = (
        f"the route goes {route.way_round.value} round the centre"
        if route.way_round in (WayRound.CLOCKWISE, WayRound.COUNTERCLOCKWISE)
        else "the route does not go round the centre"
    )
    area.suptitle(
        f"Where {who[0]} and {who[1]} can be at the same time (drawn flat, not to scale)\n"
        f"each point is (position of {who[0]}, position of {who[1]}); hatched: closer than {required:g} m\n"
        f"{round_the_centre} (both at the junction O: never allowed)",
        fontsize=11,
        y=0.985,
    )
    untangle(labels, smallest=_SMALLEST_LABEL)  # long names: smaller words, none over another
    footnote = wrapped(_footnote(graph, who), width_in=_FOOTNOTE_IN, fontsize=8)
    area.text(0.05, 0.012, footnote, fontsize=8, va="bottom", family="sans-serif")
    return finished(area, laid_out=False)  # its axes are placed by hand


def _footnote(graph: YGraph, who: tuple[str, str]) -> str:
    """How to read the picture, in plain words (the paper's notation is in docs/planner.md)."""
    a, b = graph.names[0], graph.names[1]
    return (
        f"How to read it: a point in the area '{who[0]} on {a}, {who[1]} on {b}' has {who[0]} somewhere "
        f"on leg {a} and {who[1]} on leg {b}; the farther from the centre, the farther out along their legs. "
        f"A corner of the rim names both places: ({a}, {b}) is {who[0]} at the end of {a} and {who[1]} at "
        f"the end of {b}; (O, {b}) is {who[0]} at the junction O. The small triangles are both vehicles on "
        "one leg, folded out beside the corner where they meet the rest. Every point moves out to the rim "
        "without the vehicles coming closer, so a route is told by which way round the centre it goes. "
        f"Not to scale: once round the rim is {graph.perimeter:g} m of travel, and a swap of the vehicles "
        "is drawn opposite. The paper's names for these parts: docs/planner.md."
    )
