"""``simulation.png``: a closed-loop run under faults against its plan: speeds and separation over time."""

from __future__ import annotations

import math

import numpy as np

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.plots.figure import drawing_area, finished, polygon_patch, time_label
from trajgen.plots.speed import VEHICLE_COLOURS

__all__ = ["plot_simulation"]

#: Colour of the fault marks (lines and spans).
FAULT_COLOUR = "tab:gray"


def _mark_faults(axis, marks: list[tuple[float, float | None, str]]) -> None:
    """Each fault ``(time s, duration s or None, spec)``: a shaded span or a dotted line, labelled."""
    for time, duration, spec in marks:
        if duration is not None:
            axis.axvspan(time, time + duration, color=FAULT_COLOUR, alpha=0.2, linewidth=0)
        else:
            axis.axvline(time, color=FAULT_COLOUR, linestyle=":", linewidth=1.2)
        time_label(axis, time, 0.98, spec, colour="dimgray")


def _progress(axis, result, names) -> None:
    """Each vehicle's travel along its path over time, and its frontier (dashed) where one binds it."""
    t = np.asarray(result.plot["t"])
    for vehicle in range(2):
        colour = VEHICLE_COLOURS[vehicle]
        travel = result.plot["travel"][vehicle]
        frontier = np.where(
            np.isfinite(result.plot["frontier"][vehicle]), result.plot["frontier"][vehicle], np.nan
        )
        axis.plot(t, travel, color=colour, label=f"{names[vehicle]} travel")
        axis.plot(t, frontier, color=colour, linestyle=":", linewidth=1.4, label=f"{names[vehicle]} frontier")
        waiting = np.isfinite(frontier) & (frontier - travel < 0.02)
        axis.scatter(t[waiting], travel[waiting], s=6, color=colour, marker="|", alpha=0.6)
    axis.set_ylabel("travel along its path [m]")
    axis.set_title(
        "progress and frontiers (dotted: the farthest a vehicle may come to rest; | it waits there)",
        fontsize=9,
    )
    axis.legend(loc="upper left", fontsize=7)


def _coordination(axis, result, names, min_separation: float) -> None:
    """The plan's conflicts in the plane of both vehicles' travel, the plan's curve and the executed one."""
    from trajgen.model.coordination import CoordinationDiagram, schedule_paths

    schedule = result.schedule.schedule
    paths, times, travel = schedule_paths(schedule)
    diagram = CoordinationDiagram(paths, min_separation + result.position_margin, schedule, times)
    for conflict in diagram.conflicts:
        colour = VEHICLE_COLOURS[conflict.leader]
        for polygon in conflict.polygons:
            axis.add_patch(polygon_patch(polygon, facecolor=colour, alpha=0.25, edgecolor="none"))
    axis.plot(travel[0], travel[1], color="black", linestyle="--", linewidth=0.9, label="plan")
    replanned = [event.time for event in result.events if event.kind == "replan"]
    t = np.asarray(result.plot["t"])
    before = t < (replanned[0] if replanned else math.inf)  # travel is along the plan's paths until then
    executed = result.plot["travel"][:, before]
    axis.plot(executed[0], executed[1], color="tab:purple", linewidth=1.3, label="executed")
    for vehicle in range(2):
        limit = np.where(
            np.isfinite(result.plot["frontier"][vehicle][before]),
            result.plot["frontier"][vehicle][before],
            np.nan,
        )
        if np.isfinite(limit).any():
            last = int(np.nonzero(np.isfinite(limit))[0][-1])
            point = (limit[last], executed[1, last]) if vehicle == 0 else (executed[0, last], limit[last])
            axis.plot(
                *point, marker=">" if vehicle == 0 else "^", color=VEHICLE_COLOURS[vehicle], markersize=7
            )
    for limits, length in ((axis.set_xlim, paths[0].length), (axis.set_ylim, paths[1].length)):
        pad = 0.02 * max(length, 1e-6)  # a plan that waits runs along the frame: keep it visible
        limits(-pad, length + pad)
    axis.set_xlabel(f"{names[0]} travel [m]")
    axis.set_ylabel(f"{names[1]} travel [m]")
    axis.set_title(
        "coordination diagram: conflicts shaded in the colour of the vehicle that passes first\n"
        "(the other waits at its frontier; arrows: each vehicle's last frontier)",
        fontsize=9,
    )
    axis.legend(loc="lower right", fontsize=7)


