"""``configuration.png`` for four to eight legs: the retract graph ``G_k`` drawn as a table, with the route.

With four or more legs the configuration space has no flat drawing like the Y's
(:mod:`trajgen.plots.configuration_layout`): it deforms onto the graph ``G_k`` (docs/star.md,
'The retract graph G_k'), drawn here. The layout (:class:`RetractGraphLayout`, pure geometry) is a
table of where each vehicle waits, vehicle 1 down the rows, vehicle 2 across the columns, each at
the junction ``O`` (the first row and column) or at the far end ``E_i`` of a leg (counterclockwise):

- the peak ``P(i, j)`` is the cell of row ``i``, column ``j``; the valley ``V1(j)`` (vehicle 1 at
  ``O``) is in the first row, ``V2(i)`` in the first column; the corner (both at ``O``) is the
  deleted point and the diagonal (both at one leg's end) holds no configuration;
- the edge ``P(i, j) - V1(j)`` (vehicle 1 drives leg ``i``) runs up column ``j``, the edge
  ``P(i, j) - V2(i)`` (vehicle 2 drives leg ``j``) along row ``i``, each a parabolic arc bowed
  towards the deleted point, its bow proportional to its length in cells: the arcs from one valley
  are scaled copies of each other and never cross. A point ``f`` of an edge's length from the peak
  is drawn ``f`` of the way along the arc (measured along the chord);
- a route is drawn through the points of ``G_k`` it passes: the start's retraction, the vertices
  of the route on ``G_k``, the goal's retraction.

The picture says all this in plain words (a vertex is ``(N, S)``: where each vehicle waits); the
notation stays in the code and the docs. Not to scale: every vertical edge in row ``i`` is
``L_i`` long, every horizontal edge in column ``j`` is ``L_j`` long (the headers give them).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from topology import JUNCTION_INDEX, GraphPoint, Homotopy, Instruction, Route, StarGraph
from topology.cycle import retract_indexed
from topology.indexed import IndexedConfiguration, step
from trajgen.errors import InputError
from trajgen.model.values import ArrayValue, readonly
from trajgen.plots.figure import drawing_area, finished, untangle, wrapped
from trajgen.plots.speed import VEHICLE_COLOURS, plot_period
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "BOW",
    "RULE_WORDS",
    "RetractGraphLayout",
    "instruction_text",
    "place_name",
    "plot_retract_graph",
    "point_name",
    "route_points",
    "schedule_points",
    "vertex_name",
]

#: What each of the planner's three instructions on ``G_k`` does (docs/star.md, 'The three rules').
RULE_WORDS = {
    Instruction.SHORTEST: "rule 1, the one shortest route",
    Instruction.TWO_TIED: "rule 2, two shortest routes tie: the larger ∫w wins",
    Instruction.MANY_TIED: "rule 3, three or more tie: the fixed choice",
}
#: How far the longest edge (across all ``k`` columns or rows) bows out of its straight line, cells.
BOW = 0.4
#: Samples of a whole edge's arc.
_EDGE_SAMPLES = 33
#: Most schedule samples retracted onto ``G_k``.
_MAX_PATH_SAMPLES = 2000
#: Vertex names are written beside every vertex up to this many legs, else beside the route's only.
_NAMED_UP_TO = 5


def vertex_name(graph: StarGraph, c: IndexedConfiguration) -> str:
    """A vertex's name: ``P(i,j)``, ``V1(j)`` (vehicle 1 at O) or ``V2(i)`` (vehicle 2 at O)."""
    names = graph.names
    if c[0] == JUNCTION_INDEX:
        return f"V1({names[c[2]]})"
    if c[2] == JUNCTION_INDEX:
        return f"V2({names[c[0]]})"
    return f"P({names[c[0]]},{names[c[2]]})"


def place_name(graph: StarGraph, c: IndexedConfiguration) -> str:
    """A vertex in plain words: ``(N, S)``, where vehicle 1 and vehicle 2 wait (``O``: the junction)."""
    return "({}, {})".format(*("O" if c[k] == JUNCTION_INDEX else graph.names[c[k]] for k in (0, 2)))


