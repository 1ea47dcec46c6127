"""One-dimensional motion profiles: closed-form rest-to-rest moves, piecewise cubics.

All quantities are SI: metres, seconds, m/s, m/s², m/s³.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from trajgen.errors import InputError
from trajgen.model.values import ArrayValue, readonly

__all__ = ["PiecewiseCubic", "rest_to_rest_time", "scurve_phases", "trapezoid_phases"]


def scurve_phases(distance: float, v_max: float, a_max: float, j_max: float) -> list[tuple[float, float]]:
    """Time-optimal rest-to-rest jerk-limited move, as constant-jerk phases.

    Parameters
    ----------
    distance : float
        Length of the move, metres, ``>= 0``.
    v_max, a_max, j_max : float
        Limits on ``|v|``, ``|a|``, ``|j|`` (m/s, m/s², m/s³), all ``> 0``.

    Returns
    -------
    list of (duration_s, jerk_mps3)
        Seven phases (some of zero duration): +j, 0, -j, cruise, -j, 0, +j.
        Empty for a zero distance.
    """
    if distance <= 0.0:
        return []
    # Velocity reached during the acceleration half, with its jerk and constant-acceleration times.
    if v_max * j_max >= a_max * a_max:  # a_max is reachable before v_max
        t_jerk, t_const = a_max / j_max, v_max / a_max - a_max / j_max
    else:
        t_jerk, t_const = math.sqrt(v_max / j_max), 0.0
    peak = v_max
    ramp_distance = peak * (2.0 * t_jerk + t_const)  # accelerate to v_max and back to rest
    if ramp_distance > distance:  # v_max is not reached: find the peak velocity
        if distance * j_max * j_max >= 2.0 * a_max**3:  # a_max still reached
            t_jerk = a_max / j_max
            peak = 0.5 * a_max * (-t_jerk + math.sqrt(t_jerk * t_jerk + 4.0 * distance / a_max))
            t_const = peak / a_max - t_jerk
        else:
            t_jerk = (0.5 * distance / j_max) ** (1.0 / 3.0)
            t_const = 0.0
            peak = j_max * t_jerk * t_jerk
        t_cruise = 0.0
    else:
        t_cruise = (distance - ramp_distance) / v_max
    t_const = max(t_const, 0.0)
    return [
        (t_jerk, j_max),
        (t_const, 0.0),
        (t_jerk, -j_max),
        (t_cruise, 0.0),
        (t_jerk, -j_max),
        (t_const, 0.0),
        (t_jerk, j_max),
    ]


def trapezoid_phases(distance: float, v_max: float, a_max: float) -> list[tuple[float, float]]:
    """Time-optimal rest-to-rest move with velocity and acceleration limits only.

    Returns
    -------
    list of (duration_s, acceleration_mps2)
        Constant-acceleration phases: +a, cruise, -a. Empty for zero distance.
    """
    if distance <= 0.0:
        return []
    if v_max * v_max / a_max >= distance:  # triangle: v_max not reached
        t_ramp = math.sqrt(distance / a_max)
        return [(t_ramp, a_max), (t_ramp, -a_max)]
    t_ramp = v_max / a_max
    return [(t_ramp, a_max), ((distance - v_max * t_ramp) / v_max, 0.0), (t_ramp, -a_max)]


def rest_to_rest_time(distance: float, v_max: float, a_max: float, j_max: float | None = None) -> float:
    """Duration of the time-optimal rest-to-rest move, seconds (no jerk limit if ``j_max`` is None)."""
    if j_max is None:
        return sum(d for d, _ in trapezoid_phases(distance, v_max, a_max))
    return sum(d for d, _ in scurve_phases(distance, v_max, a_max, j_max))


@dataclass(frozen=True, slots=True, eq=False)
class PiecewiseCubic(ArrayValue):
    """A trajectory ``p(t)`` whose jerk is constant between breakpoints.

    Attributes
    ----------
    times : ndarray, shape (m + 1,)
        Breakpoints, seconds, from 0 strictly increasing (``[0, 0]``: one interval of no
        time, at rest).
    initial : ndarray, shape (m, 3)
        Position (m), velocity (m/s) and acceleration (m/s²) at the start of
        each interval. Acceleration may jump at a breakpoint (trapezoids).
    jerk : ndarray, shape (m,)
        Jerk in each interval, m/s³.
    """

    times: np.ndarray
    initial: np.ndarray
    jerk: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "times", readonly(self.times, float))
        object.__setattr__(self, "initial", readonly(self.initial, float))
        object.__setattr__(self, "jerk", readonly(self.jerk, float))
        times = self.times
        if times.ndim != 1 or times.size < 2 or self.initial.shape != (times.size - 1, 3):
            raise InputError(
                f"piecewise cubic: times of shape {times.shape} and initial of shape {self.initial.shape}: "
                "expected (m + 1,) and (m, 3) with m >= 1"
            )
        if self.jerk.shape != (times.size - 1,):
            raise InputError(
                f"piecewise cubic: jerk of shape {self.jerk.shape}: expected ({times.size - 1},)"
            )
        for name in ("times", "initial", "jerk"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise InputError(f"piecewise cubic: {name} holds a non-finite value: expected finite numbers")
        if not (np.all(np.diff(times) > 0.0) or (times.size == 2 and times[1] == 0.0)):
            k = int(np.argmax(~(np.diff(times) > 0.0)))
            raise InputError(
                f"piecewise cubic: times do not increase at [{k + 1}] ({float(times[k])!r}, then "
                f"{float(times[k + 1])!r} s): expected strictly increasing knot times"
            )

    @classmethod
    def from_phases(
        cls, start: float, phases: list[tuple[float, float, float]], *, end: float | None = None
    ) -> PiecewiseCubic:
        """Integrate phases ``(duration, acceleration at phase start, jerk)`` from rest at ``start``.

        The acceleration at a phase start is taken from the phase when it is
        not NaN, else carried over from the previous phase (continuous).
        ``end``, if given, is the exact final position: the round-off of the
        integration is spread linearly in time so the profile ends there exactly.
        """
        times = [0.0]
        initial = []
        jerks = []
        p, v, a = start, 0.0, 0.0
        for duration, acceleration, jerk in phases:
            if duration <= 0.0:
                continue
            if not math.isnan(acceleration):
                a = acceleration
            initial.append((p, v, a))
            jerks.append(jerk)
            h = duration
            p, v, a = (
                p + h * (v + h * (a / 2.0 + h * jerk / 6.0)),
                v + h * (a + h * jerk / 2.0),
                a + h * jerk,
            )
            times.append(times[-1] + h)
        if not initial:  # no motion: one interval of zero length at rest
            return cls(np.array([0.0, 0.0]), np.array([[start, 0.0, 0.0]]), np.zeros(1))
        times_array = np.array(times)
        initial_array = np.array(initial)
        if end is not None and times_array[-1] > 0.0:
            drift = end - p  # round-off only: ~1e-15 relative
            initial_array[:, 0] += drift * times_array[:-1] / times_array[-1]
            initial_array[:, 1] += drift / times_array[-1]
        return cls(times_array, initial_array, np.array(jerks))

    @property
    def duration(self) -> float:
        """Total duration, seconds."""
        return float(self.times[-1])

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """Position, velocity, acceleration and jerk at times ``t``.

        Parameters
        ----------
        t : ndarray, shape (n,)
            Times in seconds; clipped to ``[0, duration]``.

        Returns
        -------
        ndarray, shape (4, n)
        """
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.times[-1])
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.jerk) - 1)
        h = t - self.times[k]
        p0, v0, a0 = self.initial[k, 0], self.initial[k, 1], self.initial[k, 2]
        j = self.jerk[k]
        return np.stack(
            [
                p0 + h * (v0 + h * (a0 / 2.0 + h * j / 6.0)),
                v0 + h * (a0 + h * j / 2.0),
                a0 + h * j,
                np.where(t >= self.times[-1], 0.0, j),  # no jerk once the motion has ended
            ]
        )

    def time_at(self, position: float) -> float:
        """The first time at which a monotone profile reaches ``position`` (metres), seconds.

        The profile must not reverse (its velocity keeps one sign); the
        position is clipped to the profile's range. Solved per interval by
        bisection on the cubic, to round-off.
        """
        nodes = np.append(self.initial[:, 0], self.end_state()[0])
        rising = nodes[-1] >= nodes[0]
        low, high = (nodes[0], nodes[-1]) if rising else (nodes[-1], nodes[0])
        target = min(max(float(position), low), high)
        ordered = nodes if rising else -nodes
        k = int(
            np.clip(
                np.searchsorted(ordered, target if rising else -target, side="left") - 1,
                0,
                len(self.jerk) - 1,
            )
        )
        p0, v0, a0 = self.initial[k]
        j = self.jerk[k]
        sign = 1.0 if rising else -1.0
        left, right = 0.0, float(self.times[k + 1] - self.times[k])
        for _ in range(100):
            middle = 0.5 * (left + right)
            value = p0 + middle * (v0 + middle * (a0 / 2.0 + middle * j / 6.0))
            if sign * (value - target) < 0.0:
                left = middle
            else:
                right = middle
        return float(self.times[k] + 0.5 * (left + right))

    def end_state(self) -> tuple[float, float, float]:
        """Position, velocity, acceleration at the end."""
        p, v, a, _ = self.evaluate(np.array([self.times[-1]]))[:, 0]
        return float(p), float(v), float(a)
