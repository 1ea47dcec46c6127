"""VDA 5050 2.1.0 orders for both vehicles: nodes and edges of each path, base and horizon, order updates.

A VDA 5050 order carries no timing: a vehicle drives its *base* (released
nodes and edges) at its own pace, at most ``maxSpeed`` on each edge, and
stops at the last base node (the *decision point*) until an order update
extends the base. So the release of the base, not the schedule's timing, is
what keeps the two vehicles apart here:

- **Path.** Each vehicle's nodes are where its verified schedule starts,
  reverses, stops, passes the junction ``O`` and ends (on the legs of the
  schedule's route, ``schedule.route``: ``optimal`` may take the other
  homotopy class and reverse shallower than the planner's waypoints), plus a
  *hold node* where the path crosses the edge of the junction zone, at the
  minimum separation from ``O``: there a vehicle can wait while the other
  passes the junction. Positions within :data:`NODE_TOLERANCE` of one of the
  route's waypoints, of a leg's end or of the junction are snapped to it.
- **Claims.** A vehicle *claims* the stretch of track from the last node it
  reached to its decision point. The claims of the two vehicles never come
  closer than the minimum separation, so whatever the timing of either
  vehicle within its base, they cannot collide.
- **Order of release.** A *node plan* orders the two paths' edges: a
  sequence of moves, each taking one vehicle to its next node while the
  other stands at a node, every move keeping the separation, that follows
  the schedule's order of arrivals wherever the nodes allow it. An edge that
  comes closer than the separation to an edge the plan gives the other
  vehicle first is released only once the other vehicle has left that edge;
  so the vehicles pass the junction in the schedule's order, and the
  releases cannot deadlock. The releases are found by replaying both paths,
  node by node, in the order of the schedule's times, each vehicle waiting
  at its decision point until released (:func:`plan_orders`).

Each update is triggered by the other vehicle reaching a node (its state's
``lastNodeId`` and ``lastNodeSequenceId``); ``send_at`` is the time of that
event in the replay (the schedule's time plus the waits before it), and the
message's ``timestamp`` is the start time plus ``send_at``. A vehicle released
after it reaches its decision point waits there (``wait``): VDA 5050 cannot
express a schedule in which both vehicles are near the junction at once, so a
schedule that does so (``optimal``) is executed a few seconds slower
(:attr:`OrderPlan.planned_duration`).

Renderers return bytes; :func:`write_orders` commits every file of a run
together (:func:`~trajgen.export.atomic.commit_files`).
"""

from __future__ import annotations

import itertools
import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path, PurePosixPath

import numpy as np

from topology import JUNCTION_INDEX, JUNCTION_NAME, Option, StarGraph
from topology.validation import short_repr
from trajgen.errors import OptionError, ScheduleError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.naming import check_vehicle_names
from trajgen.pieces import Pieces, schedule_pieces, shift
from trajgen.polynomials import derivative, evaluate, extrema, root_in
from trajgen.schedule import Schedule
from trajgen.verify import POSITION_TOLERANCE, VerifiedSchedule, require_verified

__all__ = [
    "HOLD_MARGIN",
    "MANIFEST_NAME",
    "MAX_FIRST_HEADER_ID",
    "NODE_TOLERANCE",
    "VDA5050_VERSION",
    "NodeKind",
    "OrderMessage",
    "OrderPath",
    "OrderPlan",
    "PathEdge",
    "PathNode",
    "Release",
    "Vda5050Options",
    "edge_id",
    "node_id",
    "order_files",
    "order_paths",
    "plan_orders",
    "render_manifest",
    "render_orders",
    "write_orders",
]

#: The protocol version written into every message.
VDA5050_VERSION = "2.1.0"
#: Name of the index file written beside the vehicles' folders.
MANIFEST_NAME = "manifest.json"
#: The characters VDA 5050 allows in a serial number (it is part of the MQTT topic).
SERIAL_NUMBER = re.compile(r"[A-Za-z0-9_.:-]+")
#: The years a start time may fall in (its timestamps must stay representable).
FIRST_YEAR, LAST_YEAR = 1970, 9000
#: Reversals shorter than this are round-off; nodes this close to each other, to a route waypoint,
#: a leg's end or the junction are one, metres.
NODE_TOLERANCE = 1e-6
#: No hold node is placed within this of another node, metres.
HOLD_MARGIN = 1e-3
#: Largest ``first_header_id``: header ids are uint32, and a run sends far fewer than a million messages.
MAX_FIRST_HEADER_ID = 2**32 - 1 - 1_000_000
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


