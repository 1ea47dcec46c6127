"""The node and edge graph of each vehicle's VDA 5050 path, from its verified schedule.

Each vehicle's nodes are where its verified schedule starts, reverses, stops,
passes the junction ``O`` and ends (on the legs of the schedule's route,
``schedule.route``: ``optimal`` may take the other homotopy class and reverse
shallower than the planner's waypoints), plus a *hold node* where the path
crosses the edge of the junction zone, at the minimum separation from ``O``:
there a vehicle can wait while the other passes the junction. Positions within
:data:`NODE_TOLERANCE` of one of the route's waypoints, of a leg's end or of the
junction are snapped to it. Each edge carries the highest speed the schedule
reaches on it (``maxSpeed``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from topology import JUNCTION_INDEX, JUNCTION_NAME, Option, StarGraph
from trajgen.model.pieces import Pieces, shift
from trajgen.model.polynomials import derivative, evaluate, extrema, root_in
from trajgen.model.schedule import Schedule

__all__ = [
    "HOLD_MARGIN",
    "NODE_TOLERANCE",
    "NodeKind",
    "OrderPath",
    "PathEdge",
    "PathNode",
    "hold_description",
    "metres_text",
    "node_id",
    "vehicle_path",
]


def metres_text(value: float, places: int = 6) -> str:
    """Metres as a VDA 5050 id or description writes them: ``places`` decimals, trailing zeros dropped.

    Examples
    --------
    >>> metres_text(1.5), metres_text(10.0), metres_text(1.5000004), metres_text(-0.0)
    ('1.5', '10', '1.5', '0')
    """
    text = f"{value:.{places}f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def hold_description(metres: float) -> str:
    """A junction's hold node in words: ``hold: 1.5 m from the junction (the minimum separation)``."""
    return f"hold: {metres_text(metres)} m from the junction (the minimum separation)"


def node_id(graph: StarGraph, leg: int, s: float) -> str:
    """The id of the node at ``s`` metres on leg ``leg``: ``"O"`` or ``"<leg name>:<metres>"`` (µm).

    Examples
    --------
    >>> node_id(StarGraph({"A": 10.0, "B": 10.0, "C": 10.0}), 0, 1.5)
    'A:1.5'
    >>> node_id(StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}), 3, 10.0)
    'E:10'
    """
    if leg == JUNCTION_INDEX or s == 0.0:
        return JUNCTION_NAME
    return f"{graph.names[leg]}:{metres_text(s)}"


#: Reversals shorter than this are round-off; nodes this close to each other, to a route waypoint,
#: a leg's end or the junction are one, metres.
NODE_TOLERANCE = 1e-6
#: No hold node is placed within this of another node, metres.
HOLD_MARGIN = 1e-3
#: A stretch of a piece moving less than this is at rest, metres.
_REST_MOVE = 1e-9


class NodeKind(Option):
    """Why a node is on a vehicle's path."""

    START = "start"
    GOAL = "goal"
    JUNCTION = "junction"  #: the vehicle passes (or stops at) the junction O
    REVERSAL = "reversal"  #: the vehicle reverses
    STOP = "stop"  #: the vehicle stops, and goes on in the same direction
    HOLD = "hold"  #: the edge of the junction zone, the minimum separation from O
    RELEASE = "release"  #: a node only for a finer release of the base (``spacing``)


@dataclass(frozen=True, slots=True)
class PathNode:
    """A node of one vehicle's path.

    Attributes
    ----------
    leg : int
        Leg index, ``JUNCTION_INDEX`` at the junction.
    s : float
        Distance from the junction, metres.
    axis : float
        The vehicle's signed axis there, metres.
    arrival, departure : float
        When the schedule reaches and leaves the node, seconds.
    kinds : tuple of NodeKind
    """

    leg: int
    s: float
    axis: float
    arrival: float
    departure: float
    kinds: tuple[NodeKind, ...]

    @property
    def claim(self) -> tuple[int, float, float]:
        """The node as a stretch ``(leg, s, s)`` of no length."""
        return (self.leg, self.s, self.s)


