"""``speed.png``: velocity, acceleration and jerk of both vehicles over time, with their limits.

A schedule that does not limit jerk (``toppra``) has steps in its acceleration, where its jerk is
unbounded: its third panel marks each step, with its size, instead of a jerk curve.
"""

from __future__ import annotations

import numpy as np

from trajgen.model.pieces import kinematics_polynomials
from trajgen.model.summary import both_or_all, class_label
from trajgen.plots.figure import checked_names, drawing_area, finished
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "MAX_PLOT_POINTS",
    "PLOT_PERIOD",
    "STEPS_LABEL",
    "STEP_SHARE",
    "VEHICLE_COLOURS",
    "acceleration_steps",
    "plot_period",
    "plot_speed",
    "vehicle_colour",
]

#: Sample period of the plotted curves, seconds (longer for long schedules: see :func:`plot_period`).
PLOT_PERIOD = 0.01
#: Most samples a curve is drawn from, whatever the duration.
MAX_PLOT_POINTS = 20_000


def plot_period(duration: float) -> float:
    """The sample period of the curves of a ``duration``-second schedule: 10 ms, or coarser past 200 s."""
    return max(PLOT_PERIOD, duration / MAX_PLOT_POINTS)


#: Line colours of vehicle 1 and vehicle 2.
VEHICLE_COLOURS = ("tab:blue", "tab:orange")


def vehicle_colour(index: int) -> str:
    """The colour of vehicle ``index`` (0-based): :data:`VEHICLE_COLOURS`, then matplotlib's cycle."""
    return VEHICLE_COLOURS[index] if index < len(VEHICLE_COLOURS) else f"C{index % 10}"


#: A change of acceleration below this share of the vehicle's limit is round-off, not a step.
STEP_SHARE = 1e-6
#: How far either side of a piece boundary its step is read, seconds per second of schedule (at least 1 s).
_STEP_SIDE = 1e-9
#: What the jerk panel of a schedule that does not limit jerk shows, in its legend.
STEPS_LABEL = "acceleration steps (jerk not limited)"


def acceleration_steps(schedule) -> tuple[np.ndarray, np.ndarray]:
    """Where a schedule's acceleration jumps, and by how much: where its jerk is unbounded.

    At each boundary of its polynomial pieces (exact instants, not samples) the acceleration just
    after minus the one just before, along each vehicle's axis as :meth:`state` gives it (so the
    steps are those of the acceleration plotted); at the start and the goal, the step from and to
    rest (a vehicle stands with ``a = 0`` before and after). A jump below :data:`STEP_SHARE` of the
    vehicle's acceleration limit is round-off.

    Parameters
    ----------
    schedule : Schedule or GraphSchedule
        Its sections' kinematics piecewise cubic or TOPPRA's (as every verified schedule's are).

    Returns
    -------
    times : ndarray, shape (n,)
        Instants with a step of either vehicle, seconds, increasing.
    steps : ndarray, shape (2, n)
        Per vehicle, the change of its acceleration there (0 where it does not jump), m/s².
    """
    duration = schedule.duration
    breaks = np.sort(
        np.concatenate(
            [[0.0, duration]]
            + [
                section.start_time + kinematics_polynomials(section.kinematics)[0]
                for section in schedule.sections
            ]
        )
    )
    # either side of a boundary, this close: a piece's own jerk changes a by nothing that shows
    near = _STEP_SIDE * max(1.0, duration)
    inner = breaks[(breaks > 2.0 * near) & (breaks < duration - 2.0 * near)]
    inner = inner[np.concatenate([[True], np.diff(inner) > 2.0 * near])] if inner.size else inner
    # just after the start and just before the goal (the goal itself is at rest)
    ends = schedule.state(np.array([near, duration - near])).acceleration
    jumps = schedule.state(inner + near).acceleration - schedule.state(inner - near).acceleration
    times = np.concatenate([[0.0], inner, [duration]])
    steps = np.concatenate([ends[:, :1], jumps, -ends[:, 1:]], axis=1)
    limits = np.array([vehicle.max_acceleration for vehicle in schedule.limits.vehicles])[:, None]
    real = np.abs(steps) > STEP_SHARE * limits
    shown = real.any(axis=0)
    return times[shown], np.where(real, steps, 0.0)[:, shown]


