"""The one module that imports matplotlib (lazily): figures without pyplot, rendered to PNG bytes."""

from __future__ import annotations

import io

__all__ = ["PNG_DPI", "new_figure", "png_bytes"]

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


def png_bytes(figure) -> bytes:
    """The figure as PNG bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=PNG_DPI)
    return buffer.getvalue()
