"""Online execution: a verified plan played in closed loop, keeping its order at every conflict.

:class:`Executor` is stepped once per control cycle with the measured states
of both vehicles and returns their setpoints: each vehicle follows the plan
while it is on time, else Ruckig re-times it towards its frontier (where its
leader at each conflict could still come to rest), under an independent
braking check. :func:`~trajgen.execution.goals.schedule_for_execution` makes the plan
it plays; :func:`~trajgen.execution.simulation.simulate` runs it against a
simulated plant with faults (:mod:`trajgen.execution.faults`). The argument is
in docs/online.md. The model types it uses (``VehiclePath``, ``CoordinationDiagram``,
``Conflict``) have one import path, :mod:`trajgen.model`.
"""

from trajgen.execution.braking_check import BrakingCheck, PathState
from trajgen.execution.executor import Command, Event, Executor, GoalDecision, Mode, Setpoint, VehicleState
from trajgen.execution.goals import execution_margin, schedule_for_execution

__all__ = [
    "BrakingCheck",
    "Command",
    "Event",
    "Executor",
    "GoalDecision",
    "Mode",
    "PathState",
    "Setpoint",
    "VehicleState",
    "execution_margin",
    "schedule_for_execution",
]