@dataclass(frozen=True, slots=True)
class PathEdge:
    """An edge of one vehicle's path, from node ``index`` to node ``index + 1`` (on one leg).

    Attributes
    ----------
    index : int
    leg : int
        The leg (``JUNCTION_INDEX`` only for an edge of zero length at the junction).
    low, high : float
        The stretch of the leg it covers, metres from the junction.
    max_speed : float
        Highest speed the schedule reaches on it, m/s, at most the vehicle's limit (rounded up to 1 µm/s).
    backward : bool
        Whether the vehicle drives it against the direction of its first move.
    """

    index: int
    leg: int
    low: float
    high: float
    max_speed: float
    backward: bool

    @property
    def length(self) -> float:
        """Metres."""
        return self.high - self.low

    @property
    def claim(self) -> tuple[int, float, float]:
        """The stretch ``(leg, low, high)`` the vehicle may be on while it drives the edge."""
        return (self.leg, self.low, self.high)


@dataclass(frozen=True, slots=True)
class OrderPath:
    """One vehicle's nodes and edges on a junction (``len(edges) == len(nodes) - 1``).

    Its order elements are read through the methods a track graph's
    :class:`~trajgen.export.vda5050.graph_path.GraphOrderPath` has too: :meth:`node_id`,
    :meth:`node_xy`, :meth:`node_description`, :meth:`edge_direction`.
    """

    track: StarGraph
    nodes: tuple[PathNode, ...]
    edges: tuple[PathEdge, ...]

    def node_id(self, index: int) -> str:
        """Node ``index``'s id: ``"O"`` or ``"<leg name>:<metres>"`` (:func:`node_id`)."""
        node = self.nodes[index]
        return node_id(self.track, node.leg, node.s)

    def node_xy(self, index: int) -> tuple[float, float]:
        """Node ``index``'s x/y, metres: on its leg's line at the leg's angle, the junction at the origin."""
        node = self.nodes[index]
        angle = math.radians(self.track.angles_deg[node.leg]) if node.leg != JUNCTION_INDEX else 0.0
        return (node.s * math.cos(angle), node.s * math.sin(angle))

    def node_description(self, index: int) -> str:
        """Why node ``index`` is on the path, in words (``nodeDescription``)."""
        parts = []
        for kind in self.nodes[index].kinds:
            if kind is NodeKind.HOLD:
                parts.append(hold_description(self.nodes[index].s))
            else:
                parts.append(kind.value)
        return ", ".join(parts)

    def edge_direction(self, index: int) -> str | None:
        """The leg edge ``index`` takes where it leaves the junction (``None`` elsewhere)."""
        start, end = self.nodes[index], self.nodes[index + 1]
        leaving = start.leg == JUNCTION_INDEX and end.leg != JUNCTION_INDEX
        return self.track.names[end.leg] if leaving else None

    @staticmethod
    def gap(first: tuple[int, float, float], second: tuple[int, float, float]) -> float:
        """Track distance between two stretches ``(leg, low, high)`` (leg JUNCTION_INDEX: the point O)."""
        leg_a, low_a, high_a = first
        leg_b, low_b, high_b = second
        if leg_a == leg_b and leg_a != JUNCTION_INDEX:
            return max(0.0, low_b - high_a, low_a - high_b)
        return low_a + low_b


@dataclass(frozen=True, slots=True)
class _Stretch:
    """Part of a piece on which one vehicle's axis is monotone."""

    piece: int
    t0: float
    t1: float
    a0: float
    a1: float
    leg: int
    offset: float
    sign: float

    def s(self, axis: float) -> float:
        return max(self.offset + self.sign * axis, 0.0)


