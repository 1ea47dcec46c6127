"""Plots of schedules, runs and routes: each draws into an ``ax`` or ``figure`` and returns the Figure.

Nothing here writes files: the pipeline and the command line turn Figures into PNG bytes
(:func:`png_bytes`) and an :class:`Animation` into a GIF (:func:`encode_gif`). A notebook
composes and restyles them as it likes (``docs/plots.md``). Only :mod:`trajgen.plots.figure`
imports matplotlib, and only when a plot is drawn; each plot is imported from its module when
first used. The ``render_*`` functions of 0.6 (bytes) are deprecated shims for one release.
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.plots.animation import Animation, animate
    from trajgen.plots.configuration import plot_configuration
    from trajgen.plots.coordination import METHOD_COLOURS, plot_coordination
    from trajgen.plots.deprecated import (
        render_animation,
        render_configuration,
        render_coordination,
        render_live_run,
        render_separation,
        render_simulation,
        render_speed,
    )
    from trajgen.plots.figure import png_bytes
    from trajgen.plots.gif import encode_gif, gif_bytes
    from trajgen.plots.graph_route import plot_graph_route
    from trajgen.plots.layout import plot_layout
    from trajgen.plots.live_run import plot_live_run
    from trajgen.plots.separation import plot_separation
    from trajgen.plots.simulation import plot_simulation
    from trajgen.plots.speed import plot_speed

__all__ = [
    "METHOD_COLOURS",
    "Animation",
    "animate",
    "encode_gif",
    "gif_bytes",
    "plot_configuration",
    "plot_coordination",
    "plot_graph_route",
    "plot_layout",
    "plot_live_run",
    "plot_separation",
    "plot_simulation",
    "plot_speed",
    "png_bytes",
    "render_animation",
    "render_configuration",
    "render_coordination",
    "render_live_run",
    "render_separation",
    "render_simulation",
    "render_speed",
]

_SOURCES = {
    "METHOD_COLOURS": "trajgen.plots.coordination",
    "Animation": "trajgen.plots.animation",
    "animate": "trajgen.plots.animation",
    "encode_gif": "trajgen.plots.gif",
    "gif_bytes": "trajgen.plots.gif",
    "plot_configuration": "trajgen.plots.configuration",
    "plot_coordination": "trajgen.plots.coordination",
    "plot_graph_route": "trajgen.plots.graph_route",
    "plot_layout": "trajgen.plots.layout",
    "plot_live_run": "trajgen.plots.live_run",
    "plot_separation": "trajgen.plots.separation",
    "plot_simulation": "trajgen.plots.simulation",
    "plot_speed": "trajgen.plots.speed",
    "png_bytes": "trajgen.plots.figure",
    **{name: "trajgen.plots.deprecated" for name in __all__ if name.startswith("render_")},
}

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
