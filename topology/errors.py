"""The planner's errors: the base of every error of the distribution, and bad input.

:mod:`trajgen.errors` re-exports these with the errors of the limits and of the
schedules: it is the one public exception module. Each class subclasses the
fitting built-in (``ValueError`` for bad input), so callers may catch either
the built-in or :class:`TrajgenError`. Messages name the quantity, the value
received and what was expected.
"""

from __future__ import annotations

__all__ = [
    "InfeasibleError",
    "InputError",
    "OptionError",
    "PositionError",
    "SeparationError",
    "TrackError",
    "TrajgenError",
    "VehicleCountError",
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


class OptionError(InputError):
    """A string option is not one of the accepted names."""


class InfeasibleError(InputError):
    """No collision-free route exists: the vehicles cannot reach their goals keeping the separation.

    An answer about the scenario, not a failure of the planner: raised before any timing, it is
    bad input to the command line (exit 2).
    """


class VehicleCountError(InputError):
    """A planner was given a number of vehicles it does not plan for (the planners take two, today)."""
