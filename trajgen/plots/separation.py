"""``separation.png``: the track distance between the vehicles over time, with the minimum."""

from __future__ import annotations

import numpy as np

from trajgen.model.summary import class_label, closest_text
from trajgen.plots.figure import drawing_axis, finished
from trajgen.plots.speed import plot_period
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["plot_separation"]

#: Grids searched for the instant of the closest approach (each 50 times finer than the one before).
_ROUNDS = 4


def _distance(schedule, state) -> np.ndarray:
    """Track distance between the vehicles in ``state`` (the schedule's, at some times), metres."""
    return schedule.distances(state)


def _closest(schedule, sample: float, period: float) -> tuple[float, float]:
    """Where the distance is smallest near the closest sample: ``(t, distance)``, seconds and metres.

    Searched within a sample period either side, on grids each 50 times finer than the one before
    (to a nanosecond): the minimum is often a corner of the distance, which samples miss.
    """
    low, high = max(sample - period, 0.0), min(sample + period, schedule.duration)
    for _ in range(_ROUNDS):
        near = np.linspace(low, high, 101)
        distance = _distance(schedule, schedule.state(near))
        k = int(np.argmin(distance))
        low, high = near[max(k - 1, 0)], near[min(k + 1, near.size - 1)]
    return float(near[k]), float(distance[k])


def plot_separation(verified: VerifiedSchedule, *, ax=None):
    """Track distance between the vehicles over time, with the minimum line and the closest approach.

    The closest approach is marked where the curve comes closest (refined between its samples) and
    named with the verifier's figure, written as the run's summary writes it
    (:func:`trajgen.model.summary.closest_text`: rounded down, never above the value).

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
    verified = require_verified(verified, "plot_separation")
    schedule = verified.schedule
    period = plot_period(schedule.duration)
    state = schedule.sample(period)
    t, distance = state.t, _distance(schedule, state)
    required = max(schedule.limits.min_separation, schedule.route.min_separation)
    axis = drawing_axis(ax, figsize=(10.5, 4))
    axis.plot(t, distance, label="track distance")
    axis.axhline(required, color="tab:red", linestyle="--", label=f"minimum {required:g} m")
    when, closest = _closest(schedule, t[int(np.argmin(distance))], period)
    axis.plot(
        when,
        closest,
        "v",
        color="black",
        label=f"closest {closest_text(verified.report.min_separation)} at {when:.2f} s",
    )
    axis.fill_between(t, 0, required, color="tab:red", alpha=0.1)
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