def point_name(graph: StarGraph, point: GraphPoint, *, plain: bool = False) -> str:
    """A point of ``G_k`` for people: a vertex's name, or the metres from its peak towards its valley.

    ``plain``: the vertices named by :func:`place_name` (``(N, S)``), else by :func:`vertex_name`.
    """
    name, retract = place_name if plain else vertex_name, graph.retract_graph
    if point.vertex >= 0:
        return name(graph, retract.vertices[point.vertex])
    peak, valley = (name(graph, retract.vertices[v]) for v in retract.edges[point.edge])
    return f"{point.offset:.3g} m from {peak} towards {valley}"


@dataclass(frozen=True, slots=True, eq=False)
class RetractGraphLayout(ArrayValue):
    """The drawing of a track's retract graph ``G_k`` as a table: where each point of ``G_k`` is drawn.

    Build with :meth:`of`. Drawing units are cells: the row (vehicle 1) or column
    (vehicle 2) of ``O`` is 0, of leg ``i`` is ``i + 1``; ``x`` is the column, ``y``
    minus the row.

    Attributes
    ----------
    graph : StarGraph
    vertices : ndarray, shape (k (k + 1), 2)
        Where each vertex is drawn, in the order of ``graph.retract_graph.vertices``.
    edges : tuple of (int, int), shape (2 k (k - 1),)
        ``(peak, valley)`` of each edge, as ``graph.retract_graph.edges``.
    controls : ndarray, shape (2 k (k - 1), 2)
        The control point of each edge's arc (a quadratic Bézier curve from its
        peak to its valley).
    """

    graph: StarGraph
    vertices: np.ndarray = field(repr=False)
    edges: tuple[tuple[int, int], ...] = field(repr=False)
    controls: np.ndarray = field(repr=False)
    _incident: tuple[tuple[int, ...], ...] = field(repr=False, compare=False)

    @classmethod
    def of(cls, graph: StarGraph) -> RetractGraphLayout:
        """The layout of ``graph``'s retract graph (any number of legs; the plots use it from four)."""
        if not isinstance(graph, StarGraph):
            raise InputError(f"a retract graph layout needs a StarGraph, got {type(graph).__name__}")
        retract = graph.retract_graph
        vertices = readonly([cls.cell(c[0], c[2]) for c in retract.vertices], dtype=float)
        controls = []
        incident: list[list[int]] = [[] for _ in retract.vertices]
        rise = 2.0 * BOW / graph.leg_count  # control point offset per cell of length: the bow is half
        for e, (peak, valley) in enumerate(retract.edges):
            a, b = vertices[peak], vertices[valley]
            chord = b - a
            # bowed towards the deleted point: rows upwards, columns leftwards
            normal = np.array([0.0, 1.0]) if chord[1] == 0.0 else np.array([-1.0, 0.0])
            controls.append(0.5 * (a + b) + rise * float(np.hypot(*chord)) * normal)
            incident[peak].append(e)
            incident[valley].append(e)
        return cls(graph, vertices, retract.edges, readonly(controls), tuple(tuple(i) for i in incident))

    @staticmethod
    def cell(first: int, second: int) -> tuple[float, float]:
        """Where vehicle 1 at ``first`` and vehicle 2 at ``second`` are drawn (leg index, -1 for O)."""
        return (float(second + 1), -float(first + 1))

    # -- points of G_k -------------------------------------------------------
    def edge_point(self, edge: int, fraction) -> np.ndarray:
        """Points ``fraction`` of the way along an edge's arc (0: its peak, 1: its valley), shape (..., 2)."""
        t = np.asarray(fraction, dtype=float)[..., None]
        peak, valley = (self.vertices[v] for v in self.edges[edge])
        return (1.0 - t) ** 2 * peak + 2.0 * t * (1.0 - t) * self.controls[edge] + t**2 * valley

    def edge_curve(self, edge: int, start: float = 0.0, end: float = 1.0) -> np.ndarray:
        """The arc of an edge from fraction ``start`` to ``end`` (0 at the peak), shape (n, 2)."""
        count = max(2, math.ceil(abs(end - start) * (_EDGE_SAMPLES - 1)) + 1)
        return self.edge_point(edge, np.linspace(start, end, count))

    def fraction(self, point: GraphPoint, edge: int) -> float:
        """How far along ``edge`` (0 at its peak, 1 at its valley) a point of it lies."""
        if point.vertex >= 0:
            peak, valley = self.edges[edge]
            if point.vertex not in (peak, valley):
                raise InputError(f"vertex {point.vertex} is not an end of edge {edge}")
            return 0.0 if point.vertex == peak else 1.0
        if point.edge != edge:
            raise InputError(f"point {point} is not on edge {edge}")
        return point.offset / float(self.graph.retract_graph.edge_lengths[edge])

    def point(self, point: GraphPoint) -> np.ndarray:
        """Where a point of ``G_k`` is drawn, shape (2,)."""
        if point.vertex >= 0:
            return self.vertices[point.vertex]
        return self.edge_point(point.edge, self.fraction(point, point.edge))

    def _edges_of(self, point: GraphPoint) -> tuple[int, ...]:
        return self._incident[point.vertex] if point.vertex >= 0 else (point.edge,)

    def path(self, points: Sequence[GraphPoint]) -> np.ndarray:
        """A polyline through points of ``G_k`` in order, along the arcs, shape (n, 2).

        Two consecutive points on one edge are joined along its arc; two on edges that
        meet at a vertex, through that vertex; others (a gap in the samples) straight.
        """
        if not points:
            return np.zeros((0, 2))
        line = [self.point(points[0])[None, :]]
        for a, b in itertools.pairwise(points):
            common = sorted(set(self._edges_of(a)) & set(self._edges_of(b)))
            if common:
                edge = common[0]
                line.append(self.edge_curve(edge, self.fraction(a, edge), self.fraction(b, edge))[1:])
                continue
            shared = (
                set(self.edges[a.edge]) & set(self.edges[b.edge]) if a.vertex < 0 and b.vertex < 0 else set()
            )
            if shared:
                vertex = GraphPoint(shared.pop(), -1, 0.0)
                line.append(
                    self.edge_curve(a.edge, self.fraction(a, a.edge), self.fraction(vertex, a.edge))[1:]
                )
                line.append(
                    self.edge_curve(b.edge, self.fraction(vertex, b.edge), self.fraction(b, b.edge))[1:]
                )
            else:
                line.append(self.point(b)[None, :])
        return np.concatenate(line)


