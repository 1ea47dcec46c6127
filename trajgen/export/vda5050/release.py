"""The order updates of the vehicles: which base each VDA 5050 order or order update releases, and when.

A VDA 5050 order carries no timing: a vehicle drives its *base* (released
nodes and edges) at its own pace, at most ``maxSpeed`` on each edge, and
stops at the last base node (the *decision point*) until an order update
extends the base, stitched at the previous decision point. So the release of
the base, not the schedule's timing, is what keeps the two vehicles apart here:

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
  at its decision point until released (:func:`order_releases`).

Each update is triggered by the other vehicle reaching a node (its state's
``lastNodeId`` and ``lastNodeSequenceId``); ``send_at`` is the time of that
event in the replay (the schedule's time plus the waits before it). A vehicle
released after it reaches its decision point waits there (``wait``): VDA 5050
cannot express a schedule in which both vehicles are near the junction at
once, so a schedule that does so (``optimal``) is executed a few seconds
slower (:attr:`OrderReleases.planned_duration`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from topology.validation import short_repr
from trajgen.errors import InputError, ScheduleError
from trajgen.export.vda5050.graph_path import GraphOrderPath, graph_vehicle_path
from trajgen.export.vda5050.path import OrderPath, vehicle_path
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.pieces import schedule_pieces
from trajgen.verification import POSITION_TOLERANCE, VerifiedSchedule, require_verified

__all__ = ["NODE_PLAN_STATES", "BaseRelease", "OrderReleases", "Release", "order_releases"]

#: Joint states of the vehicles' nodes the node plan may find to lead nowhere before it gives up (its
#: search budget, in states, never in time).
NODE_PLAN_STATES = 1_000_000


@dataclass(frozen=True, slots=True)
class Release:
    """One message of one vehicle: the order (``update == 0``) or an order update.

    Attributes
    ----------
    vehicle : int
        Its index among the vehicles.
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
class OrderReleases:
    """Both vehicles' paths and every release, in the order they are sent.

    Attributes
    ----------
    paths : tuple of OrderPath (a junction) or of GraphOrderPath (a track graph), one per vehicle
    releases : tuple of Release
        By ``send_at`` (and in the replay's order at equal times).
    planned_duration : float
        When every vehicle reaches its goal in the replay (the schedule's duration plus the waits), s.
    """

    paths: tuple[OrderPath, ...] | tuple[GraphOrderPath, ...]
    releases: tuple[Release, ...]
    planned_duration: float


