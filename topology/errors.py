"""The one exception module of the ``trajgen`` distribution.

Every error the packages ``topology``, ``limits`` and ``trajgen`` raise on
purpose is one of these classes. Each subclasses the fitting built-in
(``ValueError`` for bad input, ``RuntimeError`` for a computation that could
not deliver), so callers may catch either the built-in or :class:`TrajgenError`.
Messages name the quantity, the value received and what was expected.
"""

from __future__ import annotations

__all__ = [
    "InputError",
    "LimitsError",
    "OptionError",
    "PositionError",
    "ScenarioError",
    "ScheduleError",
    "SeparationError",
    "SolverError",
    "TrackError",
    "TrajgenError",
    "VerificationError",
]


class TrajgenError(Exception):
    """Base class of every error raised on purpose by trajgen."""


class InputError(TrajgenError, ValueError):
    """Bad input: a value of the wrong type, out of range or inconsistent."""


class TrackError(InputError):
    """The track (legs, lengths, angles) is not a valid Y."""


class PositionError(InputError):
    """A position is not on the track (unknown leg, ``s`` out of range, NaN)."""


class SeparationError(InputError):
    """A minimum separation is out of range, or vehicles are closer than it."""


class LimitsError(InputError):
    """A vehicle limit (velocity, acceleration, jerk) is not positive and finite."""


class OptionError(InputError):
    """A string option is not one of the accepted names."""


class ScenarioError(InputError):
    """A scenario file is unreadable, malformed or inconsistent."""


class ScheduleError(TrajgenError, RuntimeError):
    """A schedule could not be computed."""


class VerificationError(ScheduleError):
    """A schedule failed the independent verifier and must not leave the library."""


class SolverError(ScheduleError):
    """A numerical solver failed to deliver a usable result."""
