"""Timing a route on a track graph (docs/graphs.md).

The track-graph planner's route moves one vehicle at a time: in the space of every vehicle's
travel (metres driven along its path) it is a staircase, each move a step along one axis. A
junction's route on its track graph also has joint moves, several vehicles at once in fixed shares:
a diagonal step (:meth:`~topology.GraphRoute.corners`).

- ``exact`` times it as it is: each step rest to rest with the time-optimal S-curve of the limits of
  the vehicles it moves, scaled to their shares (closed form), the others standing; without jerk,
  the trapezoids.
- ``toppra`` overlaps the moves: where one vehicle's move hands over to the other's, the corner of
  the staircase is replaced by a quadratic Bézier blend (both vehicles drive at once), as large as
  half of each adjacent move, shrunk until the whole triangle of the corner keeps the separation (so
  the blend keeps it and passes every conflict in the route's order). Between stops (a corner that
  cannot be rounded, or a vehicle turning back) TOPPRA gives the time-optimal velocity- and
  acceleration-limited timing; a section TOPPRA would make slower than the trapezoids keeps them.
"""

from __future__ import annotations

import itertools
import logging

import numpy as np

from limits import Limits
from topology import GraphRoute, TrackGraph
from trajgen.errors import InputError, SolverError
from trajgen.model.axes import piece_profiles
from trajgen.model.blended import Blend, BlendedPath
from trajgen.model.graph_paths import GraphPath, graph_paths
from trajgen.model.graph_schedule import GraphSchedule, GraphSection
from trajgen.model.schedule import CubicKinematics

__all__ = ["check_graph_request", "moves_one_at_a_time", "overlapped_moves", "travel_corners"]

logger = logging.getLogger(__name__)

#: Blend sizes tried, as fractions of the largest possible one.
_BLEND_FRACTIONS = (1.0, 0.5, 0.25, 0.125, 0.0625)
#: Samples per side of the corner's triangle when checking a blend.
_TRIANGLE_SAMPLES = 48


def check_graph_request(route: object, limits: object) -> tuple[GraphRoute, Limits]:
    """Return ``(route, limits)`` if a method can time them on a track graph, else raise InputError."""
    if not isinstance(route, GraphRoute):
        raise InputError(f"route must be a topology.GraphRoute, got {type(route).__name__}")
    if not isinstance(limits, Limits):
        raise InputError(f"limits must be a limits.Limits, got {type(limits).__name__}")
    if route.min_separation < limits.min_separation:
        raise InputError(
            f"the route was planned for a min_separation of {route.min_separation!r} m but the limits ask "
            f"{limits.min_separation!r} m: plan it with "
            f"plan_graph(..., min_separation={limits.min_separation!r})"
        )
    return route, limits


def travel_corners(route: GraphRoute) -> tuple[np.ndarray, tuple[frozenset[int], ...]]:
    """The route as a polyline in the space of every vehicle's travel (:meth:`~topology.GraphRoute.corners`).

    Returns
    -------
    corners : ndarray, shape (m + 1, count)
        Every vehicle's travel before the first step and after each, metres.
    movers : tuple of frozenset of int
        The vehicles each of the m steps moves: one, or those of a joint move.
    """
    steps = [step for step in route.steps if any(part.length > 0.0 for part in step)]
    movers = tuple(frozenset(part.vehicle for part in step if part.length > 0.0) for step in steps)
    return route.corners(), movers


def moves_one_at_a_time(route: GraphRoute, limits: Limits, method, *, jerk: bool) -> GraphSchedule:
    """The route's steps one after the other, each rest to rest and time-optimal for the vehicles it moves.

    Parameters
    ----------
    route : GraphRoute
    limits : Limits
    method : TimingMethod
        Recorded in the schedule.
    jerk : bool
        S-curves (jerk-limited) if True, else trapezoids.
    """
    check_graph_request(route, limits)
    corners, _ = travel_corners(route)
    sections = []
    clock = 0.0
    for k in range(max(len(corners) - 1, 1)):
        end = corners[min(k + 1, len(corners) - 1)]
        section = GraphSection(clock, CubicKinematics(piece_profiles(corners[k], end, limits, jerk=jerk)))
        sections.append(section)
        clock += section.duration
    return GraphSchedule(route, limits, method, graph_paths(route), tuple(sections), jerk_limited=jerk)


