"""A schedule drawn on its track from above: where each vehicle goes, move by move, on every track.

The track is :func:`~trajgen.plots.track_drawing.draw_track`'s drawing (a junction's legs at their
angles, any track graph as its layout). A *move* is a stretch in which a vehicle drives one way
without stopping; each is a line in its vehicle's colour, arrowed at its end and numbered a third of
the way along, in the order the moves begin (a vehicle that waits for the other, or turns back, begins a
new move). A hollow circle marks where a vehicle starts, a hollow square where it ends. The moves
are read off the schedule's states, so the drawing is the same for every track and every timing
method: on a track graph timed by ``exact`` they are the route's moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from topology import TrackGraph
from trajgen.model.coordination import schedule_times
from trajgen.plots.figure import checked_names, drawing_axis, finished
from trajgen.plots.speed import vehicle_colour
from trajgen.plots.track_drawing import draw_move, draw_track, fit_track, mark_end
from trajgen.plots.track_layout import TrackLayout
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["DrawnMove", "plot_layout", "schedule_moves"]

#: Instants sampled across a schedule, beside its own (piece ends, turns): how finely moves are drawn.
LAYOUT_SAMPLES = 1500
#: A vehicle whose axis moves less than this between two instants rests there, metres.
_REST = 1e-9


@dataclass(frozen=True, slots=True, eq=False)
class DrawnMove:
    """One vehicle driving one way without stopping.

    Attributes
    ----------
    vehicle : int
    start, end : float
        When it begins and ends, seconds.
    edges, s : ndarray of int, ndarray, shape (n,)
        Where it is at n instants from its start to its end (edge number, metres along it).
    length : float
        Metres driven.
    """

    vehicle: int
    start: float
    end: float
    edges: np.ndarray
    s: np.ndarray
    length: float


def schedule_moves(schedule) -> tuple[DrawnMove, ...]:
    """The moves of ``schedule`` in the order they begin (ties: the lower vehicle number first).

    Read at the schedule's own instants (between two of them no vehicle turns) and at
    :data:`LAYOUT_SAMPLES` instants across it.
    """
    grid = np.union1d(schedule_times(schedule), np.linspace(0.0, schedule.duration, LAYOUT_SAMPLES))
    state = schedule.state(grid)
    moves = []
    for vehicle in range(state.axis.shape[0]):
        step = np.diff(state.axis[vehicle])
        direction = np.where(np.abs(step) > _REST, np.sign(step), 0.0)
        k = 0
        while k < step.size:
            if direction[k] == 0.0:
                k += 1
                continue
            first = k
            while k < step.size and direction[k] == direction[first]:
                k += 1
            span = slice(first, k + 1)
            moves.append(
                DrawnMove(
                    vehicle,
                    float(grid[first]),
                    float(grid[k]),
                    state.edge[vehicle, span].copy(),
                    state.s[vehicle, span].copy(),
                    float(np.abs(step[first:k]).sum()),
                )
            )
    return tuple(sorted(moves, key=lambda move: (move.start, move.vehicle)))


def _polyline(drawn: TrackLayout, move: DrawnMove) -> np.ndarray:
    """Where ``move`` is drawn: its points, and the node between two points on different edges."""
    track: TrackGraph = drawn.track
    points = drawn.points(move.edges, move.s)
    out = [points[0]]
    for k in range(1, len(points)):
        a, b = int(move.edges[k - 1]), int(move.edges[k])
        if a != b:
            shared = set(track.ends(a)) & set(track.ends(b))
            if shared:
                out.append(drawn.nodes[min(shared)])
        out.append(points[k])
    return np.array(out)


def plot_layout(verified: VerifiedSchedule, *, names=None, ax=None):
    """The schedule's track seen from above with each vehicle's moves, numbered in the order they begin.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.certify`.
    names : sequence of str, optional
        The vehicles' names, one per vehicle, for the legend and the title (default ``vehicle 1``, ...).
    ax : matplotlib Axes, optional
        Where to draw (default: a new Figure of 9 x 7 inches).

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding the plot.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        ``names`` is not one string per vehicle.
    """
    schedule = require_verified(verified, "plot_layout").schedule
    count = schedule.limits.count
    names = checked_names(names, count, what="plot_layout")
    track = schedule.track
    drawn = TrackLayout.of(track)
    axis = drawing_axis(ax, figsize=(9, 7))
    fit_track(axis, drawn)
    draw_track(axis, drawn, width=6.0, fontsize=8.0)
    moves = schedule_moves(schedule)
    shift = 0.012 * drawn.extent  # the vehicles' lines side by side where they share the track
    for number, move in enumerate(moves, start=1):
        colour = vehicle_colour(move.vehicle)
        line = _polyline(drawn, move) + (shift if move.vehicle % 2 == 0 else -shift)
        # a third of the way, not half: on a junction the middle of many moves is the junction
        draw_move(axis, line, colour, number, at=1.0 / 3.0)
    ends = schedule.state([0.0, schedule.duration])
    travel = [sum(move.length for move in moves if move.vehicle == v) for v in range(count)]
    for vehicle in range(count):
        colour = vehicle_colour(vehicle)
        points = drawn.points(ends.edge[vehicle], ends.s[vehicle])
        for point, goal in ((points[0], False), (points[1], True)):
            what = "goal" if goal else "start"
            mark_end(axis, point, goal=goal, colour=colour, label=f"{names[vehicle]} {what}")
    axis.set_aspect("equal", adjustable="box")
    axis.set_xlabel("x [m]" if drawn.given else "laid out from the track distances [m]")
    axis.set_ylabel("y [m]" if drawn.given else "")
    driven = ", ".join(f"{name} {metres:.1f} m" for name, metres in zip(names, travel, strict=True))
    apart = schedule.limits.min_separation
    axis.set_title(
        f"{schedule.method.name} schedule, {schedule.duration:.1f} s, {apart:g} m apart: "
        f"{driven}; {len(moves)} moves (numbered as they begin)",
        fontsize=10,
    )
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
    axis.grid(True, alpha=0.2)
    return finished(axis, laid_out=ax is None)