class BaseRelease:
    """The release rule of the vehicles' bases: how far each may be released, from the nodes reached.

    The order of the track is a *node plan*: a sequence of moves, each taking one vehicle to its next
    node while the others stand at nodes, every move keeping the separation, that follows the
    schedule's order of arrivals wherever the nodes allow it. A vehicle's edge is released once every
    other vehicle has reached the node the plan has it at during that move, and its track keeps the
    separation from every other vehicle's claim (the stretch from the last node it reached to its
    decision point); so the vehicles follow the plan (with more motion at once where the claims allow
    it) and cannot deadlock. "Reached the node" is relaxed to "left every edge the plan drives
    before, and that comes closer than the separation".

    Only the nodes reached move the releases on, never the time: whatever the timing of any
    vehicle within its base, the claims stay apart. This is what the live master runs
    (:mod:`trajgen.live`), on the nodes the vehicles report.

    Parameters
    ----------
    paths : tuple of OrderPath or GraphOrderPath, one per vehicle
        Both vehicles' paths, on a junction or on a track graph: each node and edge has a
        ``claim``, and the path's ``gap`` is the track distance between two claims.
    separation : float
        The minimum separation, metres.

    Raises
    ------
    ScheduleError
        No sequence of moves between the nodes keeps the separation.
    """

    def __init__(self, paths: tuple[OrderPath, ...] | tuple[GraphOrderPath, ...], separation: float) -> None:
        self.paths = paths
        # conflict: closer than the separation (verifier's tolerance); at 0, touching
        self.threshold = max(separation - POSITION_TOLERANCE, POSITION_TOLERANCE)
        self.stretches = [[edge.claim for edge in path.edges] for path in paths]
        self.points = [[node.claim for node in path.nodes] for path in paths]
        self.gap = paths[0].gap
        self.after = self._node_plan()
        #: per vehicle, the last node it reached and the index of its decision point
        self.reached = [0] * len(paths)
        self.released = [0] * len(paths)
        for vehicle in range(len(paths)):
            self.released[vehicle] = self._extend(vehicle)

    @property
    def last(self) -> tuple[int, ...]:
        """Each vehicle's goal node index."""
        return tuple(len(points) - 1 for points in self.points)

    def apart(self, first, second) -> bool:
        """Whether two claims (a node's or an edge's ``claim``) keep the separation."""
        return self.gap(first, second) >= self.threshold

    def _moves(self, state: tuple[int, ...], arrival) -> list[int]:
        """The vehicles that may drive their next edge from ``state``, the schedule's next arrival first.

        A vehicle may move while every other stands at its node of ``state`` and keeps the
        separation from the edge.
        """
        last = self.last
        movers = [
            v
            for v in range(len(state))
            if state[v] < last[v]
            and all(
                self.apart(self.stretches[v][state[v]], self.points[o][state[o]])
                for o in range(len(state))
                if o != v
            )
        ]
        return sorted(movers, key=lambda v: (arrival[v][state[v] + 1], v))

    def _apart_at(self, state: tuple[int, ...], moved: int | None = None) -> bool:
        """Whether every two vehicles standing at their nodes of ``state`` keep the separation.

        ``moved``: the one vehicle that moved into ``state`` from a state that kept it; only its pairs
        can have changed.
        """
        if moved is not None:
            here = self.points[moved][state[moved]]
            return all(self.apart(here, self.points[o][state[o]]) for o in range(len(state)) if o != moved)
        return all(
            self.apart(self.points[i][state[i]], self.points[j][state[j]])
            for i, j in itertools.combinations(range(len(state)), 2)
        )

    def _node_plan(self) -> tuple[list[tuple[int, ...]], ...]:
        """Per vehicle and edge, the node each other vehicle must have reached before the edge is released.

        The node plan is the first sequence of moves, in the order of preference of :meth:`_moves`
        (the schedule's order of arrivals), that leads every vehicle to its goal: a depth-first
        search over the vehicles' nodes that remembers the states found to lead nowhere, at most
        :data:`NODE_PLAN_STATES` of them.
        """
        last = self.last
        count = len(last)
        arrival = [[n.arrival for n in path.nodes] for path in self.paths]
        start = (0,) * count
        dead: set[tuple[int, ...]] = set()
        plan: list[tuple[int, tuple[int, ...]]] = []  # (mover, state before the move)
        stack = [(start, iter(self._moves(start, arrival)))] if self._apart_at(start) else []
        while stack and stack[-1][0] != last:
            state, options = stack[-1]
            following = None
            for mover in options:
                after = (*state[:mover], state[mover] + 1, *state[mover + 1 :])
                if after not in dead and self._apart_at(after, mover):
                    following = (mover, after)
                    break
            if following is None:
                dead.add(state)
                stack.pop()
                if plan:
                    plan.pop()
                if len(dead) > NODE_PLAN_STATES:
                    raise ScheduleError(
                        f"VDA 5050 orders: the node plan searched {NODE_PLAN_STATES:,} states of the "
                        "vehicles' nodes (NODE_PLAN_STATES) without finding an order of their edges"
                    )
                continue
            mover, after = following
            plan.append((mover, state))
            stack.append((after, iter(self._moves(after, arrival))))
        if not stack:
            raise ScheduleError(
                "VDA 5050 orders: no order of the paths' edges keeps the minimum separation "
                "node by node (the schedule relies on the vehicles' timing between nodes)"
            )
        at: list[list[tuple[int, ...]]] = [[start] * last[v] for v in range(count)]  # the others' nodes
        for mover, state in plan:
            at[mover][state[mover]] = state
        # only the others' conflicting edges that the plan drives first must be behind it
        return tuple(
            [
                tuple(
                    0
                    if other == vehicle
                    else max(
                        (
                            f + 1
                            for f in range(at[vehicle][edge][other])
                            if not self.apart(stretch, self.stretches[other][f])
                        ),
                        default=0,
                    )
                    for other in range(count)
                )
                for edge, stretch in enumerate(self.stretches[vehicle])
            ]
            for vehicle in range(count)
        )

    def claim(self, vehicle: int) -> list[tuple[int, float, float]]:
        """The track ``vehicle`` may be on: its last node reached and its base edges beyond it."""
        first, last = self.reached[vehicle], self.released[vehicle]
        return [self.points[vehicle][first], *self.stretches[vehicle][first:last]]

    def _allowed(self, vehicle: int, edge: int) -> bool:
        needed = self.after[vehicle][edge]
        others = [other for other in range(len(self.paths)) if other != vehicle]
        if any(self.reached[other] < needed[other] for other in others):
            return False
        stretch = self.stretches[vehicle][edge]
        return all(self.apart(stretch, held) for other in others for held in self.claim(other))

    def _extend(self, vehicle: int) -> int:
        edge = self.released[vehicle]
        while edge < len(self.stretches[vehicle]) and self._allowed(vehicle, edge):
            edge += 1
        return edge

    def reach(self, vehicle: int, node: int) -> list[tuple[int, int, int]]:
        """Record that ``vehicle`` reached ``node``; the releases that follow, the other vehicles' first.

        Parameters
        ----------
        vehicle : int
            Its index among the vehicles.
        node : int
            Index of the node on its path, at most its decision point (a vehicle does not drive
            past its base). A node at or before the last one reached changes nothing.

        Returns
        -------
        list of (vehicle, previous decision point, new decision point)
            The others' first, in vehicle order, then its own.

        Raises
        ------
        ValueError
            ``node`` is past the vehicle's decision point.
        """
        if node > self.released[vehicle]:
            raise ValueError(
                f"vehicle {vehicle} node {node} is past its decision point {self.released[vehicle]}; "
                "expected a node of its base"
            )
        if node <= self.reached[vehicle]:
            return []
        self.reached[vehicle] = node
        releases = []
        for each in (*(other for other in range(len(self.paths)) if other != vehicle), vehicle):
            end = self._extend(each)
            if end != self.released[each]:
                releases.append((each, self.released[each], end))
                self.released[each] = end
        return releases


