"""Validation of the numbers that reach the planner and the limits."""

from __future__ import annotations

import math
from numbers import Real

from topology.errors import VehicleCountError

__all__ = ["PLANNED_VEHICLES", "check_vehicle_count", "finite_real", "short_repr"]

#: How many vehicles the planners take: the paper's on a junction and the roadmap's on a track graph
#: plan two. Everything below the planners takes any number (the count is data).
PLANNED_VEHICLES = 2


def finite_real(value: object, quantity: str, error: type[Exception]) -> float:
    """Return ``value`` as a float if it is a finite real number, else raise ``error``.

    Parameters
    ----------
    value : object
        The value to check; ``bool`` is not accepted as a number.
    quantity : str
        Name of the quantity with its unit, for the message.
    error : type of Exception
        The exception class raised, with a message naming ``quantity`` and the value.

    Returns
    -------
    float

    Examples
    --------
    >>> finite_real(2, "length (metres)", ValueError)
    2.0
    """
    if type(value) is float and math.isfinite(value):
        return value
    if isinstance(value, bool) or not isinstance(value, Real):
        raise error(f"{quantity} must be a real number, got {short_repr(value)} ({type(value).__name__})")
    number = float(value)
    if not math.isfinite(number):
        raise error(f"{quantity} must be finite, got {number!r}")
    return number


def short_repr(value: object, limit: int = 60) -> str:
    """``repr`` of a value, cut to ``limit`` characters: what error messages quote.

    Examples
    --------
    >>> short_repr("x" * 100, 12)
    "'xxxxxxxx..."
    """
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_vehicle_count(count: int, planner: str, *, source: str | None = None) -> None:
    """Refuse a number of vehicles the planners do not plan for.

    Raises
    ------
    VehicleCountError
        ``count`` is not :data:`PLANNED_VEHICLES`; the message names ``planner`` (and ``source``,
        the file the vehicles come from, first).

    Examples
    --------
    >>> check_vehicle_count(2, "the junction planner")
    """
    if count != PLANNED_VEHICLES:
        where = "" if source is None else f"{source}: "
        raise VehicleCountError(
            f"{where}{planner} plans exactly {PLANNED_VEHICLES} vehicles, got {count}: expected two "
            "[[vehicle]] tables (planning more vehicles is to come)"
        )