@dataclass(frozen=True, slots=True)
class OrderPath:
    """One vehicle's nodes and edges (``len(edges) == len(nodes) - 1``)."""

    nodes: tuple[PathNode, ...]
    edges: tuple[PathEdge, ...]


@dataclass(frozen=True, slots=True)
class Release:
    """One message of one vehicle: the order (``update == 0``) or an order update.

    Attributes
    ----------
    vehicle : int
        0 or 1.
    update : int
        The ``orderUpdateId``.
    first : int
        Index of the first node sent: 0, or the previous decision point (the stitching node).
    decision_point : int
        Index of the last base node.
    send_at : float
        When the release becomes safe in the replay, seconds from the start.
    needed_at : float or None
        When the vehicle leaves the previous decision point in the replay if it need not wait, seconds.
    wait : float
        How long the vehicle waits at the previous decision point, seconds.
    trigger : tuple of (int, int) or None
        ``(other vehicle, node index)``: send when the other vehicle reaches that node;
        ``None``: at the start.
    """

    vehicle: int
    update: int
    first: int
    decision_point: int
    send_at: float
    needed_at: float | None
    wait: float
    trigger: tuple[int, int] | None


@dataclass(frozen=True, slots=True)
class OrderPlan:
    """Both vehicles' paths and every release, in the order they are sent.

    Attributes
    ----------
    paths : tuple of 2 OrderPath
    releases : tuple of Release
        By ``send_at`` (and in the replay's order at equal times).
    planned_duration : float
        When both vehicles reach their goals in the replay (the schedule's duration plus the waits), s.
    """

    paths: tuple[OrderPath, OrderPath]
    releases: tuple[Release, ...]
    planned_duration: float


@dataclass(frozen=True, slots=True, kw_only=True)
class Vda5050Options:
    """How the VDA 5050 messages are written.

    Parameters
    ----------
    start_time : datetime
        When the schedule starts (time zone aware); each message's
        ``timestamp`` is this plus its ``send_at``. Required: the same
        start time gives the same bytes.
    map_id : str
        ``nodePosition.mapId`` (default ``"trajgen"``).
    order_id : str
        Prefix of the ``orderId``: ``<order_id>-<vehicle name>`` (default ``"trajgen"``).
    manufacturers : tuple of 2 str
        ``manufacturer`` of vehicle 1 and vehicle 2 (default ``"unspecified"``).
    serial_numbers : tuple of 2 str or None
        ``serialNumber`` of each vehicle; ``None`` (default): the vehicle names.
    first_header_id : int
        ``headerId`` of each vehicle's first message (default 0); it grows by 1 with each message.
    """

    start_time: datetime
    map_id: str = "trajgen"
    order_id: str = "trajgen"
    manufacturers: tuple[str, str] = ("unspecified", "unspecified")
    serial_numbers: tuple[str, str] | None = None
    first_header_id: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.start_time, datetime) or self.start_time.utcoffset() is None:
            raise OptionError(
                f"VDA 5050 start_time must be a time zone aware datetime, got {short_repr(self.start_time)}"
            )
        try:
            start = self.start_time.astimezone(UTC)
        except OverflowError:
            start = None
        if start is None or not FIRST_YEAR <= start.year <= LAST_YEAR:
            raise OptionError(
                f"VDA 5050 start_time {short_repr(str(self.start_time))} is out of range: expected a time "
                f"from the years {FIRST_YEAR} to {LAST_YEAR} (UTC)"
            )
        object.__setattr__(self, "start_time", start)
        for name in ("map_id", "order_id"):
            _check_text(getattr(self, name), f"VDA 5050 {name}")
        manufacturers = _text_pair(self.manufacturers, "manufacturers")
        for value in manufacturers:
            if any(character in value for character in "/#+"):
                raise OptionError(
                    f"VDA 5050 manufacturer {short_repr(value)} has '/', '#' or '+': it is part of the "
                    "MQTT topic; expected none of them"
                )
        object.__setattr__(self, "manufacturers", manufacturers)
        if self.serial_numbers is not None:
            serials = _text_pair(self.serial_numbers, "serial_numbers")
            for value in serials:
                if not SERIAL_NUMBER.fullmatch(value):
                    raise OptionError(
                        f"VDA 5050 serial number {short_repr(value)} is not allowed: expected the characters "
                        "A-Z a-z 0-9 _ . : - only"
                    )
            if serials[0] == serials[1] and manufacturers[0] == manufacturers[1]:
                raise OptionError(
                    f"VDA 5050 serial numbers are both {serials[0]!r} with one manufacturer: expected "
                    "two vehicles (one MQTT topic each)"
                )
            object.__setattr__(self, "serial_numbers", serials)
        value = self.first_header_id
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_FIRST_HEADER_ID:
            raise OptionError(
                f"VDA 5050 first_header_id must be an integer from 0 to {MAX_FIRST_HEADER_ID:,}, "
                f"got {short_repr(value)}"
            )

    def serial_number(self, vehicle: int, names: tuple[str, str]) -> str:
        """``serialNumber`` of ``vehicle`` (0 or 1) named ``names[vehicle]``."""
        return names[vehicle] if self.serial_numbers is None else self.serial_numbers[vehicle]


