"""Deprecated: :mod:`trajgen.execution` (trajgen 0.7 renamed ``trajgen.online``); kept for one release.

Importing it warns (``DeprecationWarning``); every name is :mod:`trajgen.execution`'s, and
``plan_for_execution`` is :func:`~trajgen.execution.schedule_for_execution`.
"""

import warnings

from trajgen.lazy import lazy_attributes

warnings.warn(
    "trajgen.online is deprecated: import from trajgen.execution (plan_for_execution is now "
    "schedule_for_execution)",
    DeprecationWarning,
    stacklevel=2,
)

#: Every name of trajgen.execution's face, found there when first used.
_SOURCES = dict.fromkeys(
    (
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
    ),
    "trajgen.execution",
)

__all__ = [*_SOURCES, "plan_for_execution"]

_attribute, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)


def __getattr__(name: str) -> object:
    if name == "plan_for_execution":
        return _attribute("schedule_for_execution")
    return _attribute(name)
