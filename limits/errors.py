"""Errors of the vehicle limits (re-exported by :mod:`trajgen.errors`)."""

from __future__ import annotations

from topology.errors import InputError

__all__ = ["LimitsError"]


class LimitsError(InputError):
    """A vehicle limit (velocity, acceleration, jerk) is not positive and finite."""
