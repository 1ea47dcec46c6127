"""Plots of verified schedules. The only module that imports matplotlib (lazily).

Every function verifies the schedule first and writes its PNG atomically.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from topology.arrays import track_distance
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
    distance = track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])
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


def travelled(schedule: Schedule, period: float = 0.01):
    """Each vehicle's travelled distance over time and the track positions it passes.

    Returns
    -------
    (t, distance, leg, s)
        ``t`` shape (n,); ``distance``, ``leg``, ``s`` shape (2, n): odometer
        (metres, never decreasing), leg index and distance from the junction.
    """
    state = schedule.sample(period)
    step = track_distance(state.leg[:, :-1], state.s[:, :-1], state.leg[:, 1:], state.s[:, 1:])
    distance = np.concatenate([np.zeros((2, 1)), np.cumsum(step, axis=1)], axis=1)
    return state.t, distance, state.leg, state.s


def _forbidden(schedule: Schedule, required: float, resolution: int = 240):
    """Grid over both vehicles' travelled distances; True where their positions are too close."""
    _, distance, leg, s = travelled(schedule)
    axes = []
    for vehicle in range(2):
        total = distance[vehicle, -1]
        grid = np.linspace(0.0, total, resolution) if total > 0 else np.zeros(1)
        index = np.clip(np.searchsorted(distance[vehicle], grid), 0, distance.shape[1] - 1)
        axes.append((grid, leg[vehicle, index], s[vehicle, index]))
    (d1, leg1, s1), (d2, leg2, s2) = axes
    gap = track_distance(leg1[None, :], s1[None, :], leg2[:, None], s2[:, None])
    return d1, d2, gap < required


def plot_coordination(schedules: dict[str, Schedule], path: str | Path) -> Path:
    """The coordination diagram: both vehicles' travelled distances, forbidden region shaded.

    Each panel holds the schedules that drive the same paths (the route's
    paths for ``exact`` and ``toppra``; ``optimal`` parks shallower, so its
    paths, and therefore its forbidden region, differ). A schedule's curve
    must stay out of the shaded region of its panel.

    Parameters
    ----------
    schedules : dict of name -> Schedule
        Verified before plotting; at least one.
    path : path
        PNG file to write.
    """
    if not schedules:
        raise ValueError("plot_coordination needs at least one schedule")
    for schedule in schedules.values():
        verified(schedule)
    groups: dict[tuple, list[str]] = {}
    for name, schedule in schedules.items():
        _, distance, _, _ = travelled(schedule)
        key = tuple(np.round(distance[:, -1], 6))  # same paths drive the same distances
        groups.setdefault(key, []).append(name)
    figure = _figure(figsize=(5.2 * len(groups), 5.0))
    panels = figure.subplots(1, len(groups), squeeze=False)[0]
    colours = {"exact": "tab:blue", "toppra": "tab:green", "optimal": "tab:red"}
    for axis, names in zip(panels, groups.values(), strict=True):
        reference = schedules[names[0]]
        required = max(reference.limits.min_separation, reference.route.min_separation)
        d1, d2, forbidden = _forbidden(reference, required)
        if forbidden.any():
            axis.contourf(d1, d2, forbidden.astype(float), levels=[0.5, 1.5], colors=["tab:gray"], alpha=0.35)
        for name in names:
            _, distance, _, _ = travelled(schedules[name])
            axis.plot(
                distance[0],
                distance[1],
                color=colours.get(name, "black"),
                label=f"{name} ({schedules[name].duration:.1f} s)",
            )
        axis.set_xlabel("vehicle 1 travelled [m]")
        axis.set_ylabel("vehicle 2 travelled [m]")
        axis.set_title(f"paths of {', '.join(names)}\n(grey: closer than {required:g} m)", fontsize=10)
        axis.legend(loc="lower right", fontsize=8)
        axis.grid(True, alpha=0.3)
    figure.tight_layout()
    return _save(figure, Path(path))