def route_points(route: Route) -> tuple[GraphPoint, ...]:
    """The route's part on ``G_k``: the start's retraction, the vertices passed, the goal's retraction.

    Read from the route's waypoints (the planner puts ``retract(start)``, the route on
    ``G_k`` and ``reversed(retract(goal))`` one after the other); shape (m,), ``m >= 1``.
    A start or goal retracting onto a vertex is that vertex (it appears once).
    """
    graph = route.graph
    tuples = route.indexed_waypoints
    origin = retract_indexed(tuples[0], graph.lengths)[-1]
    target = retract_indexed(tuples[-1], graph.lengths)[-1]
    first = next((k for k, c in enumerate(tuples) if step(c, origin) == 0.0), len(tuples))
    last = max((k for k, c in enumerate(tuples) if step(c, target) == 0.0), default=-1)
    if first > last:
        raise InputError(
            f"the route does not pass the start's retraction {origin} and then the goal's {target}: "
            "expected a route from topology.plan"
        )
    locate = graph.retract_graph.locate
    return tuple(locate(c) for c in tuples[first : last + 1])


def _retracted(graph: StarGraph, c: IndexedConfiguration) -> GraphPoint | None:
    try:
        return graph.retract_graph.locate(retract_indexed(c, graph.lengths)[-1])
    except ValueError:  # a configuration whose retraction misses a leg's end by a round-off
        return None


