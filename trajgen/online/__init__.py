"""Online execution: a verified schedule played in closed loop, recovering with Ruckig under faults.

:class:`Executor` is stepped once per control cycle with the measured states
of both vehicles and returns their setpoints; :func:`simulate` runs it
against a simulated plant with faults (:mod:`trajgen.online.faults`).
"""

from trajgen.online.braking import BrakingCheck, PathState
from trajgen.online.executor import Command, Event, Executor, GoalDecision, Mode, Setpoint, VehicleState
from trajgen.paths import Coordination, VehiclePath

__all__ = [
    "BrakingCheck",
    "Command",
    "Coordination",
    "Event",
    "Executor",
    "GoalDecision",
    "Mode",
    "PathState",
    "Setpoint",
    "VehiclePath",
    "VehicleState",
]
