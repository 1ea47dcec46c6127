"""``simulation.png``: a closed-loop run under faults against its plan: speeds and separation over time."""

from __future__ import annotations

import math

import numpy as np

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.plots.figure import clip_to_data_box, drawing_area, finished, numbered_handle, polygon_patch
from trajgen.plots.speed import vehicle_colour

__all__ = ["plot_simulation"]

#: Colour of the fault marks (lines and spans).
FAULT_COLOUR = "tab:gray"


#: Colour of the re-plan marks.
REPLAN_COLOUR = "black"


def _marks(result) -> list[tuple[float, float | None, str, str]]:
    """Every fault and re-plan, in time order: ``(time s, duration s or None, text, colour)``."""
    marks = [
        (f.time, f.end - f.time if math.isfinite(f.end) and f.end > f.time else None, f.spec, FAULT_COLOUR)
        for f in result.faults
    ]
    marks += [(plan.started_s, None, "re-plan for the new goal", REPLAN_COLOUR) for plan in result.plans[1:]]
    return sorted(marks, key=lambda mark: mark[0])


#: Marks nearer than this share of the time axis are numbered one above the other.
MARK_SPACING = 0.025
#: Height of a row of mark numbers, points.
MARK_ROW = 8.0


def _mark_rows(marks, span: float) -> list[int]:
    """The row of each mark's number: the lowest whose last number is far enough along the time axis."""
    last: list[float] = []  # the time of each row's last number
    rows = []
    for time, *_ in marks:
        row = next((k for k, before in enumerate(last) if time - before >= MARK_SPACING * span), len(last))
        if row == len(last):
            last.append(time)
        last[row] = time
        rows.append(row)
    return rows


def _mark_times(axis, marks, rows: list[int]) -> None:
    """Each mark as a shaded span or a dotted line, numbered just above the panel (outside its data)."""
    for number, ((time, duration, _, colour), row) in enumerate(zip(marks, rows, strict=True), start=1):
        if duration is not None:
            axis.axvspan(time, time + duration, color=colour, alpha=0.2, linewidth=0)
        else:
            axis.axvline(time, color=colour, linestyle=":", linewidth=1.2)
        axis.annotate(
            str(number),
            (time, 1.0),
            xycoords=axis.get_xaxis_transform(),
            xytext=(0, 1.5 + MARK_ROW * row),  # just above the frame: over no data
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize=7,
            color="dimgray" if colour == FAULT_COLOUR else colour,
            annotation_clip=False,
        )


def _mark_key(marks) -> list:
    """Legend entries naming each numbered mark: its number, then its fault spec or what it is."""
    return [
        numbered_handle(number, colour="dimgray" if colour == FAULT_COLOUR else colour, label=text)
        for number, (_, _, text, colour) in enumerate(marks, start=1)
    ]


def _progress(axis, result, names, *, pad: float) -> None:
    """Each vehicle's travel along its path over time, and its frontier (dashed) where one binds it."""
    t = np.asarray(result.plot["t"])
    for vehicle in range(len(result.plot["travel"])):
        colour = vehicle_colour(vehicle)
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
        pad=pad,
    )
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)


def _shown_pair(result, required: float) -> tuple[int, int]:
    """The pair of vehicles the coordination panel draws.

    Of two vehicles, both; of more, the pair with the most conflicts in the first plan (the first
    such pair in the order of ``itertools.combinations``).
    """
    from trajgen.model.coordination import pair_diagrams, schedule_paths

    if len(result.plot["travel"]) == 2:
        return (0, 1)
    schedule = result.plans[0].schedule
    paths, times, _ = schedule_paths(schedule)
    diagrams = pair_diagrams(schedule, paths, required, times)
    most = max(len(diagram.conflicts) for _, diagram in diagrams)
    return next(pair for pair, diagram in diagrams if len(diagram.conflicts) == most)


def _coordination(axis, result, names, min_separation: float) -> None:
    """Each plan's conflicts in the plane of two vehicles' travel, each plan's curve and the executed one.

    The pair of two vehicles, or of more the pair with the most conflicts (:func:`_shown_pair`).
    After a re-plan for a new goal the new plan's paths continue where the vehicles stood: its
    conflicts and curve are drawn from that point on, the old plan's up to it.
    """
    from trajgen.model.coordination import CoordinationDiagram, SchedulePair, schedule_paths

    required = min_separation + result.position_margin
    i, j = pair = _shown_pair(result, required)
    plans = result.plans
    ends = [(plan.travel_before[i], plan.travel_before[j]) for plan in plans[1:]]
    corner = (0.0, 0.0)
    for k, plan in enumerate(plans):
        paths, times, travel = schedule_paths(plan.schedule)
        paths, travel = (paths[i], paths[j]), travel[[i, j]]
        origin = (plan.travel_before[i], plan.travel_before[j])
        far = ends[k] if k < len(ends) else (origin[0] + paths[0].length, origin[1] + paths[1].length)
        corner = (max(corner[0], far[0]), max(corner[1], far[1]))
        # what the run drove of this plan: from where it took it up to where it left it
        diagram = CoordinationDiagram(paths, required, SchedulePair(plan.schedule, pair), times)
        for conflict in diagram.conflicts:
            colour = vehicle_colour(pair[conflict.leader])
            for polygon in conflict.polygons:
                patch = polygon_patch(
                    np.asarray(polygon) + np.asarray(origin), facecolor=colour, alpha=0.25, edgecolor="none"
                )
                axis.add_patch(patch)
                clip_to_data_box(patch, axis, origin, far)
        (curve,) = axis.plot(
            origin[0] + travel[0],
            origin[1] + travel[1],
            color="black",
            linestyle="--",
            linewidth=0.9,
            label="plan" if k == 0 else None,
        )
        clip_to_data_box(curve, axis, origin, far)
        if k > 0:
            axis.plot(*origin, marker="o", color="black", markersize=5, fillstyle="none")
            axis.annotate(
                "re-plan", origin, xytext=(4, -10), textcoords="offset points", fontsize=7, color="black"
            )
    executed = result.plot["travel"][[i, j]]
    axis.plot(executed[0], executed[1], color="tab:purple", linewidth=1.3, label="executed")
    for side, vehicle in enumerate(pair):
        limit = np.where(
            np.isfinite(result.plot["frontier"][vehicle]), result.plot["frontier"][vehicle], np.nan
        )
        if np.isfinite(limit).any():
            last = int(np.nonzero(np.isfinite(limit))[0][-1])
            point = (limit[last], executed[1, last]) if side == 0 else (executed[0, last], limit[last])
            axis.plot(*point, marker=">" if side == 0 else "^", color=vehicle_colour(vehicle), markersize=7)
    for set_limits, length in ((axis.set_xlim, corner[0]), (axis.set_ylim, corner[1])):
        pad = 0.02 * max(length, 1e-6)  # a plan that waits runs along the frame: keep it visible
        set_limits(-pad, length + pad)
    axis.set_xlabel(f"{names[i]} travel [m]")
    axis.set_ylabel(f"{names[j]} travel [m]")
    axis.set_title(
        "coordination diagram: conflicts shaded in the colour of the vehicle that passes first\n"
        "(the other waits at its frontier; arrows: each vehicle's last frontier)",
        fontsize=9,
    )
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)