def schedule_points(verified: VerifiedSchedule, *, count: int = _MAX_PATH_SAMPLES) -> list[GraphPoint]:
    """The retractions onto ``G_k`` of a verified schedule's configurations at up to ``count`` instants."""
    schedule = require_verified(verified, "schedule_points").schedule
    graph = schedule.route.graph
    lengths = graph.lengths
    samples = max(2, min(count, int(schedule.duration / plot_period(schedule.duration)) + 1))
    state = schedule.state(np.linspace(0.0, schedule.duration, samples))
    points = []
    for k in range(state.t.size):
        place = []
        for v in range(2):
            leg = int(state.leg[v, k])
            s = 0.0 if leg == JUNCTION_INDEX else min(max(float(state.s[v, k]), 0.0), lengths[leg])
            place += [leg if s > 0.0 else JUNCTION_INDEX, s]
        point = _retracted(graph, (place[0], place[1], place[2], place[3]))
        if point is not None:
            points.append(point)
    return points


# -- the picture -----------------------------------------------------------------------------------
#: Colours of the route on G_k (and its arrows) and of the schedule's path retracted onto it.
_ROUTE_COLOUR = "tab:green"
_ARROW_COLOUR = "darkgreen"
_SCHEDULE_COLOUR = "black"
_EDGE_ALPHA = 0.45
#: Size of the picture, inches.
_WIDTH_IN, _HEIGHT_IN = 8.6, 10.6
#: Width of the note under the picture, inches.
_FOOTNOTE_IN = 8.0


#: How to read the picture, in plain words (the paper's notation is in docs/star.md); ``{0}``, ``{1}``:
#: the vehicles' names.
_FOOTNOTE = (
    "How to read it: each point is a pair of places where {0} and {1} wait, {0} down the rows, {1} "
    "across the columns (O: at the junction; a leg's name: at its far end). Along a line one vehicle "
    "drives its leg while the other waits at a leg's end: {0} along a column (blue), {1} along a row "
    "(orange). (O, O), both at the junction, is never allowed; × (both at one leg's end) is no place. "
    "Every position of the two moves out onto these lines without the vehicles coming closer: the route "
    "is the start moved out, a route along the lines, and the goal moved out, played backwards. Lines "
    "are arcs, not to scale: one from row i up to O is as long as leg i, one from column j across to O "
    "as long as leg j (the headers give the lengths). The paper's names for these parts: docs/star.md."
)
#: Width of the places the route passes, in the legend, inches (clear of the drawing of the track).
_LEGEND_IN = 5.0
#: The smallest font the words in the table shrink to, points.
_SMALLEST_LABEL = 5.5