def _check_text(value: object, what: str) -> str:
    if not isinstance(value, str) or not value or not value.isprintable():
        raise OptionError(f"{what} must be a non-empty printable string, got {short_repr(value)}")
    return value


def _text_pair(value: object, what: str) -> tuple[str, str]:
    if isinstance(value, str) or not isinstance(value, (tuple, list)) or len(value) != 2:
        raise OptionError(f"VDA 5050 {what} must be a pair of strings (vehicle 1, vehicle 2), got {value!r}")
    return (_check_text(value[0], f"VDA 5050 {what}[0]"), _check_text(value[1], f"VDA 5050 {what}[1]"))


# ---------------------------------------------------------------------------------------------------------
# The path of one vehicle, from its verified schedule


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


def _crossing(pieces: Pieces, vehicle: int, t0: float, t1: float, leg: int, s: float) -> float | None:
    """The time in ``[t0, t1]`` at which the vehicle is at ``s`` on ``leg`` (its s monotone there)."""
    overlapping = (pieces.start < t1) & (pieces.start + pieces.length > t0)
    for piece in np.nonzero(overlapping & (pieces.leg[vehicle] == leg))[0]:
        sign = pieces.s_sign[vehicle, piece]
        if sign == 0.0:
            continue
        low = max(t0 - pieces.start[piece], 0.0)
        high = min(t1 - pieces.start[piece], pieces.length[piece])
        c = pieces.axis[vehicle, piece].copy()
        c[0] -= (s - pieces.s_offset[vehicle, piece]) / sign
        root = root_in(c[None], np.array([low]), np.array([high]))[0]
        if np.isfinite(root):
            return float(pieces.start[piece] + root)
    return None


def _with_holds(schedule: Schedule, pieces: Pieces, vehicle: int, events: list[_Event]) -> list[_Event]:
    """Insert a hold node where the path crosses the edge of the junction zone (the separation from O)."""
    radius = schedule.limits.min_separation
    out = [events[0]]
    for a, b in itertools.pairwise(events):
        low, high = sorted((a.s, b.s))
        if low < radius - HOLD_MARGIN and high > radius + HOLD_MARGIN:
            leg = _edge_leg(a, b)
            time = _crossing(pieces, vehicle, a.departure, b.arrival, leg, radius)
            if time is not None:
                axis = float(schedule.state(time).axis[vehicle, 0])
                out.append(_Event(leg, radius, axis, time, time, {NodeKind.HOLD}))
        out.append(b)
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


def _order_path(schedule: Schedule, pieces: Pieces, vehicle: int) -> OrderPath:
    events = _events(schedule, pieces, vehicle)
    for event in events:
        _snap(schedule, vehicle, event)
    events = _with_holds(schedule, pieces, vehicle, _merged(events))
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
    return OrderPath(nodes, tuple(edges))


# ---------------------------------------------------------------------------------------------------------
# The releases: claims of track that never come closer than the separation, in the schedule's order


def _gap(first: tuple[int, float, float], second: tuple[int, float, float]) -> float:
    """Track distance between two stretches ``(leg, low, high)`` (leg JUNCTION_INDEX: the point O)."""
    leg_a, low_a, high_a = first
    leg_b, low_b, high_b = second
    if leg_a == leg_b and leg_a != JUNCTION_INDEX:
        return max(0.0, low_b - high_a, low_a - high_b)
    return low_a + low_b


