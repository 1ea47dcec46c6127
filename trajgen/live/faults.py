"""Faults a simulated vehicle can be given: a stop of a while (``trajgen vehicle --fault stop@T+D``)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = ["StopFault"]

_FAULT = re.compile(r"stop@(?P<at>[^+]+)\+(?P<duration>.+)")


@dataclass(frozen=True, slots=True)
class StopFault:
    """The vehicle stops ``at`` seconds after it took its first order and stands ``duration`` seconds.

    It brakes as hard as its limits allow, then goes on. The time counts from the first order, as
    the run's does: a vehicle started long before the master stops at the same point of the run.
    """

    at: float
    duration: float

    @classmethod
    def parse(cls, text: str) -> StopFault:
        """Read ``stop@T+D`` (seconds).

        Raises
        ------
        InputError
            Not of that form, or T, D negative or not finite.
        """
        match = _FAULT.fullmatch(text.strip()) if isinstance(text, str) else None
        try:
            at, duration = (float(match["at"]), float(match["duration"])) if match else (math.nan, math.nan)
        except ValueError:
            at = duration = math.nan
        if not (math.isfinite(at) and math.isfinite(duration) and at >= 0.0 and duration >= 0.0):
            raise InputError(
                f"vehicle fault {short_repr(text)} cannot be read: expected stop@T+D with T, D seconds >= 0 "
                "(e.g. stop@12+3)"
            )
        return cls(at, duration)

    def active(self, t: float) -> bool:
        """Whether the vehicle is held ``t`` seconds after its first order."""
        return self.at <= t < self.at + self.duration
