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
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import Route, reduce_regions
from topology.indexed import region_keys, track_distance
from trajgen.errors import InputError, SolverError
from trajgen.methods.exact import Exact
from trajgen.methods.graph_timing import check_graph_request, overlapped_moves
from trajgen.methods.toppra_timing import HEADROOM, toppra_kinematics
from trajgen.model.axes import RouteAxes, piece_maps, piece_profiles, route_axes, straight_pieces
from trajgen.model.blended import Blend, BlendedPath
from trajgen.model.schedule import (
    AxisMap,
    CubicKinematics,
    FallbackReason,
    Schedule,
    Section,
    TimingMethod,
    check_request,
)
from trajgen.verification import verify

__all__ = ["HEADROOM", "Toppra"]

logger = logging.getLogger(__name__)

#: Blend sizes tried, as fractions of the largest possible one.
_BLEND_FRACTIONS = (1.0, 0.5, 0.25, 0.125)
_BLEND_SAMPLES = 256


def _reverses(incoming: np.ndarray, outgoing: np.ndarray) -> bool:
    return bool(np.any(incoming * outgoing < 0.0))


def _locate_both(maps: tuple[AxisMap, AxisMap], points: np.ndarray):
    leg1, s1 = maps[0].locate(points[:, 0])
    leg2, s2 = maps[1].locate(points[:, 1])
    return leg1, s1, leg2, s2


def _regions(leg1, s1, leg2, s2) -> tuple:
    return reduce_regions(region_keys(leg1, s1, leg2, s2))


def _safe_blend(axes: RouteAxes, pieces: list[tuple[int, int]], corner: int, required: float) -> Blend | None:
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
        blend = Blend(p - r * incoming / len_in, p, p + r * outgoing / len_out)
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


def _groups(axes: RouteAxes, pieces: list[tuple[int, int]], blends: list[Blend | None]):
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


def _toppra_schedule(method: Toppra, route: Route, limits: Limits) -> Schedule:
    """Round corners where safe, then time each stop-to-stop section with TOPPRA."""
    grid_points = method.grid_points
    axes = route_axes(route)
    pieces = straight_pieces(axes.axes)
    if not pieces:  # nothing moves
        schedule = Exact(jerk=False).schedule(route, limits)
        return Schedule(route, limits, method, schedule.sections, jerk_limited=False)
    required = max(limits.min_separation, route.min_separation)
    blends: list[Blend | None] = [None] + [
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
                timed = toppra_kinematics(path, limits, grid_points)
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
    description: ClassVar[str] = (
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

    def schedule_graph(self, route, limits: Limits):
        """The TOPPRA schedule of a route on a track graph: hand-overs overlapped where safe, verified.

        A result that cannot be computed or fails the verifier is replaced by the exact schedule
        without jerk limits, with ``fallback_reason`` set (as on a junction).
        """
        check_graph_request(route, limits)
        try:
            schedule = overlapped_moves(route, limits, self, grid_points=self.grid_points)
        except InputError:
            raise
        except Exception as error:  # TOPPRA's own failures must not leave the library as a crash
            return _graph_fallback(
                route, limits, FallbackReason.SOLVER_FAILED, f"{type(error).__name__}: {error}"
            )
        report = verify(schedule)
        if not report.passed:
            return _graph_fallback(
                route, limits, FallbackReason.VERIFICATION_FAILED, "; ".join(report.failures)
            )
        return schedule


def _graph_fallback(route, limits: Limits, reason: FallbackReason, detail: str):
    logger.warning(
        "toppra schedule of a graph fell back to exact without jerk (%s): %s", reason.value, detail
    )
    exact = Exact(jerk=False).schedule_graph(route, limits)
    return dataclasses.replace(
        exact,
        notes=(f"fallback to exact without jerk limits ({reason.value}): {detail}",),
        fallback_reason=reason,
    )


def _fallback(route: Route, limits: Limits, reason: FallbackReason, detail: str) -> Schedule:
    logger.warning("toppra schedule fell back to exact without jerk limits (%s): %s", reason.value, detail)
    exact = Exact(jerk=False).schedule(route, limits)
    return dataclasses.replace(
        exact,
        notes=(f"fallback to exact without jerk limits ({reason.value}): {detail}",),
        fallback_reason=reason,
    )