def _distances(track: TrackGraph, paths: tuple[GraphPath, ...], points: np.ndarray) -> np.ndarray:
    """Least track distance between any two vehicles at travel points ``points``, shape (n, V) -> (n,)."""
    located = [path.locate(points[:, v]) for v, path in enumerate(paths)]
    least = np.full(points.shape[0], np.inf)
    for (edge_1, s_1), (edge_2, s_2) in itertools.combinations(located, 2):
        np.minimum(least, track.distances(edge_1, s_1, edge_2, s_2), out=least)
    return least


def _safe_blend(
    corners: np.ndarray, corner: int, track: TrackGraph, paths: tuple[GraphPath, ...], required: float
) -> Blend | None:
    """The largest blend at ``corners[corner]`` whose whole triangle keeps ``required`` metres, or None.

    The track distance of two vehicles changes by at most ``|dp_i| + |dp_j|`` between two points of
    the travel space (each pair's share of the triangle's two sides), so a grid of the
    triangle with spacing ``h`` per axis on which every pair keeps ``required + h`` keeps ``required``
    everywhere in it; the blend and the corner both lie in the triangle, which then holds
    no part of a conflict, so the blend passes every conflict on the route's side.
    """
    before, point, after = corners[corner - 1], corners[corner], corners[corner + 1]
    incoming, outgoing = point - before, after - point
    length_in, length_out = float(np.linalg.norm(incoming)), float(np.linalg.norm(outgoing))
    u = np.linspace(0.0, 1.0, _TRIANGLE_SAMPLES + 1)
    a, b = np.meshgrid(u, u)
    inside = a + b <= 1.0
    a, b = a[inside], b[inside]
    for fraction in _BLEND_FRACTIONS:
        r = 0.5 * fraction * min(length_in, length_out)
        start, end = point - r * incoming / length_in, point + r * outgoing / length_out
        # the triangle (start, point, end): point + a (start - point) + b (end - point)
        grid = point + np.outer(a, start - point) + np.outer(b, end - point)
        spacing = r / _TRIANGLE_SAMPLES
        if np.min(_distances(track, paths, grid)) >= required + 2.0 * spacing:
            return Blend(start, point, end)
    return None


def overlapped_moves(route: GraphRoute, limits: Limits, method, *, grid_points: int) -> GraphSchedule:
    """The ``toppra`` schedule of a route on a track graph: corners rounded where safe, TOPPRA between stops.

    Raises
    ------
    InputError
        A bad route or limits.
    """
    from trajgen.methods.toppra_timing import toppra_kinematics  # TOPPRA only when it times something

    check_graph_request(route, limits)
    corners, movers = travel_corners(route)
    paths = graph_paths(route)
    if not movers:
        exact = moves_one_at_a_time(route, limits, method, jerk=False)
        return exact
    required = max(limits.min_separation, route.min_separation)
    blends: list[Blend | None] = [None]
    for corner in range(1, len(movers)):
        # a vehicle moving on both sides turned back (the planner's moves) or may: at rest there
        same_vehicle = bool(movers[corner] & movers[corner - 1])
        blends.append(None if same_vehicle else _safe_blend(corners, corner, route.track, paths, required))
    groups, start = [], 0
    for corner in range(1, len(movers)):
        if blends[corner] is None:
            groups.append((start, corner))
            start = corner
    groups.append((start, len(movers)))
    sections: list[GraphSection] = []
    clock = 0.0
    rounded = timed_sections = 0
    failed: list[str] = []
    for first, stop in groups:
        trapezoids = [
            CubicKinematics(piece_profiles(corners[k], corners[k + 1], limits, jerk=False))
            for k in range(first, stop)
        ]
        timed = None
        if stop - first > 1:
            path = BlendedPath(corners[first : stop + 1], (None, *blends[first + 1 : stop], None))
            try:
                timed = toppra_kinematics(path, limits, grid_points)
            except SolverError as error:
                logger.warning(
                    "TOPPRA failed on a section of a graph route, its corners are stops: %s", error
                )
                failed.append(str(error))
            if timed is not None and timed.duration >= sum(k.duration for k in trapezoids):
                timed = None
        if timed is not None:
            sections.append(GraphSection(clock, timed))
            clock += timed.duration
            rounded += stop - first - 1
            timed_sections += 1
            continue
        for kinematics in trapezoids:
            sections.append(GraphSection(clock, kinematics))
            clock += kinematics.duration
    notes = (
        f"{rounded} of {len(movers) - 1} hand-overs between the vehicles overlapped; "
        f"{timed_sections} section(s) timed by TOPPRA",
        "jerk is not limited by this method",
        *(f"TOPPRA failed on a section ({reason}); its corners are stops" for reason in failed),
    )
    return GraphSchedule(route, limits, method, paths, tuple(sections), jerk_limited=False, notes=notes)
