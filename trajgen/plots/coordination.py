"""``coordination.png``: both vehicles' travelled distances, the too-close region shaded, per method."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from topology.indexed import track_distance
from trajgen.errors import InputError
from trajgen.methods import METHODS
from trajgen.model.analysis import travelled
from trajgen.model.schedule import Schedule
from trajgen.plots.figure import new_figure, png_bytes
from trajgen.plots.speed import plot_period
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["METHOD_COLOURS", "render_coordination"]

_PALETTE = ("tab:blue", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
#: Curve colour of each registered method, in registry order.
METHOD_COLOURS = {name: _PALETTE[k % len(_PALETTE)] for k, name in enumerate(METHODS.names)}


def _forbidden(schedule: Schedule, required: float, resolution: int = 240):
    """Grid over both vehicles' travelled distances; True where their positions are too close."""
    _, distance, leg, s = travelled(schedule, plot_period(schedule.duration))
    axes = []
    for vehicle in range(2):
        total = distance[vehicle, -1]
        grid = np.linspace(0.0, total, resolution) if total > 0 else np.zeros(1)
        index = np.clip(np.searchsorted(distance[vehicle], grid), 0, distance.shape[1] - 1)
        axes.append((grid, leg[vehicle, index], s[vehicle, index]))
    (d1, leg1, s1), (d2, leg2, s2) = axes
    gap = track_distance(leg1[None, :], s1[None, :], leg2[:, None], s2[:, None])
    return d1, d2, gap < required


def render_coordination(verified: Mapping[str, VerifiedSchedule]) -> bytes:
    """The coordination diagram as PNG bytes.

    Each panel holds the schedules that drive the same paths (the route's
    paths for ``exact`` and ``toppra``; ``optimal`` parks shallower, so its
    paths, and therefore its forbidden region, differ). A schedule's curve
    must stay out of the shaded region of its panel.

    Parameters
    ----------
    verified : mapping of method name to VerifiedSchedule
        At least one.
    """
    if not isinstance(verified, Mapping) or not verified:
        raise InputError(
            "the coordination plot needs a mapping of method name to VerifiedSchedule, "
            f"got {type(verified).__name__}"
        )
    schedules = {name: require_verified(v, "render_coordination").schedule for name, v in verified.items()}
    distances = {
        name: travelled(schedule, plot_period(schedule.duration))[1] for name, schedule in schedules.items()
    }
    groups: dict[tuple, list[str]] = {}
    for name, distance in distances.items():
        key = tuple(np.round(distance[:, -1], 6))  # same paths drive the same distances
        groups.setdefault(key, []).append(name)
    figure = new_figure(figsize=(5.2 * len(groups), 5.0))
    panels = figure.subplots(1, len(groups), squeeze=False)[0]
    for axis, names in zip(panels, groups.values(), strict=True):
        reference = schedules[names[0]]
        required = max(reference.limits.min_separation, reference.route.min_separation)
        d1, d2, forbidden = _forbidden(reference, required)
        if forbidden.any():
            axis.contourf(d1, d2, forbidden.astype(float), levels=[0.5, 1.5], colors=["tab:gray"], alpha=0.35)
        for name in names:
            axis.plot(
                distances[name][0],
                distances[name][1],
                color=METHOD_COLOURS.get(name, "black"),
                label=f"{name} ({schedules[name].duration:.1f} s)",
            )
        axis.set_xlabel("vehicle 1 travelled [m]")
        axis.set_ylabel("vehicle 2 travelled [m]")
        axis.set_title(f"paths of {', '.join(names)}\n(grey: closer than {required:g} m)", fontsize=10)
        axis.legend(loc="lower right", fontsize=8)
        axis.grid(True, alpha=0.3)
    figure.tight_layout()
    return png_bytes(figure)
