"""Track distance and regions over arrays of sampled positions (for schedules and plots).

Positions are given as leg index arrays (``-1`` at the junction) and distance
from the junction, as :class:`~trajgen.schedule.ScheduleState` holds them. The
definitions are the planner's: :meth:`~topology.graph.YGraph.distance` and the
regions of ALGORITHM.md section 6.
"""

from __future__ import annotations

import numpy as np

from topology.route import _region_key

__all__ = ["region_keys", "track_distance"]


def track_distance(leg_a, s_a, leg_b, s_b) -> np.ndarray:
    """Track distance between positions a and b, metres (arrays broadcast).

    Same leg: ``|s_a - s_b|``; different legs or either at the junction: ``s_a + s_b``.
    """
    leg_a, s_a, leg_b, s_b = (np.asarray(x) for x in (leg_a, s_a, leg_b, s_b))
    same = (leg_a == leg_b) & (leg_a >= 0)
    return np.where(same, np.abs(s_a - s_b), s_a + s_b)


def region_keys(leg1, s1, leg2, s2) -> list:
    """Region of each sampled configuration as ``(leg1, leg2, nearer)``; ``None`` on a ray.

    Parameters
    ----------
    leg1, s1, leg2, s2 : array_like, shape (n,)
        Leg indices (-1 at the junction) and distances of vehicle 1 and vehicle 2.
    """
    return [
        _region_key(a, x, b, y)
        for a, x, b, y in zip(
            np.asarray(leg1).tolist(),
            np.asarray(s1).tolist(),
            np.asarray(leg2).tolist(),
            np.asarray(s2).tolist(),
            strict=True,
        )
    ]