class _Replay:
    """Both paths replayed node by node in the schedule's order; a vehicle waits at its decision point.

    The order of the track is a *node plan*: a sequence of moves, each taking one vehicle to its next
    node while the other stands at a node, every move keeping the separation, that follows the
    schedule's order of arrivals wherever the nodes allow it. A vehicle's edge is released once the
    other vehicle has reached the node the plan has it at during that move, and its track keeps the
    separation from the other vehicle's claim; so the replay follows the plan (with more motion at
    once where the claims allow it) and cannot deadlock. "Reached the node" is relaxed to "left every
    edge the plan drives before, and that comes closer than the separation".
    """

    def __init__(self, paths: tuple[OrderPath, OrderPath], separation: float) -> None:
        self.paths = paths
        # conflict: closer than the separation (verifier's tolerance); at 0, touching
        self.threshold = max(separation - POSITION_TOLERANCE, POSITION_TOLERANCE)
        self.stretches = [[(e.leg, e.low, e.high) for e in path.edges] for path in paths]
        self.points = [[(n.leg, n.s, n.s) for n in path.nodes] for path in paths]
        self.after = self.node_plan()
        self.reached = [0, 0]
        self.released = [0, 0]
        self.delay = [0.0, 0.0]

    def apart(self, first: tuple[int, float, float], second: tuple[int, float, float]) -> bool:
        return _gap(first, second) >= self.threshold

    def node_plan(self) -> tuple[list[int], list[int]]:
        """Per vehicle and edge, the node the other vehicle must have reached before the edge is released.

        Raises
        ------
        ScheduleError
            No sequence of moves between the nodes keeps the separation.
        """
        last = (len(self.points[0]) - 1, len(self.points[1]) - 1)

        def move(vehicle: int, k: int, other_node: int) -> bool:
            """Whether ``vehicle`` may drive its edge ``k`` while the other stands at ``other_node``."""
            return k < last[vehicle] and self.apart(
                self.stretches[vehicle][k], self.points[1 - vehicle][other_node]
            )

        # which states (node of vehicle 1, node of vehicle 2) still lead to both goals
        reach = [[False] * (last[1] + 1) for _ in range(last[0] + 1)]
        for k in range(last[0], -1, -1):
            for j in range(last[1], -1, -1):
                reach[k][j] = self.apart(self.points[0][k], self.points[1][j]) and (
                    (k, j) == last
                    or (move(0, k, j) and reach[k + 1][j])
                    or (move(1, j, k) and reach[k][j + 1])
                )
        if not reach[0][0]:
            raise ScheduleError(
                "VDA 5050 orders: no order of the two paths' edges keeps the minimum separation "
                "node by node (the schedule relies on the vehicles' timing between nodes)"
            )
        at: tuple[list[int], list[int]] = ([0] * last[0], [0] * last[1])  # the other's node during a move
        k = j = 0
        arrival = [[n.arrival for n in path.nodes] for path in self.paths]
        while (k, j) != last:
            first = move(0, k, j) and reach[k + 1][j]
            second = move(1, j, k) and reach[k][j + 1]
            if first and second:  # both may go: the one the schedule has arrive first
                first = arrival[0][k + 1] <= arrival[1][j + 1]
            if first:
                at[0][k] = j
                k += 1
            else:
                at[1][j] = k
                j += 1
        # only the other's conflicting edges that the plan drives first must be behind it
        return tuple(
            [
                max(
                    (
                        f + 1
                        for f in range(at[vehicle][edge])
                        if not self.apart(stretch, self.stretches[1 - vehicle][f])
                    ),
                    default=0,
                )
                for edge, stretch in enumerate(self.stretches[vehicle])
            ]
            for vehicle in (0, 1)
        )

    def claim(self, vehicle: int) -> list[tuple[int, float, float]]:
        first, last = self.reached[vehicle], self.released[vehicle]
        return [self.points[vehicle][first], *self.stretches[vehicle][first:last]]

    def allowed(self, vehicle: int, edge: int) -> bool:
        other = 1 - vehicle
        if self.reached[other] < self.after[vehicle][edge]:
            return False
        stretch = self.stretches[vehicle][edge]
        return all(self.apart(stretch, held) for held in self.claim(other))

    def extend(self, vehicle: int) -> int:
        edge = self.released[vehicle]
        while edge < len(self.stretches[vehicle]) and self.allowed(vehicle, edge):
            edge += 1
        return edge

    def time_of(self, vehicle: int, node: int) -> float:
        return self.paths[vehicle].nodes[node].arrival + self.delay[vehicle]

    def run(self) -> tuple[list[Release], float]:
        releases: list[Release] = []
        for vehicle in (0, 1):
            self.released[vehicle] = self.extend(vehicle)
            releases.append(Release(vehicle, 0, 0, self.released[vehicle], 0.0, None, 0.0, None))
        counts = [1, 1]
        last = [len(path.nodes) - 1 for path in self.paths]
        while self.reached != last:
            movable = [v for v in (0, 1) if self.reached[v] < self.released[v]]
            if not movable:
                raise ScheduleError(
                    "VDA 5050 orders: the releases deadlock at nodes "
                    f"{self.reached[0]} and {self.reached[1]}: the schedule's order of the track "
                    "cannot be released node by node"
                )
            mover = min(movable, key=lambda v: (self.time_of(v, self.reached[v] + 1), v))
            now = self.time_of(mover, self.reached[mover] + 1)
            self.reached[mover] += 1
            for vehicle in (1 - mover, mover):
                end = self.extend(vehicle)
                if end == self.released[vehicle]:
                    continue
                old = self.released[vehicle]
                needed = self.paths[vehicle].nodes[old].departure + self.delay[vehicle]
                wait = max(0.0, now - needed) if self.reached[vehicle] == old else 0.0
                self.delay[vehicle] += wait
                releases.append(
                    Release(
                        vehicle, counts[vehicle], old, end, now, needed, wait, (mover, self.reached[mover])
                    )
                )
                counts[vehicle] += 1
                self.released[vehicle] = end
        finish = max(self.time_of(v, last[v]) for v in (0, 1))
        return releases, finish