def _draw_steps(axis, schedule, names: tuple[str, ...]) -> None:
    """The jerk panel of a schedule that does not limit jerk: a stem at each step of ``a``, as long as it."""
    times, steps = acceleration_steps(schedule)
    axis.axhline(0.0, color="0.5", linewidth=0.8)
    for vehicle in range(len(names)):
        at = steps[vehicle] != 0.0
        colour = vehicle_colour(vehicle)
        axis.vlines(times[at], 0.0, steps[vehicle, at], color=colour, linewidth=1.2)
        axis.plot(
            times[at],
            steps[vehicle, at],
            "o",
            linestyle="none",
            markersize=3.5,
            color=colour,
            label=f"{names[vehicle]}: {STEPS_LABEL}",
        )
    axis.set_ylabel("step in a [m/s²]")
    axis.set_title(
        "jerk not limited by this method: unbounded at each step of a (a stem, as long as the step)",
        fontsize=9,
    )


def plot_speed(verified: VerifiedSchedule, *, names=None, figure=None):
    """``v``, ``a``, ``j`` over time for every vehicle with their limit lines, one axis each.

    Each is along the vehicle's own axis, which grows in the direction of its first move: a
    negative ``v`` is a vehicle moving against it, backing out of a side leg it entered to make
    room (the figure says so).

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of str, optional
        Legend labels, one per vehicle (default ``vehicle 1``, ...).
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the three axes (default: a new Figure of 10.5 x 7.5 inches).

    Returns
    -------
    matplotlib.figure.Figure
    """
    schedule = require_verified(verified, "plot_speed").schedule
    count = schedule.limits.count
    names = checked_names(names, count, what="plot_speed")
    state = schedule.sample(plot_period(schedule.duration))
    area = drawing_area(figure, figsize=(10.5, 7.5))
    axes = area.subplots(3, 1, sharex=True)
    rows = [
        (state.velocity, "max_velocity", "v [m/s]", "m/s"),
        (state.acceleration, "max_acceleration", "a [m/s²]", "m/s²"),
        (state.jerk, "max_jerk", "j [m/s³]", "m/s³"),
    ]
    for axis, (values, limit_name, label, unit) in zip(axes, rows, strict=True):
        if limit_name == "max_jerk" and not schedule.jerk_limited:
            _draw_steps(axis, schedule, names)
        else:
            for vehicle in range(count):
                axis.plot(state.t, values[vehicle], color=vehicle_colour(vehicle), label=names[vehicle])
            limits = [getattr(schedule.limits.vehicles[vehicle], limit_name) for vehicle in range(count)]
            shared = len(set(limits)) == 1  # one black line for all, else one per vehicle in its colour
            for vehicle in (0,) if shared else range(count):
                whose = both_or_all(count) if shared else names[vehicle]
                for sign in (1, -1):
                    axis.axhline(
                        sign * limits[vehicle],
                        color="black" if shared else vehicle_colour(vehicle),
                        linestyle="--",
                        linewidth=0.9,
                        label=f"limit ±{limits[vehicle]:g} {unit} ({whose})" if sign == 1 else None,
                    )
            axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    axes[0].set_title(
        f"{schedule.method.name} schedule, {schedule.duration:.2f} s, class {class_label(schedule.route)}"
        "\n(dashed: the limits; along each vehicle's axis, which grows in its first move: "
        "v < 0 is backing out of a side leg)",
        fontsize=10,
    )
    axes[-1].set_xlabel("t [s]")
    return finished(area, laid_out=figure is None)
