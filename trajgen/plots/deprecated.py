"""The renderers of trajgen 0.6, which returned PNG (or GIF) bytes: kept for one release.

Each warns (``DeprecationWarning``) and returns what it returned: the plot function's Figure as
PNG bytes. Use the plot functions (they take an ``ax`` or ``figure`` and return the Figure) and
:func:`~trajgen.plots.figure.png_bytes`; for the animation, :func:`~trajgen.plots.animate` and
:func:`~trajgen.plots.gif.gif_bytes`.
"""

from __future__ import annotations

import warnings

from trajgen.plots.figure import png_bytes

__all__ = [
    "render_animation",
    "render_configuration",
    "render_coordination",
    "render_live_run",
    "render_separation",
    "render_simulation",
    "render_speed",
]


def _warn(old: str, new: str) -> None:
    warnings.warn(
        f"trajgen.plots.{old} is deprecated: use trajgen.plots.{new}, which returns a Figure "
        "(trajgen.plots.png_bytes(figure) gives the PNG)",
        DeprecationWarning,
        stacklevel=3,
    )


def render_speed(verified, *, names=("vehicle 1", "vehicle 2")) -> bytes:
    """Deprecated: ``png_bytes(plot_speed(verified, names=names))``."""
    from trajgen.plots.speed import plot_speed

    _warn("render_speed", "plot_speed")
    return png_bytes(plot_speed(verified, names=names))


def render_separation(verified) -> bytes:
    """Deprecated: ``png_bytes(plot_separation(verified))``."""
    from trajgen.plots.separation import plot_separation

    _warn("render_separation", "plot_separation")
    return png_bytes(plot_separation(verified))


def render_coordination(verified) -> bytes:
    """Deprecated: ``png_bytes(plot_coordination(verified))``."""
    from trajgen.plots.coordination import plot_coordination

    _warn("render_coordination", "plot_coordination")
    return png_bytes(plot_coordination(verified))


def render_configuration(subject, *, names=None) -> bytes:
    """Deprecated: ``png_bytes(plot_configuration(subject, names=names))``."""
    from trajgen.plots.configuration import plot_configuration

    _warn("render_configuration", "plot_configuration")
    return png_bytes(plot_configuration(subject, names=names))


def render_simulation(result, *, names, min_separation) -> bytes:
    """Deprecated: ``png_bytes(plot_simulation(result, names=names, min_separation=...))``."""
    from trajgen.plots.simulation import plot_simulation

    _warn("render_simulation", "plot_simulation")
    return png_bytes(plot_simulation(result, names=names, min_separation=min_separation))


def render_live_run(run, *, names) -> bytes:
    """Deprecated: ``png_bytes(plot_live_run(run, names=names))``."""
    from trajgen.plots.live_run import plot_live_run

    _warn("render_live_run", "plot_live_run")
    return png_bytes(plot_live_run(run, names=names))


def render_animation(verified, *, names=("vehicle 1", "vehicle 2"), fps=10, max_frames=300) -> bytes:
    """Deprecated: the GIF of ``animate(verified, ...)`` (see :func:`~trajgen.plots.gif.gif_bytes`)."""
    from trajgen.plots.animation import animate
    from trajgen.plots.gif import encode_gif

    _warn("render_animation", "animate")
    return encode_gif(animate(verified, names=names, fps=fps, max_frames=max_frames))
