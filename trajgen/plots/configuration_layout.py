"""Where the configuration space of a Y is drawn flat: pure geometry, no drawing (ConfigurationLayout).

The picture itself, ``configuration.png``, is drawn by
:mod:`trajgen.plots.configuration`; this module says where each
configuration, region and motion of it lies in the flat drawing, so that can be
checked without looking at pixels.

The space of the paper (section 5.2; docs/planner.md) is a base of six
quadrangles ``Q(i, j)`` (vehicle 1 on leg ``i``, vehicle 2 on leg ``j``) around
the deleted point where both vehicles would be at the junction, and six
triangles ``T(k, r)`` (both on leg ``k``, vehicle ``r`` nearer the junction),
each glued to the base along one ray (vehicle ``r`` at the junction, the other
on leg ``k``). The base deforms onto its boundary, the 12-cycle of peaks and
valleys: the circle of the planner.

The flat drawing:

- The boundary cycle is a star round the origin: each vertex at the angle
  ``90° + 360° θ / perimeter`` of its arc length ``θ`` (counterclockwise from
  ``P(first leg, second leg)``), peaks at radius :data:`PEAK_RADIUS`, valleys at
  :data:`VALLEY_RADIUS`; each edge is a straight line, on which the moving
  vehicle's distance from the junction is linear. So two boundary points half a
  perimeter apart (a swap of the vehicles) are drawn opposite each other.
- ``Q(i, j)`` is the kite origin - ``V2(i)`` - ``P(i, j)`` - ``V1(j)``. A
  configuration with ``u = s1 / L_i``, ``v = s2 / L_j`` is drawn at ``m b`` where
  ``m = max(u, v)`` and ``b`` is its retraction ``(u / m, v / m)`` on the kite's
  outer edges: the retraction (docs/planner.md, 'Retraction onto the circle', radial in ``(s1, s2)``)
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
from trajgen.model.values import ArrayValue, readonly
from trajgen.plots.speed import plot_period
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "FLAP_SIZE",
    "PEAK_RADIUS",
    "VALLEY_RADIUS",
    "ConfigurationLayout",
    "rotate",
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


def rotate(vector: np.ndarray, angle: float) -> np.ndarray:
    """``vector`` (shape (2,)) turned counterclockwise by ``angle`` radians, shape (2,)."""
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
                f"a configuration layout needs a YGraph (three legs), got {type(graph).__name__}: with four "
                "or more legs draw the retract graph (trajgen.plots.star_configuration.RetractGraphLayout)"
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
        return valley, outward, rotate(outward, _FLAP_TURN * room)

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
        """The retraction of ``c`` onto the boundary (docs/planner.md) as drawn, shape (n, 2).

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
