"""trajgen: collision-free, time-optimal schedules for two AGVs on a Y-track.

The planner lives in :mod:`topology`, the vehicle limits in :mod:`limits`;
this package turns routes into schedules and hands them to controllers.
Heavy dependencies (CasADi, TOPPRA, Ruckig, matplotlib) are imported only by
the modules that use them.
"""

from topology import Configuration, Position, Route, YGraph, plan
from topology.errors import TrajgenError

__all__ = ["Configuration", "Position", "Route", "TrajgenError", "YGraph", "plan"]
__version__ = "0.1.0"