def _stretches(pieces: Pieces, vehicle: int) -> list[_Stretch]:
    """The vehicle's motion cut at every reversal inside a piece, in time order."""
    out = []
    for k in range(pieces.count):
        c = pieces.axis[vehicle, k]
        h = float(pieces.length[k])
        velocity = np.trim_zeros(derivative(c[None])[0], "b")
        cuts = [0.0, h]
        if velocity.size > 1:
            for root in np.roots(velocity[::-1]):
                if abs(root.imag) <= 1e-9 * max(1.0, abs(root)) and 0.0 < root.real < h:
                    cuts.append(float(root.real))
        cuts.sort()
        values = evaluate(c[None], np.array([cuts]))[0]
        start = float(pieces.start[k])
        for (ta, a0), (tb, a1) in itertools.pairwise(zip(cuts, values, strict=True)):
            if tb > ta:
                out.append(
                    _Stretch(
                        k,
                        start + ta,
                        start + tb,
                        float(a0),
                        float(a1),
                        int(pieces.leg[vehicle, k]),
                        float(pieces.s_offset[vehicle, k]),
                        float(pieces.s_sign[vehicle, k]),
                    )
                )
    return out


@dataclass(slots=True)
class _Event:
    leg: int
    s: float
    axis: float
    arrival: float
    departure: float
    kinds: set[NodeKind]


def _same_place(a: _Event, b: _Event) -> bool:
    if abs(a.axis - b.axis) > NODE_TOLERANCE:
        return False
    if a.s <= NODE_TOLERANCE and b.s <= NODE_TOLERANCE:
        return True
    return a.leg == b.leg and abs(a.s - b.s) <= NODE_TOLERANCE


def _merged(events: list[_Event]) -> list[_Event]:
    """Consecutive events at one place (the vehicle not moving between them) as one."""
    out: list[_Event] = []
    for event in events:
        if out and _same_place(out[-1], event):
            last = out[-1]
            last.arrival = min(last.arrival, event.arrival)
            last.departure = max(last.departure, event.departure)
            last.kinds |= event.kinds
            if NodeKind.START in event.kinds or NodeKind.GOAL in event.kinds:  # the route's exact position
                last.leg, last.s = event.leg, event.s
        else:
            out.append(event)
    return out


def _events(schedule: Schedule, pieces: Pieces, vehicle: int) -> list[_Event]:
    """Start, reversals, stops, junction passages and goal of one vehicle, in time order."""
    stretches = _stretches(pieces, vehicle)
    route = schedule.route
    start = route.indexed_waypoints[0][2 * vehicle : 2 * vehicle + 2]
    goal = route.indexed_waypoints[-1][2 * vehicle : 2 * vehicle + 2]
    duration = schedule.duration
    if not stretches:
        first_axis = last_axis = 0.0
    else:
        first_axis, last_axis = stretches[0].a0, stretches[-1].a1
    events = [_Event(start[0], start[1], first_axis, 0.0, 0.0, {NodeKind.START})]
    # reversals: the extremes of the axis, ignoring wiggles below NODE_TOLERANCE
    direction = 0
    anchor = first_axis
    extreme: tuple[float, float, _Stretch] | None = None  # (axis, time, stretch)
    previous_leg = None
    rest: list[_Stretch] = []
    for stretch in stretches:
        for t, a in ((stretch.t0, stretch.a0), (stretch.t1, stretch.a1)):
            if direction == 0:
                if abs(a - anchor) > NODE_TOLERANCE:
                    direction = 1 if a > anchor else -1
                    extreme = (a, t, stretch)
            elif direction * (a - extreme[0]) > 0.0:
                extreme = (a, t, stretch)
            elif direction * (extreme[0] - a) > NODE_TOLERANCE:
                axis, time, where = extreme
                events.append(_Event(where.leg, where.s(axis), axis, time, time, {NodeKind.REVERSAL}))
                direction = -direction
                extreme = (a, t, stretch)
        # stops: stretches at rest, merged
        if abs(stretch.a1 - stretch.a0) <= _REST_MOVE:
            rest.append(stretch)
        else:
            _flush_rest(rest, events)
            rest = []
        # junction passages: a change of leg
        if stretch.leg != JUNCTION_INDEX:
            if previous_leg is not None and stretch.leg != previous_leg:
                events.append(
                    _Event(JUNCTION_INDEX, 0.0, stretch.a0, stretch.t0, stretch.t0, {NodeKind.JUNCTION})
                )
            previous_leg = stretch.leg
    _flush_rest(rest, events)
    events.append(_Event(goal[0], goal[1], last_axis, duration, duration, {NodeKind.GOAL}))
    events.sort(key=lambda event: (event.arrival, event.departure))
    return _merged(events)


