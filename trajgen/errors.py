"""The one public exception module of trajgen: every error the distribution raises on purpose.

Input errors subclass ``ValueError`` (a wrong type: ``TypeError``), failed
computations ``RuntimeError``; all subclass :class:`TrajgenError`. The
planner's and the limits' errors are re-exported here.

Examples
--------
>>> from trajgen.errors import InputError, TrajgenError
>>> issubclass(InputError, ValueError) and issubclass(InputError, TrajgenError)
True
"""

from __future__ import annotations

from collections.abc import Sequence

from limits.errors import LimitsError
from topology.errors import (
    InfeasibleError,
    InputError,
    OptionError,
    PositionError,
    SeparationError,
    TrackError,
    TrajgenError,
    VehicleCountError,
)

__all__ = [
    "InfeasibleError",
    "InputError",
    "LimitsError",
    "LiveError",
    "MissingExtraError",
    "OptionError",
    "OutputError",
    "OutputLimitError",
    "PositionError",
    "ProfileFileError",
    "ScenarioError",
    "ScheduleError",
    "SeparationError",
    "SolverError",
    "TrackError",
    "TrajgenError",
    "UnverifiedScheduleError",
    "VehicleCountError",
    "VerificationError",
]


class ScenarioError(InputError):
    """A scenario file is unreadable, malformed or inconsistent."""


class OutputError(InputError):
    """An output path cannot take the files asked for (a file where a folder must be, ...)."""


class OutputLimitError(OutputError):
    """An output would exceed a documented size limit (for example the rows of a CSV profile)."""


class ProfileFileError(InputError):
    """A profile file (CSV or cam table) cannot be read as its dialect says it is written."""


class UnverifiedScheduleError(TrajgenError, TypeError):
    """An exporter or plot was given a schedule that has not passed the verifier."""


class ScheduleError(TrajgenError, RuntimeError):
    """A schedule could not be computed."""


class VerificationError(ScheduleError):
    """A schedule failed the independent verifier and must not leave the library.

    The message says what is wrong in plain words (the quantity, its value and limit, the vehicle,
    when and where on the track); ``details`` holds where each failure lies in the schedule's arrays.

    Parameters
    ----------
    message : str
    details : sequence of str, optional
        Each failure followed by the arrays of the schedule it lies in
        (``sections[2].kinematics.vehicles[0].{times,initial,jerk} interval 4, ...``): for debugging,
        printed by ``trajgen --verbose``.

    Attributes
    ----------
    details : tuple of str
    """

    def __init__(self, message: str, *, details: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.details = tuple(details)


class SolverError(ScheduleError):
    """A numerical solver failed to deliver a usable result."""


class MissingExtraError(InputError):
    """A feature needs an optional part of the install (an extra, like ``trajgen[live]``) that is missing."""


class LiveError(TrajgenError, RuntimeError):
    """A live run over MQTT failed: the broker was unreachable, or the run did not end in time."""
