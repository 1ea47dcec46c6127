"""``coordination.png``: two vehicles' travel, the too-close region drawn exactly, per paths and pair."""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import numpy as np

from trajgen.errors import InputError
from trajgen.methods import METHODS
from trajgen.model.analysis import travelled
from trajgen.model.coordination import pair_diagrams, schedule_paths
from trajgen.model.summary import class_label
from trajgen.plots.figure import drawing_area, finished, polygon_patch, wrapped
from trajgen.plots.speed import plot_period, vehicle_colour
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["METHOD_COLOURS", "plot_coordination"]

#: Width of a panel, inches, and of what its title may take: its axes' width, about, so that a title
#: centred over them stays inside the figure.
_PANEL_IN = 5.2
_TITLE_IN = 4.1
_TITLE_POINTS = 9
_PALETTE = ("tab:blue", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
#: Curve colour of each registered method, in registry order.
METHOD_COLOURS = {name: _PALETTE[k % len(_PALETTE)] for k, name in enumerate(METHODS.names)}


def _too_close(schedule, required: float) -> list[tuple[tuple[int, int], list]]:
    """Per pair of vehicles, ``(leader, polygon)`` of every convex part of its too-close region.

    The conflicts of :class:`~trajgen.model.coordination.CoordinationDiagram` on every track (a
    junction's paths are on its track graph too), each part led by the vehicle (of the pair) the
    plan lets pass first. Two vehicles have their pair drawn whether or not they conflict; of more,
    the pairs that conflict (if none does, the pair that comes closest).
    """
    paths, times, _ = schedule_paths(schedule)
    drawn = []
    for pair, diagram in pair_diagrams(schedule, paths, required, times):
        parts = [
            (pair[conflict.leader], polygon)
            for conflict in diagram.conflicts
            for polygon in conflict.polygons
        ]
        if parts or len(paths) == 2:
            drawn.append((pair, parts))
    if drawn:
        return drawn
    state = schedule.sample(plot_period(schedule.duration))
    closest = np.argmin(np.min(schedule.pair_distances(state), axis=1))
    return [(tuple(itertools.combinations(range(len(paths)), 2))[int(closest)], [])]


def plot_coordination(verified: Mapping[str, VerifiedSchedule], *, figure=None):
    """The coordination diagram: two vehicles' travel, one panel per set of paths and pair of vehicles.

    Each panel holds the schedules that drive the same paths (the route's paths for ``exact`` and
    ``toppra``; ``optimal`` may take the other homotopy class or park shallower, so its paths, and
    therefore its axes and its too-close region, differ: the figure says so). The too-close region
    is drawn exactly, as the convex polygons of :class:`~trajgen.model.coordination.CoordinationDiagram`.
    A schedule's curve must stay out of the shaded region of its panel. With more than two vehicles,
    each set of paths has a panel per pair of vehicles that conflict.

    Parameters
    ----------
    verified : mapping of method name to VerifiedSchedule
        At least one: the schedules to compare (the pipeline's ``Outputs(compare=...)``).
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the panels (default: a new Figure, 5.2 inches wide per panel; each panel's
        title is broken into lines that fit over its axes).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(verified, Mapping) or not verified:
        raise InputError(
            "the coordination plot needs a mapping of method name to VerifiedSchedule, "
            f"got {type(verified).__name__}"
        )
    schedules = {name: require_verified(v, "plot_coordination").schedule for name, v in verified.items()}
    distances = {
        name: travelled(schedule, plot_period(schedule.duration))[1] for name, schedule in schedules.items()
    }
    groups: dict[tuple, list[str]] = {}
    for name, distance in distances.items():
        key = tuple(np.round(distance[:, -1], 6))  # same paths drive the same distances
        groups.setdefault(key, []).append(name)
    panels_of = [
        (names, pair, parts)
        for names in groups.values()
        for pair, parts in _too_close(
            schedules[names[0]],
            max(schedules[names[0]].limits.min_separation, schedules[names[0]].route.min_separation),
        )
    ]
    area = drawing_area(figure, figsize=(_PANEL_IN * len(panels_of), 5.4 if len(panels_of) > 1 else 5.0))
    panels = area.subplots(1, len(panels_of), squeeze=False)[0]
    for axis, (names, pair, parts) in zip(panels, panels_of, strict=True):
        reference = schedules[names[0]]
        required = max(reference.limits.min_separation, reference.route.min_separation)
        labelled: set[int] = set()
        for leader, polygon in parts:
            label = None if leader in labelled else f"too close: vehicle {leader + 1} passes first"
            labelled.add(leader)
            patch = polygon_patch(
                polygon, facecolor=vehicle_colour(leader), alpha=0.3, edgecolor="none", label=label
            )
            axis.add_patch(patch)
        for name in names:
            axis.plot(
                distances[name][pair[0]],
                distances[name][pair[1]],
                color=METHOD_COLOURS.get(name, "black"),
                linewidth=2.0,
                zorder=3,
                label=f"{name} ({schedules[name].duration:.1f} s)",
            )
        axis.margins(0.04)  # a curve along a path's end (one vehicle waits) stays clear of the frame
        axis.set_xlabel(f"vehicle {pair[0] + 1} travelled [m]")
        axis.set_ylabel(f"vehicle {pair[1] + 1} travelled [m]")
        title = f"paths of {', '.join(names)}: class {class_label(reference.route)}"
        axis.set_title(
            wrapped(
                f"{title}\n(shaded: closer than {required:g} m)", width_in=_TITLE_IN, fontsize=_TITLE_POINTS
            ),
            fontsize=_TITLE_POINTS,
        )
        axis.legend(loc="best", fontsize=7)
        axis.grid(True, alpha=0.3)
    if len(groups) > 1:
        area.suptitle(
            "one panel per pair of paths: the methods drive different paths (the other class, "
            "or parking less deep),\nso each panel has its own axes and its own too-close region",
            fontsize=9,
        )
    return finished(area, laid_out=figure is None)
