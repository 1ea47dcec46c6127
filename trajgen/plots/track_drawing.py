"""A track seen from above, drawn into an axis: the one drawing of every track (a junction's legs too).

The geometry is :class:`~trajgen.plots.track_layout.TrackLayout`'s. Each edge is a wide grey line,
named with its length: beyond its dead end where it has one (a junction's legs, a graph's spurs),
else beside its middle. Each node is a small circle with its name, but for a dead end named after
its edge (``<edge>-end``: a junction's leg ends, which the leg's name already says).
"""

from __future__ import annotations

import numpy as np

from topology import TrackGraph
from trajgen.plots.track_layout import TrackLayout

__all__ = ["dead_ends", "draw_move", "draw_track", "fit_track", "mark_end"]


def dead_ends(track: TrackGraph) -> set[int]:
    """The nodes only one edge ends at."""
    degree = np.zeros(len(track.nodes), dtype=int)
    for k in range(track.edge_count):
        for node in track.ends(k):
            degree[node] += 1
    return {int(n) for n in np.nonzero(degree == 1)[0]}


def fit_track(axis, drawn: TrackLayout) -> None:
    """Set ``axis``'s limits to the whole track with a margin of 12 % of its extent (room for labels)."""
    every = np.vstack([drawn.nodes, *drawn.edges])
    margin = 0.12 * drawn.extent
    axis.set_xlim(float(every[:, 0].min()) - margin, float(every[:, 0].max()) + margin)
    axis.set_ylim(float(every[:, 1].min()) - margin, float(every[:, 1].max()) + margin)


def draw_track(axis, drawn: TrackLayout, *, width: float = 7.0, fontsize: float = 9.0) -> list[np.ndarray]:
    """Draw ``drawn``'s track into ``axis``; the points its labels sit at (to keep legends off them).

    Parameters
    ----------
    axis : matplotlib Axes
        Its limits already set (labels beyond dead ends sit 7.5 % of its width out).
    drawn : TrackLayout
    width : float, optional
        Line width of the edges, points.
    fontsize : float, optional
        Of the edges' labels (the nodes' are the same).

    Returns
    -------
    list of ndarray, each shape (2,)
        Where each label is, metres.
    """
    track = drawn.track
    span = abs(axis.get_xlim()[1] - axis.get_xlim()[0])
    ends = dead_ends(track)
    labels: list[np.ndarray] = []
    for number, line in enumerate(drawn.edges):
        axis.plot(line[:, 0], line[:, 1], color="0.75", linewidth=width, solid_capstyle="round", zorder=1)
        edge = track.edges[number]
        text = f"{edge.name}\n{edge.length:g} m"
        start, end = track.ends(number)
        if end in ends or start in ends:
            tip, before = (line[-1], line[-2]) if end in ends else (line[0], line[1])
            outward = (tip - before) / max(float(np.hypot(*(tip - before))), 1e-12)
            label = tip + 0.075 * span * outward
            labels.append(label)
            axis.text(*label, text, ha="center", va="center", fontsize=fontsize, color="0.3")
        else:
            middle = line[len(line) // 2]
            labels.append(middle)
            axis.annotate(
                text,
                middle,
                xytext=(0, -14),
                textcoords="offset points",
                ha="center",
                va="top",
                fontsize=fontsize - 1,
                color="0.3",
            )
    for node, (name, (x, y)) in enumerate(zip(track.nodes, drawn.nodes, strict=True)):
        axis.plot([x], [y], "o", color="white", markeredgecolor="0.3", markersize=6, zorder=2)
        own = [track.edges[k].name for k in range(track.edge_count) if node in track.ends(k)]
        if node in ends and name in {f"{edge}-end" for edge in own}:
            continue
        axis.annotate(name, (x, y), xytext=(7, 7), textcoords="offset points", fontsize=fontsize, color="0.3")
    return labels


def draw_move(axis, line: np.ndarray, colour: str, number: int, *, at: float = 0.5) -> None:
    """One move drawn: its line in ``colour``, arrowed at its end, ``number`` in a disc ``at`` along it.

    Parameters
    ----------
    axis : matplotlib Axes
    line : ndarray, shape (m, 2)
        Where the move runs, metres, in the order it is driven.
    colour : str
    number : int
        Written in the disc (the move's place in the order).
    at : float, optional
        Fraction of the line's length where the number sits (default the middle).
    """
    axis.plot(line[:, 0], line[:, 1], color=colour, linewidth=2.2, zorder=3)
    if len(line) >= 2:
        axis.annotate(
            "",
            line[-1],
            xytext=line[-2],
            arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 2.2},
            zorder=4,
        )
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(line, axis=0).T))])
    where = [np.interp(at * along[-1], along, line[:, k]) for k in (0, 1)]
    axis.annotate(
        str(number),
        where,
        ha="center",
        va="center",
        fontsize=8,
        color="white",
        weight="bold",
        bbox={"boxstyle": "circle,pad=0.2", "facecolor": colour, "edgecolor": "none"},
        zorder=5,
    )


def mark_end(axis, point, *, goal: bool, colour: str, label: str) -> None:
    """A vehicle's start (hollow circle) or goal (hollow square) at ``point`` (x, y in metres)."""
    axis.plot(
        *point,
        "s" if goal else "o",
        markersize=12,
        markerfacecolor="none",
        markeredgecolor=colour,
        markeredgewidth=2,
        zorder=6,
        label=label,
    )
