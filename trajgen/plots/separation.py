"""``separation.png``: the track distance between the vehicles over time, with the minimum."""

from __future__ import annotations

import numpy as np

from topology.indexed import track_distance
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.summary import class_label
from trajgen.plots.figure import drawing_axis, finished
from trajgen.plots.speed import plot_period
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["plot_separation"]


def plot_separation(verified: VerifiedSchedule, *, ax=None):
    """Track distance between the vehicles over time, with the minimum line.

    Parameters
    ----------
    verified : VerifiedSchedule
    ax : matplotlib Axes, optional
        Where to draw (default: a new Figure of 10.5 x 4 inches).

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding the plot.
    """
    schedule = require_verified(verified, "plot_separation").schedule
    state = schedule.sample(plot_period(schedule.duration))
    if isinstance(schedule, GraphSchedule):
        distance = schedule.track.distances(state.edge[0], state.s[0], state.edge[1], state.s[1])
    else:
        distance = track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])
    required = max(schedule.limits.min_separation, schedule.route.min_separation)
    axis = drawing_axis(ax, figsize=(10.5, 4))
    axis.plot(state.t, distance, label="track distance")
    axis.axhline(required, color="tab:red", linestyle="--", label=f"minimum {required:g} m")
    closest = int(np.argmin(distance))
    axis.plot(
        state.t[closest],
        distance[closest],
        "v",
        color="black",
        label=f"closest {distance[closest]:.3f} m at {state.t[closest]:.2f} s",
    )
    axis.fill_between(state.t, 0, required, color="tab:red", alpha=0.1)
    axis.set_xlabel("t [s]")
    axis.set_ylabel("separation [m]")
    axis.set_ylim(bottom=0)
    axis.set_title(
        f"{schedule.method.name} schedule: separation along the track\nclass {class_label(schedule.route)}",
        fontsize=10,
    )
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
    axis.grid(True, alpha=0.3)
    return finished(axis, laid_out=ax is None)
