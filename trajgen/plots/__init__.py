"""Plots of verified schedules and simulated runs, rendered to PNG (or GIF) bytes (nothing here writes files).

Only :mod:`trajgen.plots.figure` imports matplotlib, and only when a plot is rendered. Each renderer is
imported from its module when first used.
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.plots.animation_drawing import render_animation
    from trajgen.plots.configuration_drawing import render_configuration
    from trajgen.plots.coordination import METHOD_COLOURS, render_coordination
    from trajgen.plots.live_run import render_live_run
    from trajgen.plots.separation import render_separation
    from trajgen.plots.simulation import render_simulation
    from trajgen.plots.speed import render_speed

__all__ = [
    "METHOD_COLOURS",
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
    "render_animation": "trajgen.plots.animation_drawing",
    "render_configuration": "trajgen.plots.configuration_drawing",
    "render_coordination": "trajgen.plots.coordination",
    "render_live_run": "trajgen.plots.live_run",
    "render_separation": "trajgen.plots.separation",
    "render_simulation": "trajgen.plots.simulation",
    "render_speed": "trajgen.plots.speed",
}

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