def _draw_table(axis, layout: RetractGraphLayout, who: tuple[str, str], *, named: set[int]) -> None:
    """Headers, the deleted point, the empty diagonal, the edges, the vertices (``named``: with names)."""
    graph = layout.graph
    k = graph.leg_count
    retract = graph.retract_graph
    small = k > _NAMED_UP_TO
    for e, (_, valley) in enumerate(layout.edges):
        driver = 0 if retract.vertices[valley][0] == JUNCTION_INDEX else 1  # V1: vehicle 1 drives its leg
        axis.plot(
            *layout.edge_curve(e).T,
            color=VEHICLE_COLOURS[driver],
            alpha=_EDGE_ALPHA,
            linewidth=0.7 if small else 1.1,
            zorder=1,
        )
    heading = 9 if small else 11
    for place, name in ((JUNCTION_INDEX, "O"), *enumerate(graph.names)):
        text = name if place == JUNCTION_INDEX else f"{name}\n{graph.lengths[place]:g} m"
        column, _ = layout.cell(0, place)
        _, row = layout.cell(place, 0)
        for x, y, ha, va, vehicle in (
            (column, 0.3, "center", "bottom", 1),
            (-0.3, row, "right", "center", 0),
        ):
            axis.text(
                x, y, text, ha=ha, va=va, fontsize=heading, weight="bold", color=VEHICLE_COLOURS[vehicle]
            )
        if place != JUNCTION_INDEX:
            axis.plot(*layout.cell(place, place), marker="x", color="0.7", markersize=7, zorder=2)
    axis.text(
        0.5 * (k + 1),
        0.95,
        f"{who[1]} at:  O (the junction) or the end of leg …",
        ha="center",
        va="bottom",
        fontsize=10,
        color=VEHICLE_COLOURS[1],
    )
    axis.plot([0.0], [0.0], "o", markersize=10, markerfacecolor="white", markeredgecolor="0.3", zorder=3)
    peaks = np.array([layout.vertices[v] for v, c in enumerate(retract.vertices) if JUNCTION_INDEX not in c])
    valleys = np.array([layout.vertices[v] for v, c in enumerate(retract.vertices) if JUNCTION_INDEX in c])
    size = 4 if small else 5
    axis.plot(*peaks.T, "o", color="0.25", markersize=size, zorder=3, label="both at leg ends")
    axis.plot(
        *valleys.T,
        "s",
        markerfacecolor="white",
        markeredgecolor="0.25",
        markersize=size + 1,
        zorder=3,
        label="one at the junction O, the other at a leg's end",
    )
    for v in sorted(named):
        x, y = layout.vertices[v]
        axis.text(
            x + 0.07, y - 0.09, place_name(graph, retract.vertices[v]), ha="left", va="top", fontsize=7,
            color="0.35",
        )  # fmt: skip


def _arrow(axis, line: np.ndarray) -> None:
    """An arrowhead half way along a polyline (by its length), in its direction."""
    lengths = np.hypot(*np.diff(line, axis=0).T)
    total = float(lengths.sum())
    if total <= 1e-9:
        return
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    k = int(np.searchsorted(cumulative, 0.5 * total, side="right")) - 1
    k = min(max(k, 0), len(lengths) - 1)
    while lengths[k] <= 0.0:
        k -= 1
    direction = (line[k + 1] - line[k]) / lengths[k]
    tip = line[k] + (0.5 * total - cumulative[k]) * direction
    axis.annotate(
        "",
        xy=tip,
        xytext=tip - 1e-3 * direction,
        arrowprops={"arrowstyle": "-|>", "color": _ARROW_COLOUR, "mutation_scale": 20, "linewidth": 0},
        zorder=6,
    )


def _route_label(graph: StarGraph, points: tuple[GraphPoint, ...], route: Route) -> str:
    """The legend's words on the route: its length along the lines and the places it passes, numbered."""
    vertices = [graph.retract_graph.vertices[p.vertex] for p in points if p.vertex >= 0]
    # no-break spaces within a step: the lines break between steps only
    steps = [f"{n} {place_name(graph, c)}".replace(" ", "\u00a0") for n, c in enumerate(vertices, start=1)]
    passing = wrapped(", ".join(steps), width_in=_LEGEND_IN, fontsize=8).replace("\n", "\n   ")
    head = f"route along the lines: {route.arc_length:.4g} m"
    return (
        f"{head} ({route.length:.4g} m of travel in all), passing\n   {passing}"
        if steps
        else f"{head}, through no place"
    )


def _draw_route(axis, layout: RetractGraphLayout, points: tuple[GraphPoint, ...], label: str) -> list:
    """The route on G_k: a thick line, an arrow on each piece, its vertices numbered in order (returned)."""
    axis.plot(
        *layout.path(points).T,
        color=_ROUTE_COLOUR,
        linewidth=5,
        alpha=0.75,
        solid_capstyle="round",
        solid_joinstyle="round",
        zorder=4,
        label=label,
    )
    for a, b in itertools.pairwise(points):
        _arrow(axis, layout.path([a, b]))
    graph = layout.graph
    named = graph.leg_count <= _NAMED_UP_TO
    vertices = [p.vertex for p in points if p.vertex >= 0]
    numbers = []
    for number, v in enumerate(vertices, start=1):
        c = graph.retract_graph.vertices[v]
        name = place_name(graph, c)
        above = JUNCTION_INDEX not in c  # clear of the vertex's edges and the headers: valleys below right
        numbered = axis.annotate(
            f"{number} {name}" if named else str(number),
            tuple(layout.vertices[v]),
            xytext=(6, 6 if above else -6),
            textcoords="offset points",
            ha="left",
            va="bottom" if above else "top",
            fontsize=8 if named else 9,
            weight="bold",
            color=_ARROW_COLOUR,
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.85},
            zorder=8,
        )
        numbers.append((numbered, str(number)))
    return numbers


