"""``configuration.png``: the configuration space drawn flat, with a route and its retraction.

The space of the paper (section 5.2; ALGORITHM.md sections 2-4) is a base of six
quadrangles ``Q(i, j)`` (vehicle 1 on leg ``i``, vehicle 2 on leg ``j``) around
the deleted point where both vehicles would be at the junction, and six
triangles ``T(k, r)`` (both on leg ``k``, vehicle ``r`` nearer the junction),
each glued to the base along one ray (vehicle ``r`` at the junction, the other
on leg ``k``). The base deforms onto its boundary, the 12-cycle of peaks and
valleys: the circle of the planner.

The flat drawing (:class:`ConfigurationLayout`, pure geometry, no drawing):

- The boundary cycle is a star round the origin: each vertex at the angle
  ``90° + 360° θ / perimeter`` of its arc length ``θ`` (counterclockwise from
  ``P(first leg, second leg)``), peaks at radius :data:`PEAK_RADIUS`, valleys at
  :data:`VALLEY_RADIUS`; each edge is a straight line, on which the moving
  vehicle's distance from the junction is linear. So two boundary points half a
  perimeter apart (a swap of the vehicles) are drawn opposite each other.
- ``Q(i, j)`` is the kite origin - ``V2(i)`` - ``P(i, j)`` - ``V1(j)``. A
  configuration with ``u = s1 / L_i``, ``v = s2 / L_j`` is drawn at ``m b`` where
  ``m = max(u, v)`` and ``b`` is its retraction ``(u / m, v / m)`` on the kite's
  outer edges: the retraction (ALGORITHM.md section 3, radial in ``(s1, s2)``)
  is a straight line away from the deleted point, and the rays (one vehicle at
  the junction) are the straight lines from the origin to the valleys.
- A triangle cannot lie flat in the base (three sheets meet along its ray), so
  ``T(k, r)`` is drawn folded out beside the valley of its ray: its ray is drawn
  again from that valley outwards (the junction end outermost), its far edge
  (the farther vehicle at the end of leg ``k``) leaves the valley at an angle,
  and the diagonal (both at one point) closes it. A motion in a triangle reaches
  the base through the valley, where both drawings of the ray meet.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from topology import JUNCTION_INDEX, RegionKey, Route, YGraph
from topology.cycle import retract_indexed
from topology.indexed import IndexedConfiguration, region_key
from trajgen.errors import InputError
from trajgen.plots.figure import new_figure, png_bytes
from trajgen.plots.retract_graph import configuration_subject, render_retract_graph
from trajgen.plots.speed import plot_period
from trajgen.summary import class_label
from trajgen.values import ArrayValue, readonly
from trajgen.verify import VerifiedSchedule, require_verified

__all__ = [
    "FLAP_SIZE",
    "PEAK_RADIUS",
    "VALLEY_RADIUS",
    "ConfigurationLayout",
    "render_configuration",
    "route_samples",
    "schedule_samples",
]

#: Distance of the peaks (both vehicles at leg ends) from the deleted point, drawing units.
PEAK_RADIUS = 1.0
#: Distance of the valleys (one vehicle at the junction, the other at a leg end), drawing units.
VALLEY_RADIUS = 0.6
#: Length of a folded-out triangle's two short edges, drawing units.
FLAP_SIZE = 0.38
#: A triangle's far edge turns this share of the way from its ray to the next boundary edge.
_FLAP_TURN = 0.55
#: Most schedule samples drawn, and route samples per segment.
_MAX_PATH_SAMPLES = 2000
_SEGMENT_SAMPLES = 24


def _rotate(vector: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def _segment_samples(a: IndexedConfiguration, b: IndexedConfiguration, count: int):
    """Configurations along a route segment (each vehicle linear within one leg), ``a`` and ``b`` included."""
    leg1 = a[0] if a[0] != JUNCTION_INDEX else b[0]
    leg2 = a[2] if a[2] != JUNCTION_INDEX else b[2]
    for fraction in np.linspace(0.0, 1.0, count):
        s1 = a[1] + fraction * (b[1] - a[1])
        s2 = a[3] + fraction * (b[3] - a[3])
        yield (leg1 if s1 > 0.0 else JUNCTION_INDEX, s1, leg2 if s2 > 0.0 else JUNCTION_INDEX, s2)


@dataclass(frozen=True, slots=True, eq=False)
class ConfigurationLayout(ArrayValue):
    """The flat drawing of a track's configuration space: where each configuration is drawn.

    Build with :meth:`of`. Drawing units are abstract (the peaks lie on the unit circle).

    Attributes
    ----------
    graph : YGraph
    min_separation : float
        Metres; configurations closer than this are shaded as too close.
    vertices : ndarray, shape (12, 2)
        The boundary cycle's vertices in the order of ``graph.boundary_vertices``.
    """

    graph: YGraph
    min_separation: float
    vertices: np.ndarray = field(repr=False)
    _peak: Mapping = field(repr=False, compare=False)
    _valley: Mapping = field(repr=False, compare=False)

    @classmethod
    def of(cls, graph: YGraph, *, min_separation: float = 0.0) -> ConfigurationLayout:
        """The layout of ``graph``'s configuration space; ``min_separation`` in metres (0 to shortest leg)."""
        if not isinstance(graph, YGraph):
            raise InputError(
                f"a configuration layout needs a YGraph (three legs), got {type(graph).__name__}: with "
                "four or more legs draw the retract graph (trajgen.plots.retract_graph.RetractGraphLayout)"
            )
        if not 0.0 <= min_separation <= graph.shortest_leg:
            raise InputError(
                f"min_separation {min_separation!r} m is out of range: expected 0 m to the shortest leg "
                f"{graph.shortest_leg!r} m"
            )
        cycle = graph.cycle
        peak, valley, points = {}, {}, []
        for k, (l1, _, l2, _) in enumerate(cycle.vertex_tuples):
            angle = 0.5 * math.pi + 2.0 * math.pi * cycle.vertex_theta[k] / cycle.perimeter
            is_peak = JUNCTION_INDEX not in (l1, l2)
            radius = PEAK_RADIUS if is_peak else VALLEY_RADIUS
            points.append((radius * math.cos(angle), radius * math.sin(angle)))
            if is_peak:
                peak[(l1, l2)] = k
            else:  # keyed like the triangle glued to its ray: (leg of the other vehicle, vehicle at O)
                valley[(l2, 1) if l1 == JUNCTION_INDEX else (l1, 2)] = k
        return cls(
            graph, float(min_separation), readonly(points), MappingProxyType(peak), MappingProxyType(valley)
        )

    # -- the parts of the drawing ------------------------------------------
    def peak(self, first_leg: int, second_leg: int) -> np.ndarray:
        """Where ``P(i, j)`` is drawn: vehicle 1 at the end of leg ``i``, vehicle 2 at the end of ``j``."""
        return self.vertices[self._peak[(first_leg, second_leg)]]

    def valley(self, leg: int, at_junction: int) -> np.ndarray:
        """The valley: vehicle ``at_junction`` (1 or 2) at O, the other at the end of ``leg``."""
        return self.vertices[self._valley[(leg, at_junction)]]

    def _flap_axes(self, leg: int, nearer: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Valley, unit vectors along the ray's copy (outwards) and the far edge of ``T(leg, nearer)``."""
        k = self._valley[(leg, nearer)]
        valley = self.vertices[k]
        outward = valley / np.hypot(*valley)
        edge = self.vertices[(k + 1) % 12] - valley  # the next boundary edge, counterclockwise
        room = math.atan2(outward[0] * edge[1] - outward[1] * edge[0], float(outward @ edge))
        return valley, outward, _rotate(outward, _FLAP_TURN * room)

    def region_polygon(self, key: RegionKey) -> np.ndarray:
        """The outline of a region, shape (n, 2): a kite for ``Q(i, j)``, a triangle for ``T(k, r)``."""
        if key.nearer:
            valley, along_ray, along_edge = self._flap_axes(key.first_leg, key.nearer)
            return np.array([valley, valley + FLAP_SIZE * along_ray, valley + FLAP_SIZE * along_edge])
        return np.array(
            [
                [0.0, 0.0],
                self.valley(key.first_leg, 2),
                self.peak(key.first_leg, key.second_leg),
                self.valley(key.second_leg, 1),
            ]
        )

    @property
    def regions(self) -> tuple[RegionKey, ...]:
        """The 12 regions: the six ``Q(i, j)`` then the six ``T(k, r)``."""
        quadrangles = tuple(RegionKey(i, j, 0) for i, j in itertools.permutations(range(3), 2))
        return quadrangles + tuple(RegionKey(k, k, r) for k in range(3) for r in (1, 2))

    def too_close_polygons(self) -> list[np.ndarray]:
        """Outlines of the configurations closer than ``min_separation`` (none for 0), each shape (n, 2)."""
        required = self.min_separation
        if required <= 0.0:
            return []
        lengths = self.graph.lengths
        polygons = []
        edge = np.linspace(0.0, 1.0, 24)
        for key in self.regions:
            if key.nearer:  # the strip along the diagonal: far - near < d
                leg = key.first_leg
                valley, along_ray, along_edge = self._flap_axes(leg, key.nearer)
                band = required / lengths[leg]
                corners = [(1.0 - band, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, 1.0 - band)]
                polygons.append(
                    np.array([valley + FLAP_SIZE * (a * along_ray + b * along_edge) for a, b in corners])
                )
                continue
            i, j = key.first_leg, key.second_leg
            # s1 + s2 < d: the corner at the deleted point, its hypotenuse sampled (it is drawn curved)
            hypotenuse = [(i, f * required, j, (1.0 - f) * required) for f in edge]
            polygons.append(np.array([[0.0, 0.0], *(self.base_point(c) for c in hypotenuse)]))
        return polygons

    # -- configurations ------------------------------------------------------
    def base_point(self, c: IndexedConfiguration) -> np.ndarray:
        """Where a configuration of the base (different legs, or one vehicle at O) is drawn, shape (2,)."""
        l1, s1, l2, s2 = c
        lengths = self.graph.lengths
        if l1 == JUNCTION_INDEX and l2 == JUNCTION_INDEX:
            return np.zeros(2)  # the deleted point
        if l1 == JUNCTION_INDEX:
            return min(s2 / lengths[l2], 1.0) * self.valley(l2, 1)
        if l2 == JUNCTION_INDEX:
            return min(s1 / lengths[l1], 1.0) * self.valley(l1, 2)
        if l1 == l2:
            raise InputError(f"configuration {c} has both vehicles on one leg: it is drawn in a triangle")
        u, v = min(s1 / lengths[l1], 1.0), min(s2 / lengths[l2], 1.0)
        m = max(u, v)
        if m <= 0.0:
            return np.zeros(2)
        peak = self.peak(l1, l2)
        if u >= v:  # retracts onto the edge V2(i) - P(i, j): vehicle 1 at the end of its leg
            corner = self.valley(l1, 2)
            return m * (corner + (v / m) * (peak - corner))
        corner = self.valley(l2, 1)
        return m * (corner + (u / m) * (peak - corner))

    def triangle_point(self, c: IndexedConfiguration, key: RegionKey) -> np.ndarray:
        """Where a configuration of ``T(k, r)`` (or on its ray) is drawn, in the folded-out triangle; (2,)."""
        leg, nearer = key.first_leg, key.nearer
        length = self.graph.lengths[leg]
        s_near, s_far = (c[1], c[3]) if nearer == 1 else (c[3], c[1])
        valley, along_ray, along_edge = self._flap_axes(leg, nearer)
        a = 1.0 - min(s_far / length, 1.0)  # 0 at the far end of the leg
        b = min(s_near / length, 1.0)
        return valley + FLAP_SIZE * (a * along_ray + b * along_edge)

    def side(self, c: IndexedConfiguration, region: RegionKey | None = None) -> RegionKey | None:
        """The folded-out triangle ``c`` is drawn in, or ``None`` for the base.

        A configuration in a triangle is drawn there; one on a ray belongs to a triangle
        and to two quadrangles, and is drawn in the triangle ``region`` names if it is
        that triangle's ray, else in the base.
        """
        l1, _, l2, _ = c
        if l1 == l2 and l1 != JUNCTION_INDEX:
            return region_key(*c)
        if region is not None and region.nearer:
            at_junction = 1 if l1 == JUNCTION_INDEX else 2 if l2 == JUNCTION_INDEX else 0
            other = l2 if at_junction == 1 else l1
            if at_junction == region.nearer and other == region.first_leg:
                return region
        return None

    def point(self, c: IndexedConfiguration, region: RegionKey | None = None) -> np.ndarray:
        """Where a configuration is drawn, shape (2,).

        Parameters
        ----------
        c : IndexedConfiguration
        region : RegionKey, optional
            The region the configuration is taken in, for a point on a ray (see :meth:`side`).
        """
        side = self.side(c, region)
        return self.base_point(c) if side is None else self.triangle_point(c, side)

    def boundary_point(self, theta: float) -> np.ndarray:
        """Where the boundary point ``theta`` metres counterclockwise from ``P(first, second)`` is drawn."""
        cycle = self.graph.cycle
        theta = theta % cycle.perimeter
        k = max(0, int(np.searchsorted(cycle.vertex_theta, theta, side="right")) - 1)
        end = cycle.vertex_theta[k + 1] if k < 11 else cycle.perimeter
        fraction = (theta - cycle.vertex_theta[k]) / (end - cycle.vertex_theta[k])
        return self.vertices[k] + fraction * (self.vertices[(k + 1) % 12] - self.vertices[k])

    def boundary_image(self, c: IndexedConfiguration) -> np.ndarray:
        """Where the retraction ``r(c)`` of a configuration onto the boundary circle is drawn, shape (2,)."""
        cycle = self.graph.cycle
        return self.boundary_point(cycle.theta(cycle.locate(retract_indexed(c, self.graph.lengths)[-1])))

    def retraction(self, c: IndexedConfiguration, region: RegionKey | None = None) -> np.ndarray:
        """The retraction of ``c`` onto the boundary (ALGORITHM.md section 3) as drawn, shape (n, 2).

        Its waypoints, from ``c`` to its boundary image: a straight line away from the
        deleted point in a quadrangle; in a triangle, to the ray's copy, then along it to
        the valley. ``region`` places a start on a ray, as in :meth:`point`.
        """
        steps = retract_indexed(c, self.graph.lengths)
        region = self.side(c, region)
        return np.array([self.point(step, region) for step in steps])

    def paths(self, configurations, regions) -> list[np.ndarray]:
        """Polylines of a motion through ``configurations``, each shape (n, 2).

        Parameters
        ----------
        configurations : sequence of IndexedConfiguration
            Dense enough that straight lines between them stay in one region.
        regions : sequence of RegionKey or None
            The region each configuration is taken in (see :meth:`side`).

        Returns
        -------
        list of ndarray
            A new polyline starts where the motion passes between a folded-out triangle
            and the base; the configuration where it passes (on the ray) ends the one and
            starts the other, so the two drawings of it can be joined.
        """
        lines: list[list[np.ndarray]] = []
        previous: RegionKey | None = None
        for c, region in zip(configurations, regions, strict=True):
            side = self.side(c, region)
            point = self.base_point(c) if side is None else self.triangle_point(c, side)
            if lines and side != previous and self.side(c, previous) == previous:
                lines[-1].append(self.base_point(c) if previous is None else self.triangle_point(c, previous))
            if not lines or side != previous:
                lines.append([point])
            else:
                lines[-1].append(point)
            previous = side
        return [np.array(line) for line in lines]


def route_samples(route: Route, *, per_segment: int = _SEGMENT_SAMPLES) -> tuple[list, list]:
    """Configurations along a route and the region each is taken in (for :meth:`ConfigurationLayout.paths`).

    A segment on a ray (one vehicle at the junction) is taken in the triangle of a
    neighbouring segment, if there is one: it is the end of that triangle's retraction.

    Returns
    -------
    (list of IndexedConfiguration, list of RegionKey or None)
        ``per_segment`` samples per segment, shape (n,) each.
    """
    tuples = route.indexed_waypoints
    keys = route.segment_region_keys
    if len(tuples) == 1:
        return [tuples[0]], [None]
    configurations, regions = [], []
    for k, (a, b) in enumerate(itertools.pairwise(tuples)):
        key = keys[k]
        if key is None:
            neighbours = (keys[k - 1] if k > 0 else None, keys[k + 1] if k + 1 < len(keys) else None)
            key = next((n for n in neighbours if n is not None and n.nearer), None)
        for c in _segment_samples(a, b, per_segment):
            configurations.append(c)
            regions.append(key)
    return configurations, regions


def schedule_samples(verified: VerifiedSchedule, *, count: int = _MAX_PATH_SAMPLES) -> tuple[list, list]:
    """Configurations of a verified schedule at ``count`` instants, and the region each is taken in.

    A configuration on a ray is taken in the region the schedule was last in.

    Returns
    -------
    (list of IndexedConfiguration, list of RegionKey or None)
        Shape (n,) each, ``n <= count``.
    """
    schedule = require_verified(verified, "schedule_samples").schedule
    lengths = schedule.route.graph.lengths
    samples = max(2, min(count, int(schedule.duration / plot_period(schedule.duration)) + 1))
    state = schedule.state(np.linspace(0.0, schedule.duration, samples))
    configurations, regions = [], []
    region: RegionKey | None = None
    for k in range(state.t.size):
        legs = (int(state.leg[0, k]), int(state.leg[1, k]))
        s = [
            0.0 if leg == JUNCTION_INDEX else min(max(float(state.s[v, k]), 0.0), lengths[leg])
            for v, leg in enumerate(legs)
        ]
        c = (legs[0], s[0], legs[1], s[1])
        region = region_key(*c) or region
        configurations.append(c)
        regions.append(region)
    return configurations, regions


#: Fill colours of the quadrangles and the triangles; colours of the route, the schedule and the retraction.
_QUADRANGLE_COLOUR = "#dce9f5"
_TRIANGLE_COLOUR = "#f6e7cc"
_ROUTE_COLOUR = "tab:blue"
_SCHEDULE_COLOUR = "tab:red"
_RETRACTION_COLOUR = "tab:orange"
#: The retracted motion is drawn this much outside the boundary circle, so both stay visible.
_OUTSET = 1.07
#: Retraction traces drawn from the motion.
_TRACES = 14


def _region_name(graph: YGraph, key: RegionKey) -> str:
    names = graph.names
    if key.nearer:
        return f"T({names[key.first_leg]},{key.nearer})"
    return f"Q({names[key.first_leg]},{names[key.second_leg]})"


def _vertex_name(graph: YGraph, c: IndexedConfiguration) -> str:
    names = graph.names
    if c[0] == JUNCTION_INDEX:
        return f"V1({names[c[2]]})"
    if c[2] == JUNCTION_INDEX:
        return f"V2({names[c[0]]})"
    return f"P({names[c[0]]},{names[c[2]]})"


def _draw_space(axis, layout: ConfigurationLayout) -> None:
    """The regions, the too-close parts, the rays, the boundary circle and the labels."""
    graph = layout.graph
    for key in layout.regions:
        polygon = layout.region_polygon(key)
        colour = _TRIANGLE_COLOUR if key.nearer else _QUADRANGLE_COLOUR
        axis.fill(*polygon.T, facecolor=colour, edgecolor="0.55", linewidth=0.8, zorder=1)
        centre = polygon.mean(axis=0) if key.nearer else 0.55 * layout.peak(key.first_leg, key.second_leg)
        axis.text(
            *centre, _region_name(graph, key), ha="center", va="center", fontsize=9, color="0.25", zorder=2
        )
    for k, polygon in enumerate(layout.too_close_polygons()):
        axis.fill(
            *polygon.T,
            facecolor="tab:red",
            alpha=0.3,
            edgecolor="none",
            hatch="////",
            zorder=2,
            label=f"too close (< {layout.min_separation:g} m along the track)" if k == 0 else None,
        )
    for k, c in enumerate(graph.cycle.vertex_tuples):
        vertex = layout.vertices[k]
        if JUNCTION_INDEX in (c[0], c[2]):
            axis.plot(
                *np.array([[0.0, 0.0], vertex]).T,
                color="0.45",
                linewidth=0.9,
                linestyle="--",
                zorder=2,
                label="rays (one vehicle at O)" if k == 1 else None,
            )
            place = vertex + 0.17 * _rotate(vertex / np.hypot(*vertex), -0.6)
        else:
            place = 1.1 * vertex
        axis.text(*place, _vertex_name(graph, c), ha="center", va="center", fontsize=8, zorder=3)
    star = np.vstack([layout.vertices, layout.vertices[:1]])
    axis.plot(
        *star.T,
        color="black",
        linewidth=2.0,
        zorder=3,
        label=f"boundary circle (12-cycle, {graph.perimeter:g} m round)",
    )
    axis.plot([0.0], [0.0], "o", markersize=11, markerfacecolor="white", markeredgecolor="black", zorder=6)
    axis.annotate(
        "deleted point\n(both at O)",
        (0.0, 0.0),
        xytext=(0, -14),
        textcoords="offset points",
        ha="center",
        va="top",
        fontsize=8,
        zorder=6,
    )


def _draw_paths(
    axis, lines: list[np.ndarray], *, colour: str, width: float, label: str, style: str = "-"
) -> None:
    for k, line in enumerate(lines):
        axis.plot(
            *line.T, color=colour, linewidth=width, linestyle=style, zorder=5, label=label if k == 0 else None
        )
        if k:  # the same configuration, drawn in the base and in a folded-out triangle
            axis.plot(
                *np.array([lines[k - 1][-1], line[0]]).T, color=colour, linewidth=0.8, linestyle=":", zorder=5
            )


def _draw_retraction(
    axis, layout: ConfigurationLayout, configurations: list, regions: list, label: str
) -> None:
    """Traces of the retraction from some configurations of the motion, and the motion retracted."""
    picks = np.unique(np.linspace(0, len(configurations) - 1, _TRACES + 2).round().astype(int))
    first = True
    for index in picks:
        c = configurations[int(index)]
        trace = layout.retraction(c, regions[int(index)])
        if len(trace) < 2:
            continue
        axis.plot(
            *trace.T, color="0.35", linewidth=0.8, zorder=4, label="retraction traces" if first else None
        )
        axis.annotate(
            "",
            xy=trace[-1],
            xytext=trace[-2],
            arrowprops={"arrowstyle": "->", "color": "0.35", "linewidth": 0.8},
            zorder=4,
        )
        first = False
    images = np.array([layout.boundary_image(c) for c in configurations]) * _OUTSET
    axis.plot(
        *images.T,
        color=_RETRACTION_COLOUR,
        linewidth=4,
        alpha=0.75,
        solid_capstyle="round",
        zorder=4,
        label=label,
    )
    if len(images) > 1 and np.hypot(*(images[-1] - images[-2])) > 0.0:
        axis.annotate(
            "",
            xy=images[-1],
            xytext=images[-2],
            arrowprops={"arrowstyle": "-|>", "color": _RETRACTION_COLOUR, "mutation_scale": 18},
            zorder=4,
        )


def render_configuration(subject: Route | VerifiedSchedule, *, names: tuple[str, str] | None = None) -> bytes:
    """The configuration space drawn flat with the route, the motion and its retraction, as PNG bytes.

    Four or more legs: the retract graph ``G_k`` with the route on it instead
    (:func:`trajgen.plots.retract_graph.render_retract_graph`): the space has no flat drawing.

    Drawn: the six quadrangles and six triangles (folded out beside their valleys, see
    :class:`ConfigurationLayout`) round the deleted point, the too-close parts, the rays,
    the boundary circle with its peaks and valleys named, the route (the planner's
    waypoints), for a schedule also its path, the start (hollow) and goal (solid),
    retraction traces from the motion (the schedule's path, else the route) and the motion
    retracted onto the boundary circle (drawn just outside it, with its direction).

    Parameters
    ----------
    subject : Route or VerifiedSchedule
        A route from :func:`topology.plan`, or a schedule from :func:`trajgen.certify`
        (its route and its path are drawn).
    names : pair of str, optional
        The vehicles' names, for the title (default: "vehicle 1", "vehicle 2").

    Raises
    ------
    UnverifiedScheduleError
        ``subject`` is a schedule that has not been certified.
    InputError
        ``subject`` is neither a Route nor a VerifiedSchedule, or ``names`` is not two strings.
    """
    route, verified = configuration_subject(subject, names)
    required = route.min_separation
    if verified is not None:
        required = max(verified.schedule.limits.min_separation, required)
    graph = route.graph
    if graph.cycle is None:  # four or more legs: no flat drawing, the retract graph G_k instead
        return render_retract_graph(subject, names=names)
    layout = ConfigurationLayout.of(graph, min_separation=required)
    who = "vehicle 1 and vehicle 2" if names is None else f"{names[0]} (vehicle 1) and {names[1]} (vehicle 2)"
    figure = new_figure(figsize=(8.6, 9.6))
    axis = figure.add_axes((0.02, 0.265, 0.96, 0.655))
    axis.set_aspect("equal")
    axis.set_axis_off()
    axis.set_xlim(-1.32, 1.32)
    axis.set_ylim(-1.22, 1.22)
    _draw_space(axis, layout)
    route_configurations, route_regions = route_samples(route)
    _draw_paths(
        axis,
        layout.paths(route_configurations, route_regions),
        colour=_ROUTE_COLOUR,
        width=2.6,
        label=f"route (the planner's waypoints), {route.length:.4g} m of travel",
    )
    motion, motion_regions = route_configurations, route_regions
    if verified is not None:
        configurations, regions = schedule_samples(verified)
        _draw_paths(
            axis,
            layout.paths(configurations, regions),
            colour=_SCHEDULE_COLOUR,
            width=1.8,
            style="--",
            label=f"{verified.schedule.method.name} schedule's path ({verified.schedule.duration:.2f} s)",
        )
        motion, motion_regions = configurations, regions
    what = "schedule's path" if verified is not None else "route"
    way = route.way_round.value if route.arc_length else "not"
    _draw_retraction(
        axis,
        layout,
        motion,
        motion_regions,
        f"the {what} retracted onto the circle: {abs(route.arc_length):.4g} m {way} round",
    )
    start, goal = route.indexed_waypoints[0], route.indexed_waypoints[-1]
    start_region = route.region_keys[0] if route.region_keys else None
    goal_region = route.region_keys[-1] if route.region_keys else None
    axis.plot(
        *layout.point(start, start_region),
        "o",
        markersize=11,
        markerfacecolor="white",
        markeredgecolor="black",
        markeredgewidth=2,
        zorder=7,
        label=f"start {route.start}",
    )
    axis.plot(
        *layout.point(goal, goal_region),
        "o",
        markersize=8,
        color="black",
        zorder=7,
        label=f"goal {route.goal}",
    )
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.01), ncols=2, fontsize=8.5, frameon=False)
    regions = " ".join(_region_name(graph, key) for key in route.region_keys) or "(one ray)"
    axis.set_title(
        f"Configuration space of {who}, drawn flat\nroute: {class_label(route)}; regions {regions}",
        fontsize=11,
    )
    figure.text(
        0.05,
        0.015,
        "\n".join(
            (
                "Q(i,j): vehicle 1 on leg i, vehicle 2 on leg j (a quadrangle).  T(k,r): both on leg k,",
                "vehicle r nearer O (a triangle, glued to the base along its ray; drawn folded out beside",
                "that ray's valley, the ray drawn again outwards from the valley).  P(i,j): vehicle 1 at the",
                "end of leg i, vehicle 2 at the end of leg j; V1(j): vehicle 1 at O, vehicle 2 at the end of",
                "j; V2(i): vehicle 2 at O, vehicle 1 at the end of i.  Not to scale: the angle round the",
                "deleted point is proportional to arc length on the boundary circle (a swap of the vehicles",
                "is drawn opposite); a point of a quadrangle lies on the line from the deleted point to its",
                "retraction, max(s1/L_i, s2/L_j) of the way.",
            )
        ),
        fontsize=8,
        va="bottom",
        family="sans-serif",
    )
    return png_bytes(figure)
