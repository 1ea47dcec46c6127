"""Sections timed along a smoothed path: :class:`BlendedPath` and :class:`ToppraKinematics`.

The TOPPRA method (:mod:`trajgen.methods.toppra`) makes them; the model, the verifier and the
exports read them as one of the two closed kinds of section kinematics (with
:class:`~trajgen.model.schedule.CubicKinematics`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from trajgen.errors import InputError
from trajgen.model.schedule import Kinematics
from trajgen.model.values import ArrayValue, readonly

__all__ = ["Blend", "BlendedPath", "ToppraKinematics"]


@dataclass(frozen=True, slots=True, eq=False)
class Blend(ArrayValue):
    """A quadratic Bézier blend at a corner of a :class:`BlendedPath`, metres on the signed axes."""

    before: np.ndarray  # shape (2,): where the blend leaves the incoming line
    corner: np.ndarray  # shape (2,): Bézier control point (the route's corner)
    after: np.ndarray  # shape (2,): where it joins the outgoing line

    def __post_init__(self) -> None:
        for name in ("before", "corner", "after"):
            object.__setattr__(self, name, readonly(getattr(self, name), float))

    def points(self, w: np.ndarray) -> np.ndarray:
        """Bézier points for w in [0, 1], shape (n, 2)."""
        w = w[:, None]
        return (1 - w) ** 2 * self.before + 2 * w * (1 - w) * self.corner + w**2 * self.after


@dataclass(frozen=True, slots=True, eq=False)
class BlendedPath(ArrayValue):
    """A C1 path in the axis plane: straight lines joined by quadratic Bézier blends.

    Parameterized by ``s`` (metres): on lines ``s`` is arc length; a blend of
    half-size ``r`` spans ``2 r`` of ``s`` so that ``|dq/ds| = 1`` at its ends.
    Implements the interface TOPPRA expects of a geometric path.

    Parameters
    ----------
    vertices : ndarray, shape (m, 2)
        Corners of the polyline on the signed axes, metres.
    blends : tuple of (blend or None), shape (m,)
        The blend at each vertex (``None``: a sharp corner; first and last are ``None``).
    """

    vertices: np.ndarray
    blends: tuple
    length: float = field(init=False, compare=False)
    breakpoints: np.ndarray = field(init=False, compare=False, repr=False)
    _starts: np.ndarray = field(init=False, compare=False, repr=False)
    _p0: np.ndarray = field(init=False, compare=False, repr=False)
    _d1: np.ndarray = field(init=False, compare=False, repr=False)
    _d2: np.ndarray = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        vertices = readonly(self.vertices, float)
        if not np.all(np.isfinite(vertices)):
            raise InputError("blended path: vertices hold a non-finite value: expected finite numbers")
        blends = tuple(self.blends)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "blends", blends)
        # pieces: lines (p0, unit direction, 0) and blends (before, dq/ds at start, d2q/ds2)
        starts, p0, d1, d2 = [0.0], [], [], []
        s = 0.0
        point = vertices[0]
        for k in range(1, len(vertices)):
            blend = blends[k] if k < len(vertices) - 1 else None
            target = blend.before if blend is not None else vertices[k]
            length = float(np.linalg.norm(target - point))
            if length > 0.0:
                p0.append(point)
                d1.append((target - point) / length)
                d2.append(np.zeros(vertices.shape[1]))
                s += length
                starts.append(s)
            if blend is not None:
                size = 2.0 * float(np.linalg.norm(blend.corner - blend.before))
                # q(w) = before + 2w(P - before) + w^2 (before - 2P + after), w = (s - s0) / size
                p0.append(blend.before)
                d1.append(2.0 * (blend.corner - blend.before) / size)
                d2.append(2.0 * (blend.before - 2.0 * blend.corner + blend.after) / size**2)
                s += size
                starts.append(s)
                point = blend.after
            else:
                point = target
        object.__setattr__(self, "_starts", readonly(starts[:-1]))
        object.__setattr__(self, "_p0", readonly(p0))
        object.__setattr__(self, "_d1", readonly(d1))
        object.__setattr__(self, "_d2", readonly(d2))
        object.__setattr__(self, "length", s)
        object.__setattr__(self, "breakpoints", readonly(starts))

    # TOPPRA's geometric path interface
    @property
    def dof(self) -> int:
        """Degrees of freedom: one coordinate per vehicle (its signed axis or its travel)."""
        return int(self.vertices.shape[1])

    @property
    def path_interval(self) -> np.ndarray:
        """``[0, length]``, metres."""
        return np.array([0.0, self.length])

    @property
    def waypoints(self):
        """Breakpoints and the points there."""
        return self.breakpoints, self(self.breakpoints)

    def piece(self, ss: np.ndarray) -> np.ndarray:
        """Index of the piece (line or blend) holding each path position, shape (n,)."""
        return np.clip(np.searchsorted(self._starts, ss, side="right") - 1, 0, len(self._starts) - 1)

    def __call__(self, ss, order: int = 0) -> np.ndarray:
        """Derivative ``order`` of the path at ``ss`` (metres), shape (n, 2) or (2,) for a scalar."""
        scalar = np.isscalar(ss)
        ss = np.clip(np.atleast_1d(np.asarray(ss, dtype=float)), 0.0, self.length)
        out = self.on_piece(self.piece(ss), ss, order)
        return out[0] if scalar else out

    def on_piece(self, k: np.ndarray, ss: np.ndarray, order: int) -> np.ndarray:
        """Derivative ``order`` at ``ss`` using the polynomial of piece ``k`` (one-sided at its ends)."""
        h = (ss - self._starts[k])[:, None]
        if order == 0:
            out = self._p0[k] + h * self._d1[k] + 0.5 * h * h * self._d2[k]
        elif order == 1:
            out = self._d1[k] + h * self._d2[k]
        elif order == 2:
            out = np.broadcast_to(self._d2[k], (ss.size, self.dof)).copy()
        else:
            out = np.zeros((ss.size, self.dof))
        return out

    def eval(self, ss):
        """Points at ``ss``, shape (n, 2)."""
        return self(ss, 0)

    def evald(self, ss):
        """First derivatives at ``ss``, shape (n, 2)."""
        return self(ss, 1)

    def evaldd(self, ss):
        """Second derivatives at ``ss``, shape (n, 2)."""
        return self(ss, 2)


@dataclass(frozen=True, slots=True, eq=False)
class ToppraKinematics(ArrayValue, Kinematics):
    """A section timed by TOPPRA: ``s(t)`` piecewise quadratic between grid points.

    Attributes
    ----------
    path : BlendedPath
    grid : ndarray, shape (m,)
        Path positions of TOPPRA's grid, metres.
    speed : ndarray, shape (m,)
        Path velocity ``ds/dt`` at the grid points, m/s.
    times : ndarray, shape (m,)
        Time at each grid point, seconds (constant ``d²s/dt²`` in between).
    """

    path: BlendedPath
    grid: np.ndarray
    speed: np.ndarray
    times: np.ndarray

    def __post_init__(self) -> None:
        for name in ("grid", "speed", "times"):
            object.__setattr__(self, name, readonly(getattr(self, name), float))
            if not np.all(np.isfinite(getattr(self, name))):
                raise InputError(f"TOPPRA section: {name} holds a non-finite value: expected finite numbers")
        if not np.all(np.diff(self.times) > 0.0):
            raise InputError("TOPPRA section: knot times do not increase: expected strictly increasing times")

    @property
    def duration(self) -> float:
        """Length of the section, seconds."""
        return float(self.times[-1])

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """Axis, velocity, acceleration, jerk of both vehicles; shape (2, 4, n)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.times[-1])
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.grid) - 2)
        ds = np.diff(self.grid)
        accel = (self.speed[1:] ** 2 - self.speed[:-1] ** 2) / (2.0 * ds)
        h = t - self.times[k]
        s = self.grid[k] + h * (self.speed[k] + 0.5 * h * accel[k])
        sd = self.speed[k] + h * accel[k]
        sdd = accel[k]
        at_end = t >= self.times[-1]
        s = np.where(at_end, self.grid[-1], np.minimum(s, self.grid[k + 1]))
        sd = np.where(at_end, 0.0, sd)
        sdd = np.where(at_end, 0.0, sdd)
        # every path breakpoint is a grid point, so grid interval k lies in one path piece:
        # evaluate with that piece, so the end of an interval is its one-sided limit
        piece = self.path.piece(np.minimum(self.grid[k], self.grid[-1]))
        piece = np.where(at_end, self.path.piece(np.array([self.grid[-2]]))[0], piece)
        q = self.path.on_piece(piece, s, 0)
        dq = self.path.on_piece(piece, s, 1)
        ddq = self.path.on_piece(piece, s, 2)
        out = np.empty((self.path.dof, 4, t.size))
        out[:, 0] = q.T
        out[:, 1] = (dq * sd[:, None]).T
        out[:, 2] = (ddq * (sd * sd)[:, None] + dq * sdd[:, None]).T
        out[:, 3] = (3.0 * ddq * (sd * sdd)[:, None]).T  # within intervals; unbounded at switch points
        return out

    def interior_velocity_peaks(self) -> np.ndarray:
        """Largest |velocity| of each vehicle strictly inside the grid intervals, shape (2,), m/s.

        In grid interval ``k``, at ``x = s - s_k``, a vehicle's velocity is
        ``(A + B x) sqrt(C + D x)`` (``dq/ds`` is linear on a line or blend, ``(ds/dt)^2``
        is linear in ``s`` at constant ``d²s/dt²``); it is stationary at
        ``x* = -(2 B C + D A) / (3 B D)``. Sampling instead misses such a peak by up to
        ``|v''| dt^2 / 8``, more than the verifier's tolerance on long intervals.
        """
        grid, speed, path = self.grid, self.speed, self.path
        width = np.diff(grid)
        piece = path.piece(grid[:-1])
        slope = path.on_piece(piece, grid[:-1], 1)  # A, shape (m - 1, 2)
        bend = path.on_piece(piece, grid[:-1], 2)  # B
        squared = (speed[:-1] ** 2)[:, None]  # C
        growth = ((speed[1:] ** 2 - speed[:-1] ** 2) / width)[:, None]  # D
        with np.errstate(divide="ignore", invalid="ignore"):
            x = -(2.0 * bend * squared + growth * slope) / (3.0 * bend * growth)
        inside = np.isfinite(x) & (x > 0.0) & (x < width[:, None])
        x = np.where(inside, x, 0.0)
        velocity = (slope + bend * x) * np.sqrt(np.maximum(squared + growth * x, 0.0))
        return np.max(np.where(inside, np.abs(velocity), 0.0), axis=0, initial=0.0)
