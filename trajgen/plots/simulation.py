"""``simulation.png``: a closed-loop run under faults against its plan: speeds and separation over time."""

from __future__ import annotations

import math

import numpy as np

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.plots.figure import new_figure, png_bytes
from trajgen.plots.speed import VEHICLE_COLOURS

__all__ = ["render_simulation"]

#: Colour of the fault marks (lines and spans).
FAULT_COLOUR = "tab:gray"


def _mark_faults(axis, marks: list[tuple[float, float | None, str]]) -> None:
    """Each fault ``(time s, duration s or None, spec)``: a shaded span or a dotted line, labelled."""
    for time, duration, spec in marks:
        if duration is not None:
            axis.axvspan(time, time + duration, color=FAULT_COLOUR, alpha=0.2, linewidth=0)
        else:
            axis.axvline(time, color=FAULT_COLOUR, linestyle=":", linewidth=1.2)
        axis.text(
            time,
            0.98,
            f" {spec}",
            transform=axis.get_xaxis_transform(),
            rotation=90,
            ha="right",
            va="top",
            fontsize=7,
            color="dimgray",
            bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 1},
        )


def render_simulation(result, *, names: tuple[str, str], min_separation: float) -> bytes:
    """A simulated run as PNG bytes: planned against executed speed, and the true separation.

    Top panel: each vehicle's velocity along its axis, m/s, planned (the undisturbed schedule,
    dashed) and executed (the plant's true motion). Bottom panel: the true track distance, m,
    with the minimum separation. Every fault is marked in both panels, labelled with its spec:
    a ``stop`` as a shaded span over its duration, the others as a dotted line at their time.

    Parameters
    ----------
    result : SimulationResult
        From :func:`trajgen.online.simulation.simulate`.
    names : pair of str
        Legend labels of the vehicles.
    min_separation : float
        The separation the run had to keep, metres (the scenario's, not the plan's wider one).

    Raises
    ------
    InputError
        ``result`` is not a SimulationResult, or ``min_separation`` is not a finite number >= 0.
    """
    # imported here: importing the plots must not load the online executor (and Ruckig)
    from trajgen.online.faults import FaultKind
    from trajgen.online.simulation import SimulationResult

    if not isinstance(result, SimulationResult):
        raise InputError(f"render_simulation expects a SimulationResult, got {type(result).__name__}")
    if (
        isinstance(min_separation, bool)
        or not isinstance(min_separation, (int, float))
        or not math.isfinite(min_separation)
        or min_separation < 0.0
    ):
        raise InputError(f"min_separation (m) must be a finite number >= 0, got {short_repr(min_separation)}")
    t = np.asarray(result.plot["t"])
    planned = result.schedule.schedule.state(t).velocity
    figure = new_figure(figsize=(10.5, 7))
    speed_axis, separation_axis = figure.subplots(2, 1, sharex=True)
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
    speed_axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    separation_axis.plot(t, result.plot["separation"], color="tab:green", label="true track distance")
    separation_axis.axhline(
        min_separation, color="tab:red", linestyle="--", label=f"minimum {min_separation:g} m"
    )
    separation_axis.fill_between(t, 0, min_separation, color="tab:red", alpha=0.1)
    separation_axis.set_ylim(bottom=0)
    separation_axis.set_ylabel("separation [m]")
    separation_axis.set_xlabel("t [s]")
    separation_axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    marks = [(f.time, f.value if f.kind is FaultKind.STOP else None, f.spec) for f in result.faults]
    for axis in (speed_axis, separation_axis):
        _mark_faults(axis, marks)
        axis.grid(True, alpha=0.3)
    outcome = "reached the goal" if result.reached_goal else "did NOT reach the goal"
    speed_axis.set_title(
        f"simulation: {outcome} at {result.makespan_s:.2f} s (planned {result.planned_s:.2f} s), "
        f"{result.violations} violations\n(dashed: the undisturbed plan; grey: faults)",
        fontsize=10,
    )
    figure.tight_layout()
    return png_bytes(figure)