def _draw_track(figure, graph: StarGraph, route: Route, box: tuple[float, float, float, float]) -> None:
    """A small drawing of the track from above: each vehicle's start (ring) and goal (dot)."""
    axis = figure.add_axes(box)
    axis.set_aspect("equal")
    axis.set_axis_off()
    reach = max(graph.lengths)
    for name, length, angle in zip(graph.names, graph.lengths, np.radians(graph.angles_deg), strict=True):
        direction = np.array([math.cos(angle), math.sin(angle)])
        axis.plot(*np.array([[0.0, 0.0], length * direction]).T, color="0.75", linewidth=3, zorder=1)
        axis.text(*(length * direction + 0.3 * reach * direction), name, ha="center", va="center", fontsize=8)
    axis.plot([0.0], [0.0], "o", color="white", markeredgecolor="0.3", markersize=4, zorder=2)
    for v in range(2):
        colour = VEHICLE_COLOURS[v]
        x, y = graph.xy(route.start[v])
        axis.plot(
            x, y, "o", markersize=9, markerfacecolor="none", markeredgecolor=colour, markeredgewidth=1.5
        )
        x, y = graph.xy(route.goal[v])
        axis.plot(x, y, "o", markersize=4.5, color=colour, zorder=3)
    limit = 1.4 * reach
    axis.set_xlim(-limit, limit)
    axis.set_ylim(-limit, limit)
    axis.text(0.5, -0.06, "the track: start ring, goal dot", transform=axis.transAxes, ha="center", va="top",
              fontsize=7.5)  # fmt: skip


def instruction_text(route: Route) -> str:
    """Which of the planner's instructions chose the route (or would have, for the other class), for a title.

    Examples
    --------
    >>> from topology import Configuration, Position, StarGraph, plan
    >>> crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    >>> start = Configuration(Position("N", 10.0), Position("S", 10.0))
    >>> instruction_text(plan(crossing, start, start.swapped()))
    "the planner's instruction: rule 1, the one shortest route"
    """
    words = RULE_WORDS[route.instruction]
    if route.homotopy is Homotopy.OTHER:
        return f"the planner's instruction: {words}; this route is the next shortest"
    return f"the planner's instruction: {words}"


def configuration_subject(
    subject: Route | VerifiedSchedule, names: tuple[str, str] | None
) -> tuple[Route, VerifiedSchedule | None]:
    """The route and, for a schedule, the verified schedule of a configuration plot's subject.

    Raises
    ------
    UnverifiedScheduleError
        ``subject`` is a schedule that has not been certified.
    InputError
        ``names`` is not two strings.
    """
    if names is not None and (
        not isinstance(names, (tuple, list)) or len(names) != 2 or not all(isinstance(n, str) for n in names)
    ):
        raise InputError(f"configuration plot names must be two strings, got {names!r}")
    if isinstance(subject, Route):
        return subject, None
    verified = require_verified(subject, "plot_configuration")
    return verified.schedule.route, verified


