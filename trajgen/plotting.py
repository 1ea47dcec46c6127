"""Plots of verified schedules. The only module that imports matplotlib (lazily).

Every function verifies the schedule first and writes its PNG atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from trajgen.export import atomic_write_files
from trajgen.schedule import Schedule
from trajgen.verify import verified

__all__ = ["plot_separation", "plot_speed", "write_plots"]

_PLOT_PERIOD = 0.01


def _figure(**options):
    # Figure without pyplot: no global backend state, works headless
    from matplotlib.figure import Figure

    return Figure(**options)


def _save(figure, path: Path) -> Path:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110)
    atomic_write_files({path: buffer.getvalue()})
    return path


def plot_speed(schedule: Schedule, path: str | Path, *, names=("vehicle 1", "vehicle 2")) -> Path:
    """``v``, ``a``, ``j`` over time for both vehicles with their limit lines, as a PNG.

    Parameters
    ----------
    schedule : Schedule
        Verified before plotting.
    path : path
        PNG file to write.
    names : pair of str
        Legend labels.
    """
    verified(schedule)
    state = schedule.sample(_PLOT_PERIOD)
    figure = _figure(figsize=(9, 7.5))
    axes = figure.subplots(3, 1, sharex=True)
    rows = [
        ("velocity", state.velocity, "max_velocity", "v [m/s]"),
        ("acceleration", state.acceleration, "max_acceleration", "a [m/s²]"),
        ("jerk", state.jerk, "max_jerk", "j [m/s³]"),
    ]
    colours = ("tab:blue", "tab:orange")
    for axis, (_, values, limit_name, label) in zip(axes, rows, strict=True):
        for vehicle in range(2):
            axis.plot(state.t, values[vehicle], color=colours[vehicle], label=names[vehicle])
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            if limit_name != "max_jerk" or schedule.jerk_limited:
                for sign in (1, -1):
                    axis.axhline(sign * limit, color=colours[vehicle], linestyle="--", linewidth=0.8)
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
    if not schedule.jerk_limited:
        axes[2].set_title("jerk not limited by this method (steps in a)", fontsize=9)
    axes[0].legend(loc="upper right")
    axes[0].set_title(f"{schedule.method} schedule, {schedule.duration:.2f} s (dashed: limits)")
    axes[-1].set_xlabel("t [s]")
    figure.tight_layout()
    return _save(figure, Path(path))


def plot_separation(schedule: Schedule, path: str | Path) -> Path:
    """Track distance between the vehicles over time with the minimum line, as a PNG."""
    verified(schedule)
    state = schedule.sample(_PLOT_PERIOD)
    same = (state.leg[0] == state.leg[1]) & (state.leg[0] >= 0)
    distance = np.where(same, np.abs(state.s[0] - state.s[1]), state.s[0] + state.s[1])
    required = max(schedule.limits.min_separation, schedule.route.min_separation)
    figure = _figure(figsize=(9, 4))
    axis = figure.subplots()
    axis.plot(state.t, distance, label="track distance")
    axis.axhline(required, color="tab:red", linestyle="--", label=f"minimum {required:g} m")
    axis.fill_between(state.t, 0, required, color="tab:red", alpha=0.1)
    axis.set_xlabel("t [s]")
    axis.set_ylabel("separation [m]")
    axis.set_ylim(bottom=0)
    axis.set_title(f"{schedule.method} schedule: separation along the track")
    axis.legend(loc="upper right")
    axis.grid(True, alpha=0.3)
    figure.tight_layout()
    return _save(figure, Path(path))


def write_plots(
    schedule: Schedule, directory: str | Path, *, names=("vehicle 1", "vehicle 2")
) -> tuple[Path, ...]:
    """``speed.png`` and ``separation.png`` in ``directory``."""
    directory = Path(directory)
    return (
        plot_speed(schedule, directory / "speed.png", names=names),
        plot_separation(schedule, directory / "separation.png"),
    )
