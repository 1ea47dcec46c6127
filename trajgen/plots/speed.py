"""``speed.png``: velocity, acceleration and jerk of both vehicles over time, with their limits."""

from __future__ import annotations

from trajgen.plots.figure import new_figure, png_bytes
from trajgen.summary import class_label
from trajgen.verify import VerifiedSchedule, require_verified

__all__ = ["MAX_PLOT_POINTS", "PLOT_PERIOD", "VEHICLE_COLOURS", "plot_period", "render_speed"]

#: Sample period of the plotted curves, seconds (longer for long schedules: see :func:`plot_period`).
PLOT_PERIOD = 0.01
#: Most samples a curve is drawn from, whatever the duration.
MAX_PLOT_POINTS = 20_000


def plot_period(duration: float) -> float:
    """The sample period of the curves of a ``duration``-second schedule: 10 ms, or coarser past 200 s."""
    return max(PLOT_PERIOD, duration / MAX_PLOT_POINTS)


#: Line colours of vehicle 1 and vehicle 2.
VEHICLE_COLOURS = ("tab:blue", "tab:orange")


def render_speed(verified: VerifiedSchedule, *, names: tuple[str, str] = ("vehicle 1", "vehicle 2")) -> bytes:
    """``v``, ``a``, ``j`` over time for both vehicles with their limit lines, as PNG bytes.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : pair of str
        Legend labels.
    """
    schedule = require_verified(verified, "render_speed").schedule
    state = schedule.sample(plot_period(schedule.duration))
    figure = new_figure(figsize=(9, 7.5))
    axes = figure.subplots(3, 1, sharex=True)
    rows = [
        (state.velocity, "max_velocity", "v [m/s]"),
        (state.acceleration, "max_acceleration", "a [m/s²]"),
        (state.jerk, "max_jerk", "j [m/s³]"),
    ]
    for axis, (values, limit_name, label) in zip(axes, rows, strict=True):
        for vehicle in range(2):
            colour = VEHICLE_COLOURS[vehicle]
            axis.plot(state.t, values[vehicle], color=colour, label=names[vehicle])
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            if limit_name != "max_jerk" or schedule.jerk_limited:
                for sign in (1, -1):
                    axis.axhline(sign * limit, color=colour, linestyle="--", linewidth=0.8)
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
    if not schedule.jerk_limited:
        axes[2].set_title("jerk not limited by this method (steps in a)", fontsize=9)
    axes[0].legend(loc="upper right")
    axes[0].set_title(
        f"{schedule.method.name} schedule, {schedule.duration:.2f} s, class {class_label(schedule.route)}"
        "\n(dashed: limits)",
        fontsize=10,
    )
    axes[-1].set_xlabel("t [s]")
    figure.tight_layout()
    return png_bytes(figure)