def plan_orders(verified: VerifiedSchedule) -> OrderPlan:
    """Both vehicles' VDA 5050 paths and the releases of their bases (see the module's description).

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verify.certify`.

    Returns
    -------
    OrderPlan

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    ScheduleError
        No order of the two paths' edges keeps the separation node by node (not seen on any
        schedule: 220 random scenarios of the three methods, and the tests' cases).
    """
    schedule = require_verified(verified, "plan_orders").schedule
    pieces = schedule_pieces(schedule)
    paths = (_order_path(schedule, pieces, 0), _order_path(schedule, pieces, 1))
    releases, finish = _Replay(paths, schedule.limits.min_separation).run()
    return OrderPlan(paths, tuple(releases), max(finish, schedule.duration))


# ---------------------------------------------------------------------------------------------------------
# Rendering


def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


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
    return f"{graph.names[leg]}:{_number(s)}"


def edge_id(start: str, end: str) -> str:
    """The id of the edge from node ``start`` to node ``end``: ``"<start>-><end>"``."""
    return f"{start}->{end}"


def _timestamp(start: datetime, seconds: float) -> str:
    """ISO 8601 UTC with milliseconds, rounded up (a message is never stamped before it is safe)."""
    moment = start + timedelta(milliseconds=math.ceil(round(seconds * 1000.0, 6)))
    return moment.strftime("%Y-%m-%dT%H:%M:%S.") + f"{moment.microsecond // 1000:03d}Z"


def _coordinate(value: float) -> float:
    return round(value, 9) + 0.0  # nanometres, no "-0.0"


def _node_description(node: PathNode) -> str:
    parts = []
    for kind in node.kinds:
        if kind is NodeKind.HOLD:
            parts.append(f"hold: {_number(node.s)} m from the junction (the minimum separation)")
        else:
            parts.append(kind.value)
    return ", ".join(parts)


def _node_json(graph: StarGraph, node: PathNode, sequence: int, released: bool, map_id: str) -> dict:
    angle = math.radians(graph.angles_deg[node.leg]) if node.leg != JUNCTION_INDEX else 0.0
    return {
        "nodeId": node_id(graph, node.leg, node.s),
        "sequenceId": sequence,
        "nodeDescription": _node_description(node),
        "released": released,
        "nodePosition": {
            "x": _coordinate(node.s * math.cos(angle)),
            "y": _coordinate(node.s * math.sin(angle)),
            "mapId": map_id,
        },
        "actions": [],
    }