def plot_retract_graph(
    subject: Route | VerifiedSchedule, *, names: tuple[str, str] | None = None, figure=None
):
    """The retract graph ``G_k`` drawn as a table with the route on it.

    Drawn (see :class:`RetractGraphLayout`): the ``k (k + 1)`` vertices and ``2 k (k - 1)``
    edges of ``G_k`` (each edge in the colour of the vehicle that drives its leg on it), the
    route's part on ``G_k`` from the start's retraction (ring) through the vertices it
    passes (numbered in order) to the goal's retraction (dot), for a schedule also its
    path retracted onto ``G_k``, and a small drawing of the track. The title says which of
    the planner's three instructions chose the route. Vertex names are written beside
    every vertex up to five legs, beside the route's vertices only for more.

    Parameters
    ----------
    subject : Route or VerifiedSchedule
        A route from :func:`topology.plan`, or a schedule from :func:`trajgen.certify`.
    names : pair of str, optional
        The vehicles' names, for the title (default: "vehicle 1", "vehicle 2").

    figure : matplotlib Figure or SubFigure, optional
        Where to draw (default: a new Figure of of the table's size inches).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    UnverifiedScheduleError
        ``subject`` is a schedule that has not been certified.
    InputError
        ``subject`` is neither a Route nor a VerifiedSchedule, or ``names`` is not two strings.
    """
    route, verified = configuration_subject(subject, names)
    graph = route.graph
    k = graph.leg_count
    layout = RetractGraphLayout.of(graph)
    points = route_points(route)
    passed = {p.vertex for p in points if p.vertex >= 0}
    who = ("vehicle 1", "vehicle 2") if names is None else (names[0], names[1])
    area = drawing_area(figure, figsize=(_WIDTH_IN, _HEIGHT_IN))
    axis = area.add_axes((0.02, 0.27, 0.96, 0.655))
    axis.set_aspect("equal")
    axis.set_axis_off()
    axis.set_xlim(-1.5, k + 0.55)
    axis.set_ylim(-(k + 0.45), 1.3)
    unnamed = set() if k > _NAMED_UP_TO else set(range(len(layout.vertices))) - passed
    _draw_table(axis, layout, who, named=unnamed)
    for v in range(2):
        label = f"{who[v]} drives its leg, {who[1 - v]} waits"
        axis.plot([], [], color=VEHICLE_COLOURS[v], alpha=_EDGE_ALPHA, label=label)
    numbers = _draw_route(axis, layout, points, _route_label(graph, points, route))
    if verified is not None:
        schedule = verified.schedule
        axis.plot(
            *layout.path(schedule_points(verified)).T,
            color=_SCHEDULE_COLOUR,
            linewidth=1.2,
            linestyle="--",
            zorder=5,
            label=f"{schedule.method.name} schedule's path ({schedule.duration:.2f} s), moved to the lines",
        )
    axis.plot(
        *layout.point(points[0]),
        "o",
        markersize=13,
        markerfacecolor="none",
        markeredgecolor="black",
        markeredgewidth=2,
        zorder=7,
        label=f"start {route.start}, moved out to {point_name(graph, points[0], plain=True)}",
    )
    axis.plot(
        *layout.point(points[-1]),
        "o",
        markersize=8,
        color="black",
        zorder=7,
        label=f"goal {route.goal}, moved out to {point_name(graph, points[-1], plain=True)}",
    )
    axis.legend(loc="upper left", bbox_to_anchor=(0.0, -0.005), fontsize=8, frameon=False)
    _draw_track(area, graph, route, (0.8, 0.11, 0.18, 0.13))
    places = f"{len(layout.vertices)} places, {len(layout.edges)} lines between them: {k} legs"
    axis.set_title(
        f"Where {who[0]} and {who[1]} wait ({places})\neach point is (position of {who[0]}: its row, "
        f"position of {who[1]}: its column)\n{instruction_text(route)}",
        fontsize=11,
    )
    words = [*axis.texts, *area.axes[-1].texts]  # the table's and the track's
    if not untangle(words, smallest=_SMALLEST_LABEL):  # long names: the route's places by number only
        for text, number in numbers:
            text.set_text(number)
        untangle(words, smallest=_SMALLEST_LABEL)
    footnote = wrapped(_FOOTNOTE.format(*who), width_in=_FOOTNOTE_IN, fontsize=7.5)
    area.text(0.03, 0.012, footnote, fontsize=7.5, va="bottom", family="sans-serif")
    return finished(area, laid_out=False)  # its axes are placed by hand
