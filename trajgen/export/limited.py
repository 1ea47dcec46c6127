"""The limited columns of a generic CSV (velocity, acceleration, jerk), held to their limits as written.

A verified schedule keeps its limits to the verifier's round-off
(:data:`~trajgen.verification.RELATIVE_TOLERANCE`, 1e-6 of the limit): a velocity of 1.2 m/s may
be 1.2000000061 m/s, written 1.200000006. Written, such a number would exceed its limit to a
strict reader; it is written as the largest number of the file's decimals at most the limit
instead (:func:`~trajgen.export.numbers.within_limit`). Positions are not touched: the change is
below the round-off every check of the file allows.
"""

from __future__ import annotations

import numpy as np

from limits import VehicleLimits
from trajgen.export.numbers import within_limit
from trajgen.verification import RELATIVE_TOLERANCE

__all__ = ["limited_columns"]


def limited_columns(
    state, vehicle: int, scale: float, decimals: int, limits: VehicleLimits | None, jerk_limited: bool
) -> list[np.ndarray]:
    """A vehicle's velocity, acceleration and jerk in the file's unit, each held to its limit as written.

    With ``limits``, a value above its limit by no more than the verifier's round-off
    (:data:`~trajgen.verification.RELATIVE_TOLERANCE`) is written as the largest number of
    ``decimals`` places at most the limit (:func:`~trajgen.export.numbers.within_limit`): the jerk
    only if ``jerk_limited``. Without ``limits`` (executed motion) the values are as given.

    Parameters
    ----------
    state : ScheduleState or GraphState
        Both vehicles at n sample times (``velocity``, ``acceleration``, ``jerk``: m/s, m/s^2, m/s^3).
    vehicle : int
        0 or 1.
    scale : float
        Multiplier from metres to the file's length unit.
    decimals : int
        Decimal places the columns are written with.
    limits : VehicleLimits or None
        The vehicle's limits (SI units).
    jerk_limited : bool
        Whether the schedule limits jerk (else its jerk column states no limit and is left as it is).

    Returns
    -------
    list of 3 ndarray, shape (n,)
        Velocity, acceleration and jerk in the file's units.
    """
    quantities = [
        (state.velocity[vehicle] * scale, "max_velocity"),
        (state.acceleration[vehicle] * scale, "max_acceleration"),
        (state.jerk[vehicle] * scale, "max_jerk"),
    ]
    if limits is None:
        return [values for values, _ in quantities]
    held = []
    for values, name in quantities:
        if name != "max_jerk" or jerk_limited:
            limit = getattr(limits, name) * scale
            values = within_limit(values, limit, decimals, tolerance=RELATIVE_TOLERANCE)
        held.append(values)
    return held