def _edge_json(graph: StarGraph, path: OrderPath, edge: PathEdge, released: bool) -> dict:
    start, end = path.nodes[edge.index], path.nodes[edge.index + 1]
    first, second = node_id(graph, start.leg, start.s), node_id(graph, end.leg, end.s)
    data = {
        "edgeId": edge_id(first, second),
        "sequenceId": 2 * edge.index + 1,
        "released": released,
        "startNodeId": first,
        "endNodeId": second,
        "maxSpeed": edge.max_speed,
        "length": _coordinate(edge.length),
        "orientation": math.pi if edge.backward else 0.0,
        "orientationType": "TANGENTIAL",
        "actions": [],
    }
    if start.leg == JUNCTION_INDEX and end.leg != JUNCTION_INDEX:
        data["direction"] = graph.names[end.leg]  # the leg taken at the junction
    return data


@dataclass(frozen=True, slots=True)
class OrderMessage:
    """One rendered message and when to send it.

    Attributes
    ----------
    vehicle : int
        0 or 1.
    release : Release
    header_id : int
    timestamp : str
        ISO 8601, UTC.
    path : PurePosixPath
        Where it is written, relative to the output folder: ``<vehicle name>/order-<update>.json``.
    data : bytes
        The JSON message, UTF-8.
    """

    vehicle: int
    release: Release
    header_id: int
    timestamp: str
    path: PurePosixPath
    data: bytes


def _dumps(document: dict) -> bytes:
    return (json.dumps(document, indent=2, ensure_ascii=False, allow_nan=False) + "\n").encode("utf-8")


def _checked(verified: object, names: Sequence[str], options: object, what: str):
    schedule = require_verified(verified, what).schedule
    names = check_vehicle_names(names)
    if not isinstance(options, Vda5050Options):
        raise OptionError(f"VDA 5050 options must be Vda5050Options, got {type(options).__name__}")
    return schedule, names


def render_orders(
    verified: VerifiedSchedule,
    names: Sequence[str],
    *,
    options: Vda5050Options,
    plan: OrderPlan | None = None,
) -> tuple[OrderMessage, ...]:
    """Every VDA 5050 order message of both vehicles, in the order they are sent.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of 2 str
        Vehicle names (folder names, default serial numbers).
    options : Vda5050Options
    plan : OrderPlan, optional
        ``plan_orders(verified)``, if already computed.

    Returns
    -------
    tuple of OrderMessage

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names or options.
    """
    schedule, names = _checked(verified, names, options, "render_orders")
    plan = plan_orders(verified) if plan is None else plan
    graph = schedule.route.graph
    messages = []
    for release in plan.releases:
        vehicle = release.vehicle
        path = plan.paths[vehicle]
        nodes = [
            _node_json(graph, node, 2 * j, j <= release.decision_point, options.map_id)
            for j, node in enumerate(path.nodes)
            if j >= release.first
        ]
        edges = [
            _edge_json(graph, path, edge, edge.index < release.decision_point)
            for edge in path.edges
            if edge.index >= release.first
        ]
        header_id = options.first_header_id + release.update
        timestamp = _timestamp(options.start_time, release.send_at)
        document = {
            "headerId": header_id,
            "timestamp": timestamp,
            "version": VDA5050_VERSION,
            "manufacturer": options.manufacturers[vehicle],
            "serialNumber": options.serial_number(vehicle, names),
            "orderId": f"{options.order_id}-{names[vehicle]}",
            "orderUpdateId": release.update,
            "nodes": nodes,
            "edges": edges,
        }
        messages.append(
            OrderMessage(
                vehicle,
                release,
                header_id,
                timestamp,
                PurePosixPath(names[vehicle], f"order-{release.update:03d}.json"),
                _dumps(document),
            )
        )
    return tuple(messages)