def plot_simulation(result, *, names: tuple[str, str], min_separation: float, figure=None):
    """A simulated run: speeds, separation, progress with frontiers, coordination diagram.

    Left: each vehicle's velocity along its axis, m/s, planned (the undisturbed schedule, dashed)
    and executed (the plant's true motion); below, the true track distance, m, with the minimum
    separation. Right: each vehicle's travel along its path with its frontier (where the executor
    lets it come to rest at the latest, so a user sees why a vehicle waits), and the coordination
    diagram: the plan's conflicts (shaded in the colour of the vehicle that passes first), the
    plan's curve and the executed one. Every fault is marked on the time axes, labelled with its
    spec: a ``stop`` or a ``slow`` for a while as a shaded span, the others as a dotted line.

    Parameters
    ----------
    result : SimulationResult
        From :func:`trajgen.execution.simulation.simulate`.
    names : pair of str
        Legend labels of the vehicles.
    min_separation : float
        The separation the run had to keep, metres (the scenario's, not the plan's wider one).
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the four axes (default: a new Figure of 15 x 8.5 inches).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        ``result`` is not a SimulationResult, or ``min_separation`` is not a finite number >= 0.
    """
    # imported here: importing the plots must not load the online executor (and Ruckig)
    from trajgen.execution.simulation import SimulationResult

    if not isinstance(result, SimulationResult):
        raise InputError(f"plot_simulation expects a SimulationResult, got {type(result).__name__}")
    if (
        isinstance(min_separation, bool)
        or not isinstance(min_separation, (int, float))
        or not math.isfinite(min_separation)
        or min_separation < 0.0
    ):
        raise InputError(f"min_separation (m) must be a finite number >= 0, got {short_repr(min_separation)}")
    t = np.asarray(result.plot["t"])
    planned = result.schedule.schedule.state(t).velocity
    area = drawing_area(figure, figsize=(15, 8.5))
    grid = area.add_gridspec(2, 2, width_ratios=(1.25, 1.0))
    speed_axis = area.add_subplot(grid[0, 0])
    separation_axis = area.add_subplot(grid[1, 0], sharex=speed_axis)
    progress_axis = area.add_subplot(grid[0, 1], sharex=speed_axis)
    coordination_axis = area.add_subplot(grid[1, 1])
    for vehicle in range(2):
        colour = VEHICLE_COLOURS[vehicle]
        speed_axis.plot(
            t,
            planned[vehicle],
            color=colour,
            linestyle="--",
            linewidth=0.9,
            label=f"{names[vehicle]} planned",
        )
        speed_axis.plot(t, result.plot["speed"][vehicle], color=colour, label=f"{names[vehicle]} executed")
    speed_axis.set_ylabel("v [m/s]")
    speed_axis.legend(loc="upper left", fontsize=7)
    separation_axis.plot(t, result.plot["separation"], color="tab:green", label="true track distance")
    separation_axis.axhline(
        min_separation, color="tab:red", linestyle="--", label=f"minimum {min_separation:g} m"
    )
    separation_axis.fill_between(t, 0, min_separation, color="tab:red", alpha=0.1)
    separation_axis.set_ylim(bottom=0)
    separation_axis.set_ylabel("separation [m]")
    separation_axis.set_xlabel("t [s]")
    separation_axis.legend(loc="upper left", fontsize=7)
    _progress(progress_axis, result, names)
    _coordination(coordination_axis, result, names, min_separation)
    marks = [
        (f.time, f.end - f.time if math.isfinite(f.end) and f.end > f.time else None, f.spec)
        for f in result.faults
    ]
    for axis in (speed_axis, separation_axis, progress_axis):
        _mark_faults(axis, marks)
        axis.grid(True, alpha=0.3)
    coordination_axis.grid(True, alpha=0.3)
    outcome = "reached the goal" if result.reached_goal else "did NOT reach the goal"
    speed_axis.set_title(
        f"simulation: {outcome} at {result.makespan_s:.2f} s (planned {result.planned_s:.2f} s), "
        f"{result.violations} violations\n(dashed: the undisturbed plan; grey: faults)",
        fontsize=10,
    )
    return finished(area, laid_out=figure is None)