def _flush_rest(rest: list[_Stretch], events: list[_Event]) -> None:
    if rest:
        first, last = rest[0], rest[-1]
        kind = NodeKind.JUNCTION if first.s(first.a0) <= NODE_TOLERANCE else NodeKind.STOP
        events.append(_Event(first.leg, first.s(first.a0), first.a0, first.t0, last.t1, {kind}))


def _snap(schedule: Schedule, vehicle: int, event: _Event) -> None:
    """Put an event within NODE_TOLERANCE of the junction, a route waypoint or a leg's end on it."""
    graph = schedule.route.graph
    if event.s <= NODE_TOLERANCE:
        event.leg, event.s = JUNCTION_INDEX, 0.0
        event.kinds.add(NodeKind.JUNCTION)
        return
    places = {graph.lengths[event.leg]} if event.leg != JUNCTION_INDEX else set()
    for waypoint in schedule.route.indexed_waypoints:
        if waypoint[2 * vehicle] == event.leg:
            places.add(waypoint[2 * vehicle + 1])
    nearest = min(places, key=lambda s: abs(s - event.s), default=None)
    if nearest is not None and abs(nearest - event.s) <= NODE_TOLERANCE:
        event.s = nearest


def _edge_leg(a: _Event | PathNode, b: _Event | PathNode) -> int:
    return a.leg if a.leg != JUNCTION_INDEX else b.leg


def _crossings(
    pieces: Pieces, vehicle: int, t0: float, t1: float, leg: int, places: np.ndarray
) -> np.ndarray:
    """The times in ``[t0, t1]`` at which the vehicle is at each of ``places`` (s on ``leg``, m).

    Its s is monotone there. Shape of ``places`` and of the result (n,); NaN where it is not
    there. All places and pieces are searched in one vectorized root search.
    """
    overlapping = (pieces.start < t1) & (pieces.start + pieces.length > t0)
    candidates = np.nonzero(overlapping & (pieces.leg[vehicle] == leg) & (pieces.s_sign[vehicle] != 0.0))[0]
    times = np.full(places.shape, np.nan)
    if candidates.size == 0 or places.size == 0:
        return times
    # one row per (piece, place), pieces in time order: the first piece with a root wins
    sign = pieces.s_sign[vehicle, candidates]
    low = np.maximum(t0 - pieces.start[candidates], 0.0)
    high = np.minimum(t1 - pieces.start[candidates], pieces.length[candidates])
    rows = np.repeat(pieces.axis[vehicle, candidates], places.size, axis=0)
    rows[:, 0] -= ((places[None, :] - pieces.s_offset[vehicle, candidates][:, None]) / sign[:, None]).ravel()
    roots = root_in(rows, np.repeat(low, places.size), np.repeat(high, places.size))
    roots = roots.reshape(candidates.size, places.size) + pieces.start[candidates][:, None]
    for row in roots[::-1]:  # the earliest piece's root last, so it is the one kept
        times = np.where(np.isfinite(row), row, times)
    return times


def _with_holds(schedule: Schedule, pieces: Pieces, vehicle: int, events: list[_Event]) -> list[_Event]:
    """Insert a hold node where the path crosses the edge of the junction zone (the separation from O)."""
    radius = schedule.limits.min_separation
    inserted: list[list[tuple[int, float, float]]] = [[] for _ in events]  # (leg, s, time) after each
    for k, (a, b) in enumerate(itertools.pairwise(events)):
        low, high = sorted((a.s, b.s))
        if low < radius - HOLD_MARGIN and high > radius + HOLD_MARGIN:
            leg = _edge_leg(a, b)
            time = _crossings(pieces, vehicle, a.departure, b.arrival, leg, np.array([radius]))[0]
            if np.isfinite(time):
                inserted[k].append((leg, radius, float(time)))
    return _inserted(schedule, vehicle, events, inserted, NodeKind.HOLD)


