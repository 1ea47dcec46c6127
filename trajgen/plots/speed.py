"""``speed.png``: velocity, acceleration and jerk of both vehicles over time, with their limits."""

from __future__ import annotations

from trajgen.model.summary import class_label
from trajgen.plots.figure import drawing_area, finished
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["MAX_PLOT_POINTS", "PLOT_PERIOD", "VEHICLE_COLOURS", "plot_period", "plot_speed"]

#: Sample period of the plotted curves, seconds (longer for long schedules: see :func:`plot_period`).
PLOT_PERIOD = 0.01
#: Most samples a curve is drawn from, whatever the duration.
MAX_PLOT_POINTS = 20_000


def plot_period(duration: float) -> float:
    """The sample period of the curves of a ``duration``-second schedule: 10 ms, or coarser past 200 s."""
    return max(PLOT_PERIOD, duration / MAX_PLOT_POINTS)


#: Line colours of vehicle 1 and vehicle 2.
VEHICLE_COLOURS = ("tab:blue", "tab:orange")


def plot_speed(
    verified: VerifiedSchedule, *, names: tuple[str, str] = ("vehicle 1", "vehicle 2"), figure=None
):
    """``v``, ``a``, ``j`` over time for both vehicles with their limit lines, one axis each.

    Each is along the vehicle's own axis, which grows in the direction of its first move: a
    negative ``v`` is a vehicle moving against it, backing out of a side leg it entered to make
    room (the figure says so).

    Parameters
    ----------
    verified : VerifiedSchedule
    names : pair of str
        Legend labels.
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the three axes (default: a new Figure of 10.5 x 7.5 inches).

    Returns
    -------
    matplotlib.figure.Figure
    """
    schedule = require_verified(verified, "plot_speed").schedule
    state = schedule.sample(plot_period(schedule.duration))
    area = drawing_area(figure, figsize=(10.5, 7.5))
    axes = area.subplots(3, 1, sharex=True)
    rows = [
        (state.velocity, "max_velocity", "v [m/s]", "m/s"),
        (state.acceleration, "max_acceleration", "a [m/s²]", "m/s²"),
        (state.jerk, "max_jerk", "j [m/s³]", "m/s³"),
    ]
    for axis, (values, limit_name, label, unit) in zip(axes, rows, strict=True):
        for vehicle in range(2):
            axis.plot(state.t, values[vehicle], color=VEHICLE_COLOURS[vehicle], label=names[vehicle])
        limits = [getattr(schedule.limits.vehicles[vehicle], limit_name) for vehicle in range(2)]
        if limit_name != "max_jerk" or schedule.jerk_limited:
            shared = limits[0] == limits[1]  # one black line for both, else one per vehicle in its colour
            for vehicle in (0,) if shared else (0, 1):
                whose = "both" if shared else names[vehicle]
                for sign in (1, -1):
                    axis.axhline(
                        sign * limits[vehicle],
                        color="black" if shared else VEHICLE_COLOURS[vehicle],
                        linestyle="--",
                        linewidth=0.9,
                        label=f"limit ±{limits[vehicle]:g} {unit} ({whose})" if sign == 1 else None,
                    )
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    if not schedule.jerk_limited:
        axes[2].set_title("jerk not limited by this method (steps in a)", fontsize=9)
    axes[0].set_title(
        f"{schedule.method.name} schedule, {schedule.duration:.2f} s, class {class_label(schedule.route)}"
        "\n(dashed: the limits; along each vehicle's axis, which grows in its first move: "
        "v < 0 is backing out of a side leg)",
        fontsize=10,
    )
    axes[-1].set_xlabel("t [s]")
    return finished(area, laid_out=figure is None)
