"""The one module that imports matplotlib (lazily): figures without pyplot, and their PNG bytes.

The plots draw into an ``ax`` or ``figure`` a caller gives (a notebook composing several) or into
a new Figure, and return the Figure; :func:`png_bytes` is for the edges (the pipeline, the command
line) that write files.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = [
    "PNG_DPI",
    "checked_names",
    "drawing_area",
    "drawing_axis",
    "finished",
    "frame_painter",
    "new_figure",
    "png_bytes",
    "polygon_patch",
    "root_figure",
    "untangle",
    "wrapped",
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


def wrapped(text: str, *, width_in: float, fontsize: float) -> str:
    """``text`` broken between words into lines at most ``width_in`` inches wide at ``fontsize`` points.

    Measured as the PNGs draw text (Agg at :data:`PNG_DPI`); a word wider than the width stays on
    a line of its own; the line breaks already in ``text`` are kept.
    """
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    renderer = RendererAgg(1, 1, PNG_DPI)
    font = FontProperties(size=fontsize)
    limit = width_in * PNG_DPI

    def fits(line: str) -> bool:
        return renderer.get_text_width_height_descent(line, font, ismath=False)[0] <= limit

    lines = []
    for paragraph in text.split("\n"):
        line = ""
        for word in paragraph.split(" "):
            candidate = f"{line} {word}" if line else word
            if line and not fits(candidate):
                lines.append(line)
                line = word
            else:
                line = candidate
        lines.append(line)
    return "\n".join(lines)


def untangle(texts, *, smallest: float, step: float = 0.5, padding_px: float = 2.0) -> bool:
    """Make the font of each text that overlaps another smaller, until none overlap or all are ``smallest``.

    Boxes are measured as drawn (Agg at the figure's dpi), ``padding_px`` apart; the texts of a
    pair that overlap both shrink by ``step`` points a round, none below ``smallest`` points.

    Parameters
    ----------
    texts : sequence of matplotlib Text
        Of one figure, placed.
    smallest : float
        Points.

    Returns
    -------
    bool
        Whether no two overlap now.
    """
    from matplotlib.backends.backend_agg import RendererAgg

    texts = [text for text in texts if text.get_visible() and text.get_text().strip()]
    if not texts:
        return True
    figure = root_figure(texts[0])
    renderer = RendererAgg(int(figure.bbox.width) + 1, int(figure.bbox.height) + 1, figure.dpi)
    for axis in figure.axes:  # where an equal-aspect axis really lies is settled when it is drawn
        axis.apply_aspect()
    while True:
        boxes = [text.get_window_extent(renderer).padded(padding_px) for text in texts]
        clashing = {
            k
            for i, a in enumerate(boxes)
            for j in range(i + 1, len(boxes))
            if a.overlaps(boxes[j])
            for k in (i, j)
        }
        shrinking = [texts[k] for k in sorted(clashing) if texts[k].get_fontsize() > smallest]
        if not shrinking:
            return not clashing
        for text in shrinking:
            text.set_fontsize(max(smallest, text.get_fontsize() - step))


def polygon_patch(vertices, *, facecolor, alpha: float, edgecolor, label: str | None = None):
    """A closed polygon patch through ``vertices`` (array of shape (n, 2)), labelled for a legend."""
    from matplotlib.patches import Polygon

    return Polygon(vertices, closed=True, facecolor=facecolor, alpha=alpha, edgecolor=edgecolor, label=label)


def clip_to_data_box(artist, axis, lower: tuple[float, float], upper: tuple[float, float]) -> None:
    """Draw ``artist`` only inside the box from ``lower`` to ``upper`` (data units of ``axis``)."""
    from matplotlib.transforms import Bbox, TransformedBbox

    artist.set_clip_box(TransformedBbox(Bbox([list(lower), list(upper)]), axis.transData))


def numbered_handle(number: int, *, colour, label: str):
    """A legend entry showing ``number`` (as drawn on a panel) before ``label``."""
    from matplotlib.lines import Line2D

    return Line2D([], [], linestyle="none", marker=f"${number}$", markersize=6, color=colour, label=label)


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
    from PIL import Image

    canvas = FigureCanvasAgg(figure)
    for artist in animated:
        artist.set_animated(True)
    with matplotlib.rc_context({"text.hinting": "none"}):
        canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)

    def paint():
        canvas.restore_region(background)
        # the one setting for the artists drawn here, put back at once (a whole rc_context per frame
        # copies every setting)
        hinting = matplotlib.rcParams["text.hinting"]
        matplotlib.rcParams["text.hinting"] = "none"
        try:
            for artist in animated:
                figure.draw_artist(artist)
        finally:
            matplotlib.rcParams["text.hinting"] = hinting
        rgba = np.asarray(canvas.buffer_rgba())
        height, width = rgba.shape[:2]
        # Pillow drops the alpha channel about three times faster than a strided numpy copy
        rgb = Image.frombuffer("RGBA", (width, height), rgba, "raw", "RGBA", 0, 1).convert("RGB")
        return np.array(rgb)

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


def checked_names(names: object, count: int, *, what: str) -> tuple[str, ...]:
    """The vehicles' names a picture writes: one string per vehicle (``None``: ``vehicle 1``, ...).

    Raises
    ------
    InputError
        Not ``count`` strings (a single string is one name, not a sequence of them); the message
        names ``what`` asked and the value given.
    """
    if names is None:
        return tuple(f"vehicle {k}" for k in range(1, count + 1))
    if (
        not isinstance(names, Sequence)
        or isinstance(names, str)
        or len(names) != count
        or not all(isinstance(name, str) for name in names)
    ):
        raise InputError(f"{what} names must be {count} strings, one per vehicle, got {short_repr(names)}")
    return tuple(names)
