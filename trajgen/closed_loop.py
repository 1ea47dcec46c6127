"""Deprecated: :mod:`trajgen.simulation_pipeline` (trajgen 0.7 renamed ``trajgen.closed_loop``); one release.

Importing it warns (``DeprecationWarning``); every name is :mod:`trajgen.simulation_pipeline`'s.
"""

import warnings

from trajgen.simulation_pipeline import (
    SIMULATION_PLOT_NAME,
    SimulationRun,
    format_simulation,
    run_simulation,
    simulation_paths,
)

warnings.warn(
    "trajgen.closed_loop is deprecated: import from trajgen.simulation_pipeline",
    DeprecationWarning,
    stacklevel=2,
)

__all__ = ["SIMULATION_PLOT_NAME", "SimulationRun", "format_simulation", "run_simulation", "simulation_paths"]
