"""TOPPRA timing of a path in the plane of both vehicles' coordinates (shared by junctions and graphs).

TOPPRA (``toppra``, constant-acceleration parametrizer) gives the time-optimal velocity- and
acceleration-limited timing along a path of lines and quadratic blends. It enforces its
constraints at grid points; with the acceleration constraint discretized by interpolation and a grid
that contains every breakpoint, acceleration is linear in ``s`` between grid points. Speed on a
blend may bulge between grid points by a tiny amount, so TOPPRA plans with limits scaled by
:data:`HEADROOM`, and :func:`fit_to_limits` stretches a section in time until the limits hold
between grid points too.
"""

from __future__ import annotations

import logging

import numpy as np

from limits import Limits
from trajgen.errors import InputError, SolverError
from trajgen.model.blended import BlendedPath, ToppraKinematics
from trajgen.model.values import sorted_unique

__all__ = ["HEADROOM", "fit_to_limits", "toppra_kinematics"]

logger = logging.getLogger(__name__)

#: Fraction of the velocity and acceleration limits TOPPRA plans with.
HEADROOM = 1.0 - 1e-4


def toppra_kinematics(path: BlendedPath, limits: Limits, grid_points: int) -> ToppraKinematics:
    """TOPPRA's time-optimal velocity/acceleration-limited timing of ``path``, rest to rest.

    Parameters
    ----------
    path : BlendedPath
        Both vehicles' coordinates (axes or travel, metres) along a path of lines and blends.
    limits : Limits
        Each coordinate's velocity and acceleration limits are its vehicle's.
    grid_points : int
        TOPPRA's grid points, besides every breakpoint of the path.

    Raises
    ------
    SolverError
        TOPPRA found no parameterization.
    """
    import toppra
    import toppra.algorithm
    import toppra.constraint

    v = np.array([vehicle.max_velocity for vehicle in limits.vehicles]) * HEADROOM
    a = np.array([vehicle.max_acceleration for vehicle in limits.vehicles]) * HEADROOM
    velocity = toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v]))
    acceleration = toppra.constraint.JointAccelerationConstraint(
        np.column_stack([-a, a]), discretization_scheme=toppra.constraint.DiscretizationType.Interpolation
    )
    grid = sorted_unique(np.concatenate([np.linspace(0.0, path.length, grid_points), path.breakpoints]))
    instance = toppra.algorithm.TOPPRA(
        [velocity, acceleration], path, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    )
    instance.compute_parameterization(0.0, 0.0)
    data = instance.problem_data
    speed = None if data.sd_vec is None else np.asarray(data.sd_vec, dtype=float)
    if speed is None or not np.all(np.isfinite(speed)):
        raise SolverError(f"TOPPRA could not parameterize a section: return code {data.return_code}")
    grid = np.asarray(data.gridpoints, dtype=float)
    speed = np.maximum(speed, 0.0)
    speed[0] = speed[-1] = 0.0
    mean = 0.5 * (speed[1:] + speed[:-1])
    if np.any(mean <= 0.0):
        raise SolverError("TOPPRA returned a zero path velocity inside a section")
    times = np.concatenate([[0.0], np.cumsum(np.diff(grid) / mean)])
    try:
        return fit_to_limits(ToppraKinematics(path, grid, speed, times), limits)
    except InputError as error:  # e.g. two grid points at one time: TOPPRA's numbers, not the caller's
        raise SolverError(f"TOPPRA's timing of a section is not usable: {error}") from None


def fit_to_limits(kinematics: ToppraKinematics, limits: Limits) -> ToppraKinematics:
    """Stretch a TOPPRA section uniformly in time until it meets the limits between grid points too.

    Scaling time by ``c >= 1`` divides velocities by ``c`` and accelerations by ``c**2`` exactly.
    """
    # acceleration is linear in s within a grid interval: its extremes are at the interval ends,
    # which are sampled as one-sided limits (ends nudged inside)
    fine = np.array([0.0, 1.0 - 1e-9])
    times = (kinematics.times[:-1, None] + np.diff(kinematics.times)[:, None] * fine).ravel()
    values = kinematics.evaluate(times)
    peaks = kinematics.interior_velocity_peaks()
    ratio = 1.0
    for vehicle, vehicle_limits in enumerate(limits.vehicles):
        fastest = max(float(np.max(np.abs(values[vehicle, 1]))), float(peaks[vehicle]))
        ratio = max(
            ratio,
            fastest / vehicle_limits.max_velocity,
            float(np.sqrt(np.max(np.abs(values[vehicle, 2])) / vehicle_limits.max_acceleration)),
        )
    if ratio <= 1.0:
        return kinematics
    stretch = ratio * (1.0 + 1e-7)  # the dense samples bound the maxima to well within this
    logger.debug("TOPPRA section stretched in time by %.3g to meet the limits between grid points", stretch)
    return ToppraKinematics(
        kinematics.path, kinematics.grid, kinematics.speed / stretch, kinematics.times * stretch
    )