class _Replay:
    """Both paths replayed node by node in the schedule's order; a vehicle waits at its decision point."""

    def __init__(self, paths: tuple[OrderPath, ...] | tuple[GraphOrderPath, ...], separation: float) -> None:
        self.paths = paths
        self.rule = BaseRelease(paths, separation)
        self.delay = [0.0] * len(paths)

    def time_of(self, vehicle: int, node: int) -> float:
        return self.paths[vehicle].nodes[node].arrival + self.delay[vehicle]

    def run(self) -> tuple[list[Release], float]:
        rule = self.rule
        count = len(self.paths)
        releases = [Release(v, 0, 0, rule.released[v], 0.0, None, 0.0, None) for v in range(count)]
        counts = [1] * count
        last = list(rule.last)
        while rule.reached != last:
            movable = [v for v in range(count) if rule.reached[v] < rule.released[v]]
            if not movable:
                raise ScheduleError(
                    "VDA 5050 orders: the releases deadlock at nodes "
                    f"{', '.join(str(node) for node in rule.reached)}: the schedule's order of the track "
                    "cannot be released node by node"
                )
            mover = min(movable, key=lambda v: (self.time_of(v, rule.reached[v] + 1), v))
            now = self.time_of(mover, rule.reached[mover] + 1)
            for vehicle, old, end in rule.reach(mover, rule.reached[mover] + 1):
                needed = self.paths[vehicle].nodes[old].departure + self.delay[vehicle]
                wait = max(0.0, now - needed) if rule.reached[vehicle] == old else 0.0
                self.delay[vehicle] += wait
                releases.append(
                    Release(
                        vehicle, counts[vehicle], old, end, now, needed, wait, (mover, rule.reached[mover])
                    )
                )
                counts[vehicle] += 1
        finish = max(self.time_of(v, last[v]) for v in range(count))
        return releases, finish


def order_releases(verified: VerifiedSchedule, *, spacing: float | None = None) -> OrderReleases:
    """Both vehicles' VDA 5050 paths and the releases of their bases (see the module's description).

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verification.certify`.
    spacing : float, optional
        Longest edge, metres (``None``: the paths' own nodes only): release nodes between let
        the base follow the other vehicle more closely.

    Returns
    -------
    OrderReleases

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    ScheduleError
        No order of the two paths' edges keeps the separation node by node (not seen on any
        schedule: 220 random scenarios of the three methods, and the tests' cases).
    """
    schedule = require_verified(verified, "order_releases").schedule
    usable = isinstance(spacing, int | float) and not isinstance(spacing, bool) and math.isfinite(spacing)
    if spacing is not None and not (usable and spacing > 0):
        raise InputError(f"release spacing {short_repr(spacing)} m is not allowed: expected a number > 0")
    count = schedule.limits.count
    if isinstance(schedule, GraphSchedule):
        paths = tuple(graph_vehicle_path(schedule, v, spacing=spacing) for v in range(count))
    else:
        pieces = schedule_pieces(schedule)
        paths = tuple(vehicle_path(schedule, pieces, v, spacing=spacing) for v in range(count))
    releases, finish = _Replay(paths, schedule.limits.min_separation).run()
    return OrderReleases(paths, tuple(releases), max(finish, schedule.duration))
