"""Plots of verified schedules and simulated runs, rendered to PNG (or GIF) bytes (nothing here writes files).

Only :mod:`trajgen.plots.figure` imports matplotlib, and only when a plot is rendered.
"""

from trajgen.plots.animation_drawing import render_animation
from trajgen.plots.configuration_drawing import render_configuration
from trajgen.plots.coordination import METHOD_COLOURS, render_coordination
from trajgen.plots.separation import render_separation
from trajgen.plots.simulation import render_simulation
from trajgen.plots.speed import render_speed

__all__ = [
    "METHOD_COLOURS",
    "render_animation",
    "render_configuration",
    "render_coordination",
    "render_separation",
    "render_simulation",
    "render_speed",
]
