"""The one module that imports matplotlib (lazily): figures without pyplot, and their PNG bytes.

The plots draw into an ``ax`` or ``figure`` a caller gives (a notebook composing several) or into
a new Figure, and return the Figure; :func:`png_bytes` is for the edges (the pipeline, the command
line) that write files.
"""

from __future__ import annotations

import io

__all__ = [
    "PNG_DPI",
    "drawing_area",
    "drawing_axis",
    "finished",
    "frame_painter",
    "new_figure",
    "png_bytes",
    "polygon_patch",
    "root_figure",
]

#: Resolution of the PNGs, dots per inch.
PNG_DPI = 110


def new_figure(*, figsize: tuple[float, float]):
    """A matplotlib Figure not registered with pyplot (no global backend state, works headless).

    Parameters
    ----------
    figsize : (float, float)
        Width and height, inches.
    """
    from matplotlib.figure import Figure

    return Figure(figsize=figsize)


def drawing_area(figure, *, figsize: tuple[float, float]):
    """Where a plot of several axes draws: ``figure`` (a Figure or SubFigure), else a new Figure."""
    return new_figure(figsize=figsize) if figure is None else figure


def drawing_axis(ax, *, figsize: tuple[float, float]):
    """Where a plot of one axis draws: ``ax``, else the one axis of a new Figure of ``figsize`` inches."""
    return new_figure(figsize=figsize).subplots() if ax is None else ax


def root_figure(part):
    """The Figure that holds ``part`` (an Axes, a SubFigure or the Figure itself)."""
    figure = part.figure
    while figure.figure is not figure:  # a SubFigure's figure is its parent's
        figure = figure.figure
    return figure


def finished(area, *, laid_out: bool):
    """The Figure of a plot drawn into ``area``; laid out tightly when the plot made it (``laid_out``).

    A figure given by the caller keeps the layout the caller chose.
    """
    figure = root_figure(area)
    if laid_out:
        figure.tight_layout()
    return figure


def polygon_patch(vertices, *, facecolor, alpha: float, edgecolor, label: str | None = None):
    """A closed polygon patch through ``vertices`` (array of shape (n, 2)), labelled for a legend."""
    from matplotlib.patches import Polygon

    return Polygon(vertices, closed=True, facecolor=facecolor, alpha=alpha, edgecolor=edgecolor, label=label)


def png_bytes(figure) -> bytes:
    """The figure as PNG bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=PNG_DPI)
    return buffer.getvalue()


def frame_painter(figure, animated):
    """A function that draws the frames of an animation of ``figure`` as RGB arrays.

    Everything but the ``animated`` artists is drawn once (Agg, at the figure's dpi)
    and kept; each call of the returned function restores that background, draws the
    ``animated`` artists over it in the order given (after their data were changed)
    and returns the frame as a new array of shape (height, width, 3), uint8. Text is drawn
    without hinting: at a frame's small sizes it looks the same and renders about a quarter faster
    (hundreds of labels per animation).

    Parameters
    ----------
    figure : matplotlib Figure
    animated : sequence of matplotlib Artist
        The artists that change from frame to frame, in drawing order.
    """
    import matplotlib
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    unhinted = {"text.hinting": "none"}
    canvas = FigureCanvasAgg(figure)
    for artist in animated:
        artist.set_animated(True)
    with matplotlib.rc_context(unhinted):
        canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)

    def paint():
        canvas.restore_region(background)
        with matplotlib.rc_context(unhinted):
            for artist in animated:
                figure.draw_artist(artist)
        return np.array(np.asarray(canvas.buffer_rgba())[:, :, :3])

    return paint


def time_label(axis, t: float, height: float, text: str, *, colour) -> None:
    """A vertical label at time ``t`` (data units), its top at ``height`` of the axis (0 to 1)."""
    axis.text(
        t,
        height,
        f" {text}",
        transform=axis.get_xaxis_transform(),
        rotation=90,
        ha="right",
        va="top",
        fontsize=7,
        color=colour,
        bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 1},
    )
