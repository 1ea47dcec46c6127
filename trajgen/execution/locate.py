"""Where a measured vehicle stands along its path: its travel, velocity and acceleration along it.

The executor's measurements (:class:`~trajgen.execution.executor.Executor`) are places on the track
(a leg or an edge, metres along it) and signed rates along the vehicle's axis; its frontiers and
motions are in travel along the vehicle's path, which never runs back. A place a path passes twice
(either side of a reversal) is read as the later one only once the vehicle has turned there.
"""

from __future__ import annotations

import bisect

from trajgen.execution.braking_check import PathState

__all__ = ["locate_on_path", "not_yet_reversed"]


def not_yet_reversed(path, p: float, last: float, slack: float) -> float:
    """``p``, or the same place before the reversal just behind it if the vehicle has not turned there yet.

    Either side of a reversal, travel ``c - x`` and ``c + x`` are one place. A vehicle that was
    before ``c`` in the last cycle (travel ``last``) and is not moving away from the tip now (a
    lagging drive still approaching it, or resting short of it) is still before it: reading it as
    past the tip would move its earliest rest point, and its follower's frontier, back.

    Parameters
    ----------
    path : VehiclePath or GraphVehiclePath
    p, last, slack : float
        The travel read now, the travel of the last cycle and how far a reading may stray, metres.
    """
    k = bisect.bisect_right(path.stops, p) - 1
    if k < 0:
        return p
    tip = path.stops[k]
    mirrored = 2.0 * tip - p
    before = path.stops[k - 1] if k else 0.0
    if last < tip < p <= tip + slack and mirrored >= before:
        return mirrored
    return p


def locate_on_path(track, path, measured, near: float, last: float, slack: float) -> PathState | None:
    """A measured state in travel coordinates along ``path``, or ``None`` if it is off the path.

    Parameters
    ----------
    track : ExecutionTrack
        The track's projections (:func:`~trajgen.execution.tracks.execution_track`).
    path : VehiclePath or GraphVehiclePath
    measured : VehicleState
    near : float
        The travel of the vehicle's last setpoint, metres: the reading nearest it is taken.
    last : float
        The vehicle's travel read in the last cycle, metres.
    slack : float
        How far a reading may stray from ``near``, metres (tolerance and margin).
    """
    # next to a reversal one place is on the path twice: travel never runs back, so the later
    p = track.project(path, measured.leg, measured.s, near + slack, slack)
    if p is None or abs(p - near) > slack:
        p = track.project(path, measured.leg, measured.s, near, slack)
    if p is None:
        return None
    p = min(max(p, 0.0), path.length)
    heading = path.heading(p)
    if heading * measured.velocity <= 0.0:
        p = not_yet_reversed(path, p, last, slack)
        heading = path.heading(p)
    return PathState(p, heading * measured.velocity, heading * measured.acceleration)
