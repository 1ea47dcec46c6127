"""``configuration.png`` drawn: the configuration space of a Y laid flat, with a route and its retraction.

The picture is drawn on :class:`trajgen.plots.configuration_layout.ConfigurationLayout`
(where everything lies, computed apart from the drawing): the regions and the
boundary circle, the too-close parts, the route, a schedule's path, retraction
traces and the motion retracted onto the circle, rendered to PNG bytes. A
junction of four or more legs has no flat drawing: it is handed to
:func:`trajgen.plots.star_configuration.plot_retract_graph`.
"""

from __future__ import annotations

import numpy as np

from topology import JUNCTION_INDEX, RegionKey, Route, YGraph
from topology.indexed import IndexedConfiguration
from trajgen.model.summary import class_label
from trajgen.plots.configuration_layout import ConfigurationLayout, rotate, route_samples, schedule_samples
from trajgen.plots.figure import drawing_area, finished
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


def _region_name(graph: YGraph, key: RegionKey) -> str:
    names = graph.names
    if key.nearer:
        return f"T({names[key.first_leg]},{key.nearer})"
    return f"Q({names[key.first_leg]},{names[key.second_leg]})"


def _vertex_name(graph: YGraph, c: IndexedConfiguration) -> str:
    names = graph.names
    if c[0] == JUNCTION_INDEX:
        return f"V1({names[c[2]]})"
    if c[2] == JUNCTION_INDEX:
        return f"V2({names[c[0]]})"
    return f"P({names[c[0]]},{names[c[2]]})"


def _draw_space(axis, layout: ConfigurationLayout) -> None:
    """The regions, the too-close parts, the rays, the boundary circle and the labels."""
    graph = layout.graph
    for key in layout.regions:
        polygon = layout.region_polygon(key)
        colour = _TRIANGLE_COLOUR if key.nearer else _QUADRANGLE_COLOUR
        axis.fill(*polygon.T, facecolor=colour, edgecolor="0.55", linewidth=0.8, zorder=1)
        centre = polygon.mean(axis=0) if key.nearer else 0.55 * layout.peak(key.first_leg, key.second_leg)
        axis.text(
            *centre, _region_name(graph, key), ha="center", va="center", fontsize=9, color="0.25", zorder=2
        )
    for k, polygon in enumerate(layout.too_close_polygons()):
        axis.fill(
            *polygon.T,
            facecolor="tab:red",
            alpha=0.3,
            edgecolor="none",
            hatch="////",
            zorder=2,
            label=f"too close (< {layout.min_separation:g} m along the track)" if k == 0 else None,
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
                label="rays (one vehicle at O)" if k == 1 else None,
            )
            place = vertex + 0.17 * rotate(vertex / np.hypot(*vertex), -0.6)
        else:
            place = 1.1 * vertex
        axis.text(*place, _vertex_name(graph, c), ha="center", va="center", fontsize=8, zorder=3)
    star = np.vstack([layout.vertices, layout.vertices[:1]])
    axis.plot(
        *star.T,
        color="black",
        linewidth=2.0,
        zorder=3,
        label=f"boundary circle (12-cycle, {graph.perimeter:g} m round)",
    )
    axis.plot([0.0], [0.0], "o", markersize=11, markerfacecolor="white", markeredgecolor="black", zorder=6)
    axis.annotate(
        "deleted point\n(both at O)",
        (0.0, 0.0),
        xytext=(0, -14),
        textcoords="offset points",
        ha="center",
        va="top",
        fontsize=8,
        zorder=6,
    )


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
        axis.plot(
            *trace.T, color="0.35", linewidth=0.8, zorder=4, label="retraction traces" if first else None
        )
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
    """The configuration space drawn flat with the route, the motion and its retraction.

    Four or more legs: the retract graph ``G_k`` with the route on it instead
    (:func:`trajgen.plots.star_configuration.plot_retract_graph`): the space has no flat drawing.

    Drawn: the six quadrangles and six triangles (folded out beside their valleys, see
    :class:`~trajgen.plots.configuration_layout.ConfigurationLayout`) round the deleted point, the
    too-close parts, the rays, the boundary circle with its peaks and valleys named, the route (the planner's
    waypoints), for a schedule also its path, the start (hollow) and goal (solid),
    retraction traces from the motion (the schedule's path, else the route) and the motion
    retracted onto the boundary circle (drawn just outside it, with its direction).

    Parameters
    ----------
    subject : Route or VerifiedSchedule
        A route from :func:`topology.plan`, or a schedule from :func:`trajgen.certify`
        (its route and its path are drawn).
    names : pair of str, optional
        The vehicles' names, for the title (default: "vehicle 1", "vehicle 2").
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
    who = "vehicle 1 and vehicle 2" if names is None else f"{names[0]} (vehicle 1) and {names[1]} (vehicle 2)"
    area = drawing_area(figure, figsize=(8.6, 9.6))
    axis = area.add_axes((0.02, 0.265, 0.96, 0.655))
    axis.set_aspect("equal")
    axis.set_axis_off()
    axis.set_xlim(-1.32, 1.32)
    axis.set_ylim(-1.22, 1.22)
    _draw_space(axis, layout)
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
        f"the {what} retracted onto the circle: {abs(route.arc_length):.4g} m {way} round",
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
    regions = " ".join(_region_name(graph, key) for key in route.region_keys) or "(one ray)"
    axis.set_title(
        f"Configuration space of {who}, drawn flat\nroute: {class_label(route)}; regions {regions}",
        fontsize=11,
    )
    area.text(
        0.05,
        0.015,
        "\n".join(
            (
                "Q(i,j): vehicle 1 on leg i, vehicle 2 on leg j (a quadrangle).  T(k,r): both on leg k,",
                "vehicle r nearer O (a triangle, glued to the base along its ray; drawn folded out beside",
                "that ray's valley, the ray drawn again outwards from the valley).  P(i,j): vehicle 1 at the",
                "end of leg i, vehicle 2 at the end of leg j; V1(j): vehicle 1 at O, vehicle 2 at the end of",
                "j; V2(i): vehicle 2 at O, vehicle 1 at the end of i.  Not to scale: the angle round the",
                "deleted point is proportional to arc length on the boundary circle (a swap of the vehicles",
                "is drawn opposite); a point of a quadrangle lies on the line from the deleted point to its",
                "retraction, max(s1/L_i, s2/L_j) of the way.",
            )
        ),
        fontsize=8,
        va="bottom",
        family="sans-serif",
    )
    return finished(area, laid_out=False)  # its axes are placed by hand
