"""Routes of three and four vehicles, made by hand: the stages below the planners take any number.

The planners plan two vehicles until the issue that plans any number; every stage below them (the
route's verifier, the timing methods, the schedule's verifier, the CSV and PLC tables and their
read-back, the VDA 5050 orders, the pictures) takes a sequence of vehicles. These cases are routes a
planner could have made, one vehicle moving at a time, written out move by move, each built once per
process and shared after (all immutable):

- ``convoy-of-3``: three vehicles on one 40 m line, the front one first, each moving up to the separation
  behind it;
- ``rotation-of-4``: four vehicles on a five-leg star, each in turn through the junction to the leg the
  one before it left, passing the others standing the separation from the junction;
- ``ring-of-3``: three vehicles on a ring of four 10 m edges, each in turn round a corner, the first to
  the separation from the last.

In each, vehicles come exactly the separation apart.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

from limits import Limits, VehicleLimits
from topology import GraphMove, GraphRoute, TrackGraph
from trajgen import certify
from trajgen.methods import make_schedule

__all__ = ["FLEETS", "Fleet", "fleet", "one_at_a_time"]


def one_at_a_time(
    track: TrackGraph,
    starts: tuple[str, ...],
    moves: tuple[tuple[int, tuple[str, ...]], ...],
    *,
    separation: float,
    names: tuple[str, ...],
) -> GraphRoute:
    """A route of ``len(starts)`` vehicles from its moves: ``(vehicle, (point, node, ..., point))``.

    Each step of a move runs along the one edge both its points are on.
    """
    where = [track.point(start) for start in starts]
    travel = [0.0] * len(starts)
    built = []
    for vehicle, names_of_points in moves:
        points = tuple(track.point(name) for name in names_of_points)
        edges, length = [], 0.0
        for a, b in itertools.pairwise(points):
            edge = next(
                k
                for k in range(track.edge_count)
                if track.position_on(a, k) is not None and track.position_on(b, k) is not None
            )
            edges.append(edge)
            length += abs(track.position_on(b, edge) - track.position_on(a, edge))
        built.append(GraphMove(vehicle, points, tuple(edges), length, tuple(where)))
        where[vehicle] = points[-1]
        travel[vehicle] += length
    return GraphRoute(
        track,
        separation,
        tuple(track.point(start) for start in starts),
        tuple(where),
        tuple(built),
        tuple(travel),
        0,
        0,
        names,
    )


@dataclass(frozen=True, slots=True)
class Fleet:
    """One case: its id; :meth:`route`, :meth:`limits`, :meth:`verified` are built once per process."""

    name: str

    @property
    def count(self) -> int:
        return self.route().count

    def route(self) -> GraphRoute:
        return _route(self.name)

    def limits(self) -> Limits:
        return _limits(self.name)

    def verified(self, method: str = "exact"):
        """The route's verified schedule by ``method``."""
        return _verified(self.name, method)


SEPARATION = 2.0


@functools.cache
def _route(name: str) -> GraphRoute:
    if name == "convoy-of-3":
        track = TrackGraph.from_edges(
            {"main": ("W", "E", 40.0)}, coordinates={"W": (0.0, 0.0), "E": (40.0, 0.0)}
        )
        return one_at_a_time(
            track,
            ("main:2", "main:10", "main:20"),
            ((2, ("main:20", "main:30")), (1, ("main:10", "main:28")), (0, ("main:2", "main:26"))),
            separation=SEPARATION,
            names=("agv1", "agv2", "agv3"),
        )
    if name == "rotation-of-4":
        legs = {"n": (0.0, 1.0), "e": (1.0, 0.0), "s": (0.0, -1.0), "w": (-1.0, 0.0), "x": (0.7, 0.7)}
        track = TrackGraph.from_edges(
            {leg: ("J", leg.upper(), 10.0) for leg in legs},
            coordinates={
                "J": (0.0, 0.0),
                **{leg.upper(): (10 * dx, 10 * dy) for leg, (dx, dy) in legs.items()},
            },
        )
        return one_at_a_time(
            track,
            ("n:6", "e:2", "s:2", "w:2"),
            (
                (0, ("n:6", "J", "x:6")),
                (1, ("e:2", "J", "n:2")),
                (2, ("s:2", "J", "e:2")),
                (3, ("w:2", "J", "s:2")),
            ),
            separation=SEPARATION,
            names=("agv1", "agv2", "agv3", "agv4"),
        )
    if name == "ring-of-3":
        corners = {"A": (0.0, 0.0), "B": (10.0, 0.0), "C": (10.0, 10.0), "D": (0.0, 10.0)}
        track = TrackGraph.from_edges(
            {"ab": ("A", "B", None), "bc": ("B", "C", None), "cd": ("C", "D", None), "da": ("D", "A", None)},
            coordinates=corners,
        )
        return one_at_a_time(
            track,
            ("ab:2", "bc:2", "cd:2"),
            ((2, ("cd:2", "D", "A")), (1, ("bc:2", "C", "cd:8")), (0, ("ab:2", "B", "bc:8"))),
            separation=SEPARATION,
            names=("agv1", "agv2", "agv3"),
        )
    raise KeyError(name)


@functools.cache
def _limits(name: str) -> Limits:
    count = _route(name).count
    # unequal vehicles: each limit is read for its own vehicle
    vehicles = tuple(VehicleLimits(1.0 + 0.2 * k, 0.5 + 0.1 * k, 1.0) for k in range(count))
    return Limits(vehicles, SEPARATION)


@functools.cache
def _verified(name: str, method: str):
    return certify(make_schedule(_route(name), _limits(name), method=method))


#: The table: a line, a star and a ring, with three or four vehicles.
FLEETS = (Fleet("convoy-of-3"), Fleet("rotation-of-4"), Fleet("ring-of-3"))


def fleet(name: str) -> Fleet:
    """The case of the table named ``name``."""
    return next(f for f in FLEETS if f.name == name)
