"""Mutants of valid schedules: defects placed between the verifier's samples, for the mutation tests."""

from __future__ import annotations

import dataclasses

import numpy as np

from tests.support.corruption import corrupted
from trajgen import Schedule
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import CubicKinematics

#: A uniform cubic B-spline of knot spacing h: position, velocity, acceleration at its 5 knots
#: (times h^0, h^-1, h^-2) and its jerk on its 4 intervals (times h^-3); scaled by 1.5 it peaks at 1.
_KNOT_P = np.array([0.0, 1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0])
_KNOT_V = np.array([0.0, 0.5, 0.0, -0.5, 0.0])
_KNOT_A = np.array([0.0, 1.0, -2.0, 1.0, 0.0])
_JERK = np.array([1.0, -3.0, 3.0, -1.0])


def with_bump(schedule: Schedule, vehicle: int, start: float, width: float, height: float) -> Schedule:
    """``schedule`` with a smooth bump of ``height`` metres on one vehicle's axis, on [start, start + width].

    The bump is a cubic B-spline: position, velocity and acceleration return to the original
    after it, so only what happens inside the window (which can lie between two samples) changes.
    Its velocity peak is ``height / (width / 4)``.
    """
    index = next(
        k for k, s in enumerate(schedule.sections) if s.start_time <= start < s.start_time + s.duration
    )
    section = schedule.sections[index]
    profile = section.kinematics.vehicles[vehicle]
    h = width / 4.0
    local = start - section.start_time
    knots = local + h * np.arange(5)
    times = np.unique(np.concatenate([profile.times, knots]))
    values = profile.evaluate(times[:-1])  # (4, m): p, v, a, j of the original at each new interval start
    scale = 1.5 * height
    bump_p = np.interp(times[:-1], knots, _KNOT_P * scale, left=0.0, right=0.0)
    bump_v = np.interp(times[:-1], knots, _KNOT_V * scale / h, left=0.0, right=0.0)
    bump_a = np.interp(times[:-1], knots, _KNOT_A * scale / h**2, left=0.0, right=0.0)
    inside = (times[:-1] >= knots[0]) & (times[:-1] < knots[-1])
    on_knot = np.isin(times[:-1], knots)
    if not np.all(on_knot[inside]):
        raise ValueError("the bump window must not contain a breakpoint of the profile")
    jerk = values[3].copy()
    which = np.clip(np.searchsorted(knots, times[:-1], side="right") - 1, 0, 3)
    jerk = np.where(inside, jerk + _JERK[which] * scale / h**3, jerk)
    initial = np.column_stack([values[0] + bump_p, values[1] + bump_v, values[2] + bump_a])
    mutated = PiecewiseCubic(times, initial, jerk)
    vehicles = list(section.kinematics.vehicles)
    vehicles[vehicle] = mutated
    changed = dataclasses.replace(section, kinematics=CubicKinematics(tuple(vehicles)))
    return dataclasses.replace(
        schedule, sections=(*schedule.sections[:index], changed, *schedule.sections[index + 1 :])
    )


def between_samples(schedule: Schedule, near: float, period: float = 1e-3) -> float:
    """A time just after the verifier's sample before ``near``: a 0.8-period window fits before the next."""
    duration = schedule.duration
    count = max(int(np.ceil(duration / period)), 1)
    grid = np.linspace(0.0, duration, count + 1)
    k = int(np.clip(np.searchsorted(grid, near) - 1, 0, count - 1))
    return float(grid[k] + 0.1 * (grid[k + 1] - grid[k]))


def free_window(
    schedule: Schedule, vehicle: int, near: float, width: float = 0.8e-3, period: float = 1e-3
) -> float:
    """Start of a window of ``width`` between two samples near ``near``, free of the vehicle's breakpoints."""
    duration = schedule.duration
    count = max(int(np.ceil(duration / period)), 1)
    grid = np.linspace(0.0, duration, count + 1)
    centre = int(np.clip(np.searchsorted(grid, near) - 1, 0, count - 1))
    for offset in range(count):
        for k in (centre + offset, centre - offset):
            if not 0 <= k < count:
                continue
            start = float(grid[k] + 0.1 * (grid[k + 1] - grid[k]))
            section = next(
                (
                    s
                    for s in schedule.sections
                    if s.start_time <= start and start + width < s.start_time + s.duration
                ),
                None,
            )
            if section is None:
                continue
            local = np.asarray(section.kinematics.vehicles[vehicle].times) + section.start_time
            if not np.any((local > start) & (local < start + width)):
                return start
    raise ValueError("no free window")


def with_coefficient(schedule: Schedule, vehicle: int, column: int, value: float) -> tuple[Schedule, str]:
    """One initial-state coefficient (0 position, 1 velocity, 2 acceleration) of section 0 replaced.

    The constructors refuse non-finite numbers, so the array is replaced behind them
    (:func:`tests.support.corruption.corrupted`), as a bug or a stray write would. Returns the
    schedule and the path of the entry replaced (``sections[0]...initial[3, 1]``).
    """
    path = f"sections[0].kinematics.vehicles[{vehicle}].initial"
    initial = np.array(schedule.sections[0].kinematics.vehicles[vehicle].initial)
    row = len(initial) // 2
    initial[row, column] = value
    return corrupted(schedule, path, initial), f"{path}[{row}, {column}]"