def _manifest(schedule: Schedule, plan: OrderPlan, messages, names, options: Vda5050Options) -> dict:
    graph = schedule.route.graph

    def node_ref(vehicle: int, index: int) -> dict:
        node = plan.paths[vehicle].nodes[index]
        return {"node_id": node_id(graph, node.leg, node.s), "sequence_id": 2 * index}

    entries = []
    for message in messages:
        release = message.release
        trigger = None
        if release.trigger is not None:
            other, index = release.trigger
            trigger = {"vehicle": names[other], **node_ref(other, index)}
        entries.append(
            {
                "file": str(message.path),
                "vehicle": names[message.vehicle],
                "order_update_id": release.update,
                "header_id": message.header_id,
                "send_at_s": round(release.send_at, 6),
                "timestamp": message.timestamp,
                "trigger": trigger,
                "first_node": node_ref(message.vehicle, release.first),
                "decision_point": node_ref(message.vehicle, release.decision_point),
                "needed_at_s": None if release.needed_at is None else round(release.needed_at, 6),
                "wait_s": round(release.wait, 6),
            }
        )
    vehicles = {}
    for vehicle, name in enumerate(names):
        path = plan.paths[vehicle]
        vehicles[name] = {
            "manufacturer": options.manufacturers[vehicle],
            "serial_number": options.serial_number(vehicle, names),
            "order_id": f"{options.order_id}-{name}",
            "nodes": [node_id(graph, n.leg, n.s) for n in path.nodes],
            "messages": sum(1 for m in messages if m.vehicle == vehicle),
        }
    return {
        "format": "trajgen VDA 5050 orders",
        "version": VDA5050_VERSION,
        "start_time": _timestamp(options.start_time, 0.0),
        "map_id": options.map_id,
        "method": schedule.method.name,
        "min_separation_m": schedule.limits.min_separation,
        "schedule_duration_s": round(schedule.duration, 6),
        "planned_duration_s": round(plan.planned_duration, 6),
        "vehicles": vehicles,
        "messages": entries,
    }


def render_manifest(
    verified: VerifiedSchedule,
    names: Sequence[str],
    messages: Sequence[OrderMessage],
    *,
    options: Vda5050Options,
    plan: OrderPlan | None = None,
) -> bytes:
    """The index of a run's messages (``manifest.json``): each file, when and on which event to send it.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of 2 str
    messages : sequence of OrderMessage
        From :func:`render_orders` with the same arguments.
    options : Vda5050Options
    plan : OrderPlan, optional
        ``plan_orders(verified)``, if already computed.

    Returns
    -------
    bytes
        JSON, UTF-8.
    """
    schedule, names = _checked(verified, names, options, "render_manifest")
    plan = plan_orders(verified) if plan is None else plan
    return _dumps(_manifest(schedule, plan, messages, names, options))


def order_paths(names: Sequence[str], directory: str | Path) -> tuple[Path, Path, Path]:
    """The files every run writes: ``directory/manifest.json`` and each vehicle's first order.

    Raises
    ------
    InputError
        Bad names (also a vehicle named like the manifest), or ``directory`` names no folder.
    """
    first, second = check_vehicle_names(names)
    for name in (first, second):
        if name.lower() == MANIFEST_NAME.lower():
            raise OptionError(
                f"vehicle name {name!r} is the manifest's file name: expected another name (its orders "
                f"go into a folder of that name beside {MANIFEST_NAME})"
            )
    if not isinstance(directory, (str, Path)) or str(directory) == "":
        raise OptionError(f"VDA 5050 output folder must name a folder, got {short_repr(directory)}")
    directory = Path(directory)
    return (
        directory / MANIFEST_NAME,
        directory / first / "order-000.json",
        directory / second / "order-000.json",
    )


def order_files(
    verified: VerifiedSchedule, names: Sequence[str], directory: str | Path, *, options: Vda5050Options
) -> dict[Path, bytes]:
    """Every file of a run, rendered: ``directory/<vehicle name>/order-NNN.json`` and ``manifest.json``."""
    order_paths(names, directory)
    plan = plan_orders(require_verified(verified, "order_files"))
    messages = render_orders(verified, names, options=options, plan=plan)
    directory = Path(directory)
    files = {directory / message.path: message.data for message in messages}
    files[directory / MANIFEST_NAME] = render_manifest(verified, names, messages, options=options, plan=plan)
    return files


def write_orders(
    verified: VerifiedSchedule, names: Sequence[str], directory: str | Path, *, options: Vda5050Options
) -> tuple[Path, ...]:
    """Write every VDA 5050 message of a run and its manifest, all or none.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verify.certify`.
    names : sequence of 2 str
        Vehicle names (their folders).
    directory : path
        Created if missing.
    options : Vda5050Options

    Returns
    -------
    tuple of Path
        The files written.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names, options or output paths; nothing was written.
    """
    check_output_paths(order_paths(names, directory))
    files = order_files(verified, names, directory, options=options)
    check_output_paths(files)
    return commit_files(files)
