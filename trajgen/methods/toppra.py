"""The ``toppra`` method: round the route's corners where safe, then TOPPRA timing.

In the plane of the two signed axes the route is a polyline. Where it turns
without any vehicle reversing, the corner is replaced by a quadratic Bézier
blend, as large as half of each adjacent piece, shrunk until the blend keeps
the separation (with a margin that covers the gaps between its samples) and
visits the same regions as the corner. Corners that cannot be rounded (a
vehicle reverses, or no blend is safe) are stops; between stops TOPPRA
(``toppra``, constant-acceleration parametrizer) gives the time-optimal
velocity- and acceleration-limited timing. Jerk is not limited.

TOPPRA enforces its constraints at grid points; with the acceleration
constraint discretized by interpolation and a grid that contains every blend
boundary, acceleration is linear in ``s`` between grid points. Speed on a blend
may bulge between grid points by a tiny amount, so TOPPRA plans with limits
scaled by :data:`HEADROOM`. A section whose TOPPRA timing would be slower than
the closed-form rest-to-rest trapezoids of its pieces (possible only through
the headroom) takes the trapezoids, so ``toppra`` is never slower than
``exact`` without jerk limits.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import Route, reduce_regions
from topology.indexed import region_keys, track_distance
from trajgen.errors import InputError, SolverError
from trajgen.methods.exact import Exact
from trajgen.model.axes import RouteAxes, piece_maps, piece_profiles, route_axes, straight_pieces
from trajgen.model.schedule import (
    AxisMap,
    CubicKinematics,
    FallbackReason,
    Kinematics,
    Schedule,
    Section,
    TimingMethod,
    check_request,
)
from trajgen.model.values import ArrayValue, readonly, sorted_unique
from trajgen.verification import verify

__all__ = ["HEADROOM", "BlendedPath", "Toppra", "ToppraKinematics"]

logger = logging.getLogger(__name__)

#: Fraction of the velocity and acceleration limits TOPPRA plans with.
HEADROOM = 1.0 - 1e-4
#: Blend sizes tried, as fractions of the largest possible one.
_BLEND_FRACTIONS = (1.0, 0.5, 0.25, 0.125)
_BLEND_SAMPLES = 256


@dataclass(frozen=True, slots=True, eq=False)
class _Blend(ArrayValue):
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
                d2.append(np.zeros(2))
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
        """Degrees of freedom: the two signed axes."""
        return 2

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
            out = np.broadcast_to(self._d2[k], (ss.size, 2)).copy()
        else:
            out = np.zeros((ss.size, 2))
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
        out = np.empty((2, 4, t.size))
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


def _reverses(incoming: np.ndarray, outgoing: np.ndarray) -> bool:
    return bool(np.any(incoming * outgoing < 0.0))


def _locate_both(maps: tuple[AxisMap, AxisMap], points: np.ndarray):
    leg1, s1 = maps[0].locate(points[:, 0])
    leg2, s2 = maps[1].locate(points[:, 1])
    return leg1, s1, leg2, s2


def _regions(leg1, s1, leg2, s2) -> tuple:
    return reduce_regions(region_keys(leg1, s1, leg2, s2))


def _safe_blend(
    axes: RouteAxes, pieces: list[tuple[int, int]], corner: int, required: float
) -> _Blend | None:
    """The largest safe blend at the corner between pieces ``corner - 1`` and ``corner``."""
    (first, middle), (_, last) = pieces[corner - 1], pieces[corner]
    points = axes.axes
    p = points[middle]
    incoming, outgoing = p - points[first], points[last] - p
    if _reverses(incoming, outgoing):
        return None
    len_in, len_out = float(np.linalg.norm(incoming)), float(np.linalg.norm(outgoing))
    maps = piece_maps(axes, first, last)
    w = np.linspace(0.0, 1.0, _BLEND_SAMPLES + 1)
    for fraction in _BLEND_FRACTIONS:
        r = 0.5 * fraction * min(len_in, len_out)
        blend = _Blend(p - r * incoming / len_in, p, p + r * outgoing / len_out)
        curve = blend.points(w)
        spacing = float(np.max(np.linalg.norm(np.diff(curve, axis=0), axis=1)))
        located = _locate_both(maps, curve)
        # between samples the separation changes by at most |da1| + |da2| <= sqrt(2) * spacing
        if np.min(track_distance(*located)) < required + 1.5 * spacing:
            continue
        polyline = np.concatenate(
            [blend.before + np.outer(w, p - blend.before), p + np.outer(w, blend.after - p)]
        )
        if _regions(*located) != _regions(*_locate_both(maps, polyline)):
            continue
        return blend
    return None


def _toppra_section(path: BlendedPath, limits: Limits, grid_points: int) -> ToppraKinematics:
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
    return _fit_to_limits(ToppraKinematics(path, grid, speed, times), limits)


def _groups(axes: RouteAxes, pieces: list[tuple[int, int]], blends: list[_Blend | None]):
    """Runs of pieces joined by rounded corners, as (first piece, end piece) index ranges.

    A run never contains a reversal of either vehicle (even across a piece in
    which that vehicle stands still): within a section each vehicle's axis is
    monotone, so it maps onto the track one-to-one.
    """
    start = 0
    heading = np.sign(axes.axes[pieces[0][1]] - axes.axes[pieces[0][0]])
    for corner in range(1, len(pieces)):
        step = np.sign(axes.axes[pieces[corner][1]] - axes.axes[pieces[corner][0]])
        if blends[corner] is None or np.any(heading * step < 0):
            yield start, corner
            start = corner
            heading = step
        else:
            heading = np.where(heading == 0, step, heading)
    yield start, len(pieces)


def _fit_to_limits(kinematics: ToppraKinematics, limits: Limits) -> ToppraKinematics:
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


def _toppra_schedule(method: Toppra, route: Route, limits: Limits) -> Schedule:
    """Round corners where safe, then time each stop-to-stop section with TOPPRA."""
    grid_points = method.grid_points
    axes = route_axes(route)
    pieces = straight_pieces(axes.axes)
    if not pieces:  # nothing moves
        schedule = Exact(jerk=False).schedule(route, limits)
        return Schedule(route, limits, method, schedule.sections, jerk_limited=False)
    required = max(limits.min_separation, route.min_separation)
    blends: list[_Blend | None] = [None] + [
        _safe_blend(axes, pieces, corner, required) for corner in range(1, len(pieces))
    ]
    sections: list[Section] = []
    clock = 0.0
    rounded = toppra_sections = 0
    failed: list[str] = []
    for start, stop in _groups(axes, pieces, blends):
        group = pieces[start:stop]
        trapezoids = [
            CubicKinematics(piece_profiles(axes.axes[a], axes.axes[b], limits, jerk=False)) for a, b in group
        ]
        timed = None
        if len(group) > 1:
            vertices = axes.axes[[group[0][0]] + [b for _, b in group]]
            path = BlendedPath(vertices, (None, *blends[start + 1 : stop], None))
            try:
                timed = _toppra_section(path, limits, grid_points)
            except SolverError as error:  # keep this section's stops, flagged in the notes
                logger.warning("TOPPRA failed on a section, its corners are stops: %s", error)
                failed.append(str(error))
            if timed is not None and timed.duration >= sum(k.duration for k in trapezoids):
                logger.info("TOPPRA section is not faster than stopping at its corners; keeping the stops")
                timed = None
        if timed is not None:
            sections.append(Section(clock, timed, piece_maps(axes, group[0][0], group[-1][1])))
            clock += timed.duration
            rounded += len(group) - 1
            toppra_sections += 1
        else:
            for (first, last), kinematics in zip(group, trapezoids, strict=True):
                sections.append(Section(clock, kinematics, piece_maps(axes, first, last)))
                clock += kinematics.duration
    notes = (
        f"{rounded} of {len(pieces) - 1} corners rounded; {toppra_sections} section(s) timed by TOPPRA",
        "jerk is not limited by this method",
        *(f"TOPPRA failed on a section ({reason}); its corners are stops" for reason in failed),
    )
    logger.info("toppra schedule: %s", notes[0])
    return Schedule(route, limits, method, tuple(sections), jerk_limited=False, notes=notes)


@dataclass(frozen=True, slots=True)
class Toppra(TimingMethod):
    """Corners rounded where safe, then TOPPRA's time-optimal velocity/acceleration-limited timing.

    Jerk is not limited. Never slower than ``Exact(jerk=False)``.

    Parameters
    ----------
    grid_points : int, optional
        Grid points TOPPRA uses per section, besides every blend boundary (default 120, at least 2).
    """

    name: ClassVar[str] = "toppra"
    summary: ClassVar[str] = (
        "rounded corners where safe, TOPPRA velocity/acceleration timing (jerk not limited)"
    )

    grid_points: int = 120

    def __post_init__(self) -> None:
        if (
            isinstance(self.grid_points, bool)
            or not isinstance(self.grid_points, int)
            or self.grid_points < 2
        ):
            raise InputError(f"toppra option grid_points must be an integer >= 2, got {self.grid_points!r}")

    @property
    def jerk_limited(self) -> bool:
        """Always False: TOPPRA limits velocity and acceleration only."""
        return False

    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """The TOPPRA schedule of ``route`` under ``limits``, verified; else ``Exact(jerk=False)``, flagged.

        Like ``optimal``, a result that cannot be computed or fails the
        verifier is replaced by the exact schedule without jerk limits (which
        this method is never slower than), with ``fallback_reason`` set.
        """
        check_request(route, limits)
        try:
            schedule = _toppra_schedule(self, route, limits)
        except InputError:
            raise
        except Exception as error:  # TOPPRA's own failures must not leave the library as a crash
            return _fallback(route, limits, FallbackReason.SOLVER_FAILED, f"{type(error).__name__}: {error}")
        report = verify(schedule)
        if not report.passed:
            return _fallback(route, limits, FallbackReason.VERIFICATION_FAILED, "; ".join(report.failures))
        return schedule


def _fallback(route: Route, limits: Limits, reason: FallbackReason, detail: str) -> Schedule:
    logger.warning("toppra schedule fell back to exact without jerk limits (%s): %s", reason.value, detail)
    exact = Exact(jerk=False).schedule(route, limits)
    return dataclasses.replace(
        exact,
        notes=(f"fallback to exact without jerk limits ({reason.value}): {detail}",),
        fallback_reason=reason,
    )