def _with_spacing(
    schedule: Schedule, pieces: Pieces, vehicle: int, events: list[_Event], spacing: float
) -> list[_Event]:
    """Insert release nodes so that no edge is longer than ``spacing`` metres."""
    inserted: list[list[tuple[int, float, float]]] = [[] for _ in events]  # (leg, s, time) after each
    for k, (a, b) in enumerate(itertools.pairwise(events)):
        count = math.ceil(abs(b.s - a.s) / spacing - 1e-9)
        if count < 2:
            continue
        leg = _edge_leg(a, b)
        places = a.s + (b.s - a.s) * np.arange(1, count) / count
        times = _crossings(pieces, vehicle, a.departure, b.arrival, leg, places)
        found = np.isfinite(times)
        inserted[k] += [(leg, float(p), float(t)) for p, t in zip(places[found], times[found], strict=True)]
    return _inserted(schedule, vehicle, events, inserted, NodeKind.RELEASE)


def _inserted(
    schedule: Schedule,
    vehicle: int,
    events: list[_Event],
    inserted: list[list[tuple[int, float, float]]],
    kind: NodeKind,
) -> list[_Event]:
    """``events`` with the new nodes ``inserted[k]`` (leg, s, time) after event ``k``, of ``kind``."""
    times = np.array([time for new in inserted for _, _, time in new])
    axes = iter(schedule.state(times).axis[vehicle] if times.size else ())
    out = []
    for event, new in zip(events, inserted, strict=True):
        out.append(event)
        out += [_Event(leg, s, float(next(axes)), time, time, {kind}) for leg, s, time in new]
    return out


def _max_speed(pieces: Pieces, vehicle: int, t0: float, t1: float) -> float:
    """Highest |velocity| of the vehicle in ``[t0, t1]``, m/s (closed form, piece by piece)."""
    mask = (pieces.start < t1) & (pieces.start + pieces.length > t0)
    if not mask.any():
        return 0.0
    starts = pieces.start[mask]
    low = np.maximum(t0 - starts, 0.0)
    high = np.minimum(t1 - starts, pieces.length[mask])
    c = shift(pieces.axis[vehicle][mask], low)
    v_low, _, v_high, _ = extrema(derivative(c), np.maximum(high - low, 0.0))
    return float(np.max(np.maximum(np.abs(v_low), np.abs(v_high))))


def vehicle_path(
    schedule: Schedule, pieces: Pieces, vehicle: int, *, spacing: float | None = None
) -> OrderPath:
    """The nodes and edges of ``vehicle``'s (0 or 1) VDA 5050 path (see the module's description).

    Parameters
    ----------
    schedule : Schedule
        A verified schedule.
    pieces : Pieces
        ``schedule_pieces(schedule)``.
    vehicle : int
        0 or 1.
    spacing : float, optional
        Longest edge, metres: longer ones get release nodes between (``None``: none). Base is
        released node by node, so finer nodes let a vehicle follow the other more closely.

    Returns
    -------
    OrderPath
    """
    events = _events(schedule, pieces, vehicle)
    for event in events:
        _snap(schedule, vehicle, event)
    events = _with_holds(schedule, pieces, vehicle, _merged(events))
    if spacing is not None:
        events = _with_spacing(schedule, pieces, vehicle, events, spacing)
    for event in events:  # a stop is named only where nothing else names the node
        if len(event.kinds) > 1:
            event.kinds.discard(NodeKind.STOP)
    nodes = tuple(
        PathNode(e.leg, e.s, e.axis, e.arrival, e.departure, tuple(k for k in NodeKind if k in e.kinds))
        for e in events
    )
    limit = schedule.limits.vehicles[vehicle].max_velocity
    edges = []
    for index, (a, b) in enumerate(itertools.pairwise(nodes)):
        peak = _max_speed(pieces, vehicle, a.departure, b.arrival)
        edges.append(
            PathEdge(
                index=index,
                leg=_edge_leg(a, b),
                low=min(a.s, b.s),
                high=max(a.s, b.s),
                max_speed=min(math.ceil(peak * 1e6) / 1e6, limit),
                backward=b.axis < a.axis,
            )
        )
    return OrderPath(schedule.route.graph, nodes, tuple(edges))