def _planned_velocity(result, t: np.ndarray) -> np.ndarray:
    """Each vehicle's planned velocity at ``t``, m/s, shape (V, n): each plan from when the run took it up."""
    planned = np.full((len(result.plot["speed"]), t.size), np.nan)
    for plan in result.plans:
        inside = (t >= plan.started_s) & (t <= plan.ended_s)
        if not inside.any():
            continue
        local = np.clip(t[inside] - plan.started_s, 0.0, plan.schedule.duration)
        velocity = plan.schedule.state(local).velocity
        for v, sign in enumerate(plan.axis_signs):
            planned[v, inside] = sign * velocity[v]
    return planned


def plot_simulation(result, *, names: tuple[str, ...], min_separation: float, figure=None):
    """A simulated run: speeds, separation, progress with frontiers, coordination diagram.

    Left: each vehicle's velocity along its axis, m/s, planned (each plan the run drove, from when
    it took it up, dashed) and executed (the plant's true motion); below, the true track distance,
    m, with the minimum separation. Right: each vehicle's travel along its paths with its frontier
    (where the executor lets it come to rest at the latest, so a user sees why a vehicle waits),
    and the coordination diagram: each plan's conflicts (shaded in the colour of the vehicle that
    passes first) and curve over the part the run drove of it, and the executed curve. Across a
    re-plan for a new goal the travel continues (the new plan's paths start where the vehicles
    stood). Every fault and re-plan is marked on the time axes (a ``stop`` or a ``slow`` for a
    while as a shaded span, the others as a dotted line) and numbered just above the panel; the
    speed panel's legend names each number. Legends stand beside the panels, over no data.

    Parameters
    ----------
    result : SimulationResult
        From :func:`trajgen.execution.simulation.simulate`.
    names : sequence of str
        Legend labels of the vehicles, one per vehicle.
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
    planned = _planned_velocity(result, t)
    area = drawing_area(figure, figsize=(15, 8.5))
    grid = area.add_gridspec(2, 2, width_ratios=(1.25, 1.0))
    speed_axis = area.add_subplot(grid[0, 0])
    separation_axis = area.add_subplot(grid[1, 0], sharex=speed_axis)
    progress_axis = area.add_subplot(grid[0, 1], sharex=speed_axis)
    coordination_axis = area.add_subplot(grid[1, 1])
    for vehicle in range(len(planned)):
        colour = vehicle_colour(vehicle)
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
    separation_axis.plot(t, result.plot["separation"], color="tab:green", label="true track distance")
    separation_axis.axhline(
        min_separation, color="tab:red", linestyle="--", label=f"minimum {min_separation:g} m"
    )
    separation_axis.fill_between(t, 0, min_separation, color="tab:red", alpha=0.1)
    separation_axis.set_ylim(bottom=0)
    separation_axis.set_ylabel("separation [m]")
    separation_axis.set_xlabel("t [s]")
    separation_axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    marks = _marks(result)
    rows = _mark_rows(marks, max(float(t[-1] - t[0]), 1e-9) if t.size else 1.0)
    above = MARK_ROW * max(rows, default=0)  # the titles stand above the rows of numbers
    _progress(progress_axis, result, names, pad=12 + above)
    _coordination(coordination_axis, result, names, min_separation)
    for axis in (speed_axis, separation_axis, progress_axis):
        _mark_times(axis, marks, rows)
        axis.grid(True, alpha=0.3)
    handles, _ = speed_axis.get_legend_handles_labels()
    speed_axis.legend(
        handles=handles + _mark_key(marks), loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7
    )
    coordination_axis.grid(True, alpha=0.3)
    outcome = "reached the goal" if result.reached_goal else "did NOT reach the goal"
    speed_axis.set_title(
        f"simulation: {outcome} at {result.makespan_s:.2f} s (planned {result.planned_s:.2f} s), "
        f"{result.violations} violations\n(dashed: the plans; grey: faults, numbered as in the legend)",
        fontsize=10,
        pad=12 + above,
    )
    return finished(area, laid_out=figure is None)
