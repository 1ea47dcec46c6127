"""Validation of the numbers that reach the planner and the limits."""

from __future__ import annotations

import math
from numbers import Real

__all__ = ["finite_real", "short_repr"]


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
