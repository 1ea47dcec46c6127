"""The motion planner and its result, the :class:`Route`.

docs/planner.md, 'The two instructions' and 'Homotopy classes' (three legs): retract the start onto the
boundary circle, go round the circle (shortest way, or counterclockwise half a
turn when the goal is the start with the vehicles swapped), then undo the
goal's retraction. docs/star.md (four to eight legs): the same
retractions, and between them a route on the retract graph ``G_k`` chosen by
three rules (:mod:`topology.retract_graph`).
"""

from __future__ import annotations

import bisect
import itertools
import sys
from dataclasses import dataclass, field

from topology.cycle import ANTIPODAL_TOLERANCE, as_indexed, retract_indexed
from topology.errors import OptionError, PositionError, SeparationError
from topology.graph import StarGraph
from topology.indexed import (
    JUNCTION_INDEX,
    IndexedConfiguration,
    RegionKey,
    leg_travel,
    reduce_regions,
    reduce_regions_indexed,
    region_key,
    segment_region_key,
    separation,
    step,
)
from topology.options import Option, rename_values
from topology.positions import Configuration
from topology.retract_graph import Geodesic, GraphPoint, RetractGraph
from topology.validation import finite_real

__all__ = ["Homotopy", "Instruction", "Region", "Route", "WayRound", "plan", "region_sequence"]


class Instruction(Option):
    """The continuous instructions of the planner.

    Three legs (topological complexity 2): ``SHORTEST`` and ``COUNTERCLOCKWISE``.
    Four to eight legs (topological complexity 3): ``SHORTEST``, ``TWO_TIED``
    and ``MANY_TIED`` (docs/star.md, 'The three rules').
    """

    #: the unique shortest route (three legs: paper Instruction 2, the shorter way round)
    SHORTEST = "shortest"
    #: three legs, paper Instruction 1: half a turn counterclockwise, for swaps
    COUNTERCLOCKWISE = "counterclockwise"
    #: four or more legs, rule 2: two shortest routes tie; the larger integral of ``w`` wins
    TWO_TIED = "two-tied"
    #: four or more legs, rule 3: three or more tie; a fixed deterministic choice
    MANY_TIED = "many-tied"

    @classmethod
    def of_track(cls, graph: StarGraph) -> tuple[Instruction, ...]:
        """The instructions of the planner on ``graph``: two for three legs, three for more."""
        if graph.leg_count == 3:
            return (cls.SHORTEST, cls.COUNTERCLOCKWISE)
        return (cls.SHORTEST, cls.TWO_TIED, cls.MANY_TIED)


#: The instruction of each rule of the geodesic planner on G_k (k >= 4), by the number of tied routes.
_RULE_INSTRUCTION = {1: Instruction.SHORTEST, 2: Instruction.TWO_TIED, 3: Instruction.MANY_TIED}


class Homotopy(Option):
    """Which of the two shortest homotopy classes :func:`plan` takes."""

    PLANNED = "planned"  #: the class of the planner's instruction (docs/planner.md, 'The two instructions')
    #: three legs: the other way round the boundary circle; four or more: the shortest
    #: route on ``G_k`` in another class (the second-shortest simple route)
    OTHER = "other"
    PAPER = "planned"  #: deprecated name of :attr:`PLANNED` (0.7)


class WayRound(Option):
    """The direction a route goes round the boundary circle (its homotopy class)."""

    COUNTERCLOCKWISE = "counterclockwise"
    CLOCKWISE = "clockwise"
    NONE = "none"  #: start and goal retract to the same boundary point
    #: four or more legs: the configuration space deforms onto a graph (``G_k``), not a circle, so a
    #: route goes round nothing; :func:`trajgen.model.summary.class_name` names its class
    NOT_APPLICABLE = "not-applicable"
    GRAPH = "not-applicable"  #: deprecated name of :attr:`NOT_APPLICABLE` (0.7)


rename_values(Homotopy, {"paper": "planned"}, "0.7")
rename_values(WayRound, {"graph": "not-applicable"}, "0.7")


@dataclass(frozen=True, slots=True)
class Region:
    """A contractible region of the configuration space (docs/planner.md, 'Homotopy classes').

    ``Q(i, j)``: vehicle 1 on leg ``i``, vehicle 2 on another leg ``j``.
    ``T(k, r)``: both vehicles on leg ``k``, vehicle ``r`` (1 or 2) nearer the
    junction. Either vehicle may also be at the junction, where regions meet.

    Parameters
    ----------
    first_leg, second_leg : str
        Legs of vehicle 1 and vehicle 2.
    nearer : int or None
        For a shared leg, the vehicle (1 or 2) nearer the junction; ``None``
        for different legs.
    """

    first_leg: str
    second_leg: str
    nearer: int | None = None

    def __post_init__(self) -> None:
        shared = self.first_leg == self.second_leg
        if shared and self.nearer not in (1, 2):
            raise OptionError(
                f"region on shared leg {self.first_leg!r} needs nearer 1 or 2, got {self.nearer!r}"
            )
        if not shared and self.nearer is not None:
            raise OptionError(f"region on different legs needs nearer None, got {self.nearer!r}")

    @property
    def shared_leg(self) -> bool:
        """Whether both vehicles are on one leg (a ``T`` region)."""
        return self.first_leg == self.second_leg

    @classmethod
    def from_key(cls, graph: StarGraph, key: RegionKey) -> Region:
        """The named region of a :class:`~topology.indexed.RegionKey` on ``graph``."""
        names = graph.names
        return cls(names[key.first_leg], names[key.second_leg], key.nearer or None)

    def key(self, graph: StarGraph) -> RegionKey:
        """The region by leg indices of ``graph``."""
        return RegionKey(graph.index(self.first_leg), graph.index(self.second_leg), self.nearer or 0)

    def __str__(self) -> str:
        if self.shared_leg:
            return f"T({self.first_leg},{self.nearer})"
        return f"Q({self.first_leg},{self.second_leg})"


def region_sequence(graph: StarGraph, configurations) -> tuple[Region, ...]:
    """Reduced region sequence of densely sampled configurations.

    Parameters
    ----------
    graph : StarGraph
    configurations : iterable of Configuration
        Samples along a motion, in time order, dense enough that no region is
        entered and left between two samples except through the same ray.
    """
    keys = (region_key(*as_indexed(graph, configuration)) for configuration in configurations)
    return tuple(Region.from_key(graph, key) for key in reduce_regions(keys))


@dataclass(frozen=True, slots=True)
class Route:
    """A collision-free route of the two vehicles, as the planner produced it.

    Attributes
    ----------
    graph : StarGraph
        The track.
    instruction : Instruction
        Which of the planner's instructions produced the route (two for three legs, three
        for more: :meth:`Instruction.of_track`).
    waypoints : tuple of Configuration
        Start first, goal last; shape (n,), ``n >= 1``. Between consecutive
        waypoints each vehicle moves linearly within one leg (it crosses the
        junction only at a waypoint); no segment has zero length.
    min_separation : float
        The separation the route was planned for, metres.
    arc_length : float
        Three legs: signed length of the trip round the boundary circle, metres,
        positive counterclockwise. Four or more: length of the route on ``G_k``, metres.
    indexed_waypoints : tuple of IndexedConfiguration
        The waypoints in the indexed form ``(leg1, s1, leg2, s2)``, shape (n,).
    cumulative_travel : tuple of float
        Travel ``|ds1| + |ds2|`` from the start to each waypoint, metres, shape (n,).
    homotopy : Homotopy
        ``PLANNED`` if the route takes the class of the planner's instruction, ``OTHER`` for the
        second class (``plan(..., homotopy=Homotopy.OTHER)``).
    """

    graph: StarGraph
    instruction: Instruction
    waypoints: tuple[Configuration, ...]
    min_separation: float
    arc_length: float
    indexed_waypoints: tuple[IndexedConfiguration, ...] = field(repr=False)
    cumulative_travel: tuple[float, ...] = field(repr=False)
    homotopy: Homotopy = Homotopy.PLANNED

    def __post_init__(self) -> None:
        count = len(self.waypoints)
        if count < 1 or len(self.indexed_waypoints) != count or len(self.cumulative_travel) != count:
            raise PositionError(
                f"a route needs one indexed waypoint and one cumulative travel per waypoint, got "
                f"{count}, {len(self.indexed_waypoints)} and {len(self.cumulative_travel)}: "
                "build routes with plan()"
            )

    @property
    def track(self) -> StarGraph:
        """The track the route is on (its :attr:`graph`; a track graph's route names it so too)."""
        return self.graph

    @property
    def way_round(self) -> WayRound:
        """The direction the route goes round the boundary circle (from the sign of ``arc_length``).

        ``GRAPH`` for four or more legs, unless the route stays at one point of ``G_k``.
        """
        if self.graph.cycle is None:
            return WayRound.NOT_APPLICABLE if self.arc_length > 0.0 else WayRound.NONE
        if self.arc_length > 0.0:
            return WayRound.COUNTERCLOCKWISE
        if self.arc_length < 0.0:
            return WayRound.CLOCKWISE
        return WayRound.NONE

    @property
    def start(self) -> Configuration:
        """The start configuration."""
        return self.waypoints[0]

    @property
    def goal(self) -> Configuration:
        """The goal configuration."""
        return self.waypoints[-1]

    @property
    def length(self) -> float:
        """Total travel ``sum |ds1| + |ds2|`` along the route, metres."""
        return self.cumulative_travel[-1]

    @property
    def travel(self) -> tuple[float, float]:
        """Distance driven by vehicle 1 and by vehicle 2, metres."""
        segments = self.segment_travel
        return (sum(first for first, _ in segments), sum(second for _, second in segments))

    @property
    def segment_travel(self) -> tuple[tuple[float, float], ...]:
        """Per segment, the distance driven by vehicle 1 and vehicle 2, metres; shape (n-1, 2)."""
        return tuple(
            (leg_travel(a[0], a[1], b[0], b[1]), leg_travel(a[2], a[3], b[2], b[3]))
            for a, b in itertools.pairwise(self.indexed_waypoints)
        )

    @property
    def segment_region_keys(self) -> tuple[RegionKey | None, ...]:
        """Region of the interior of each segment; shape (n-1,); ``None`` for a segment on a ray."""
        return tuple(segment_region_key(a, b) for a, b in itertools.pairwise(self.indexed_waypoints))

    @property
    def region_entries(self) -> tuple[tuple[RegionKey, int], ...]:
        """The homotopy class by leg indices, with the segment in which each region is entered.

        Returns
        -------
        tuple of (RegionKey, int)
            Reduced region sequence; segment ``k`` runs from waypoint ``k`` to ``k + 1``.
        """
        return reduce_regions_indexed(self.segment_region_keys)

    @property
    def region_keys(self) -> tuple[RegionKey, ...]:
        """The homotopy class by leg indices (see :attr:`regions`)."""
        return tuple(key for key, _ in self.region_entries)

    @property
    def regions(self) -> tuple[Region, ...]:
        """The homotopy class: reduced sequence of regions visited (docs/planner.md, 'Homotopy classes').

        Empty when the whole route stays on one ray (a vehicle parked at the
        junction while the other moves on one leg) or does not move.
        """
        return tuple(Region.from_key(self.graph, key) for key in self.region_keys)

    def at(self, tau: float) -> Configuration:
        """The configuration a fraction ``tau`` in [0, 1] of the travel along the route.

        Parameters
        ----------
        tau : float
            Fraction of the total travel ``|ds1| + |ds2|``; clipped to [0, 1].
        """
        tau = finite_real(tau, "route parameter tau", OptionError)
        cumulative = self.cumulative_travel
        tuples = self.indexed_waypoints
        if len(tuples) == 1 or tau <= 0.0:
            return self.waypoints[0]
        if tau >= 1.0:
            return self.waypoints[-1]
        target = tau * cumulative[-1]
        k = min(bisect.bisect_right(cumulative, target) - 1, len(tuples) - 2)
        a, b = tuples[k], tuples[k + 1]
        span = cumulative[k + 1] - cumulative[k]
        fraction = (target - cumulative[k]) / span
        leg1 = a[0] if a[0] != JUNCTION_INDEX else b[0]
        leg2 = a[2] if a[2] != JUNCTION_INDEX else b[2]
        # s is 0 at the junction, so linear interpolation holds through it too.
        s1 = _between(a[1], b[1], fraction)
        s2 = _between(a[3], b[3], fraction)
        return self.graph.configuration(
            (leg1 if s1 > 0.0 else JUNCTION_INDEX, s1, leg2 if s2 > 0.0 else JUNCTION_INDEX, s2)
        )


def _between(s_a: float, s_b: float, fraction: float) -> float:
    """Linear interpolation clamped to the segment (round-off must not overshoot a leg's end)."""
    s = s_a + fraction * (s_b - s_a)
    return min(max(s, min(s_a, s_b)), max(s_a, s_b))


def plan(
    graph: StarGraph,
    start: Configuration,
    goal: Configuration,
    *,
    min_separation: float = 0.0,
    homotopy: Homotopy | str = Homotopy.PLANNED,
) -> Route:
    """Plan a collision-free route from ``start`` to ``goal``.

    Three legs: the paper's planner (docs/planner.md, 'The two instructions'). Four to eight
    legs: the three-rule geodesic planner on ``G_k`` (docs/star.md).

    Parameters
    ----------
    graph : StarGraph
        The track (a :class:`~topology.YGraph` or any :class:`~topology.StarGraph`).
    start, goal : Configuration
        Vehicle 1 and vehicle 2 positions at the start and at the goal.
    min_separation : float, optional
        Minimum track distance between the vehicles, metres,
        ``0 <= min_separation <= shortest leg``. ``0`` means only "not the
        same point".
    homotopy : Homotopy or str, optional
        ``"planned"`` (default): the class the planner's instruction takes (``"paper"``, its
        name before 0.7, still works with a ``DeprecationWarning``).
        ``"other"``: the same retractions, but the other way round the
        boundary circle (three legs), or the shortest route on ``G_k`` in
        another class (four or more legs). ``Route.instruction`` names the
        planner's instruction either way.

    Returns
    -------
    Route
        The route; the track distance along it never drops below
        ``min(dist(start), dist(goal), shortest leg) >= min_separation``.

    Raises
    ------
    PositionError
        A position is not on the track.
    OptionError
        An unknown ``homotopy``, or ``"other"`` where start and goal retract to
        the same boundary point (the other way would be a full turn).
    SeparationError
        ``min_separation`` out of range (naming the legs it would not fit as
        sidings), or the vehicles closer than it at the start or at the goal.

    Examples
    --------
    >>> from topology import StarGraph, Position, Configuration, plan
    >>> crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    >>> start = Configuration(Position("N", 10.0), Position("S", 10.0))
    >>> route = plan(crossing, start, Configuration(Position("S", 10.0), Position("N", 10.0)))
    >>> route.instruction, len(route.waypoints), route.length
    (<Instruction.SHORTEST: 'shortest'>, 7, 60.0)
    """
    if not isinstance(graph, StarGraph):
        raise TypeError(f"graph must be a StarGraph or YGraph, got {graph!r} ({type(graph).__name__})")
    required = _check_min_separation(graph, min_separation)
    homotopy = Homotopy.lookup(homotopy)
    a = as_indexed(graph, start)
    b = as_indexed(graph, goal)
    for name, config, c in (("start", start, a), ("goal", goal, b)):
        if separation(c) < required:
            raise SeparationError(
                f"vehicles at the {name} {config} are {separation(c)!r} m apart along the track: "
                f"expected at least the min_separation {required!r} m"
            )
    lengths = graph.lengths
    to_boundary = retract_indexed(a, lengths)
    from_boundary = retract_indexed(b, lengths)
    if graph.cycle is None:
        instruction, arc_length, boundary = _route_on_graph(
            graph.retract_graph, to_boundary[-1], from_boundary[-1], homotopy, start, goal
        )
        vertex = graph.retract_graph.vertex_configuration
    else:
        instruction, arc_length, boundary = _route_round_circle(
            graph, to_boundary[-1], from_boundary[-1], homotopy, start, goal
        )
        vertex = graph.cycle.vertex_configuration
    candidates = to_boundary + boundary + from_boundary[::-1]

    # Drop zero-length segments only: a tiny step (even 1e-300 m) may carry a vehicle
    # to the junction, and dropping it would make that vehicle change legs mid-segment.
    kept = [a]
    cumulative = [0.0]
    for c in candidates[1:]:
        travel = step(kept[-1], c)
        if travel > 0.0:
            kept.append(c)
            cumulative.append(cumulative[-1] + travel)
    inner = tuple(vertex.get(c) or graph.configuration(c) for c in kept[1:-1])
    waypoints = (start, *inner, goal) if len(kept) > 1 else (start,)
    return Route(
        graph=graph,
        instruction=instruction,
        waypoints=waypoints,
        min_separation=required,
        arc_length=arc_length,
        indexed_waypoints=tuple(kept),
        cumulative_travel=tuple(cumulative),
        homotopy=homotopy,
    )


def _same_point_refused(start: Configuration, goal: Configuration) -> OptionError:
    return OptionError(
        f"homotopy 'other' from {start} to {goal}: both retract to the same boundary point, so "
        "the other way round is a full turn; expected a query whose retractions differ"
    )


def _route_round_circle(
    graph: StarGraph,
    origin_point: IndexedConfiguration,
    target_point: IndexedConfiguration,
    homotopy: Homotopy,
    start: Configuration,
    goal: Configuration,
) -> tuple[Instruction, float, list[IndexedConfiguration]]:
    """Instruction, signed arc length and cycle vertices passed, three legs (docs/planner.md)."""
    cycle = graph.cycle
    origin = cycle.locate(origin_point)
    target = cycle.locate(target_point)
    perimeter = cycle.perimeter
    half = 0.5 * perimeter
    delta = cycle.counterclockwise_distance(origin, target)
    if abs(delta - half) <= ANTIPODAL_TOLERANCE * perimeter:
        instruction, counterclockwise = Instruction.COUNTERCLOCKWISE, True
    else:
        instruction, counterclockwise = Instruction.SHORTEST, delta < half
    if homotopy is Homotopy.OTHER:
        # the same point: delta is 0, or the perimeter less a round-off (from retractions of
        # positions such as 1e-311 m, a float's step away from the junction)
        if min(delta, perimeter - delta) <= SAME_POINT_TOLERANCE * perimeter:
            raise _same_point_refused(start, goal)
        counterclockwise = not counterclockwise
    arc_length = delta if counterclockwise else -(perimeter - delta)
    return instruction, arc_length, cycle.arc(origin, target, counterclockwise)


def _route_on_graph(
    retract_graph: RetractGraph,
    origin_point: IndexedConfiguration,
    target_point: IndexedConfiguration,
    homotopy: Homotopy,
    start: Configuration,
    goal: Configuration,
) -> tuple[Instruction, float, list[IndexedConfiguration]]:
    """Instruction, length and ``G_k`` vertices passed, four or more legs (docs/star.md, the rules)."""
    origin: GraphPoint = retract_graph.locate(origin_point)
    target: GraphPoint = retract_graph.locate(target_point)
    chosen: Geodesic = retract_graph.shortest(origin, target)
    instruction = _RULE_INSTRUCTION[chosen.tied]
    if homotopy is Homotopy.OTHER:
        if retract_graph.same_point(origin, target, SAME_POINT_TOLERANCE * retract_graph.total_length):
            raise _same_point_refused(start, goal)
        chosen = retract_graph.second_shortest(origin, target, chosen)
    vertices = retract_graph.vertices
    return instruction, chosen.length, [vertices[v] for v in chosen.vertices]


#: Boundary points closer than this fraction of the perimeter are one point (float round-off).
SAME_POINT_TOLERANCE = 64 * sys.float_info.epsilon


def _check_min_separation(graph: StarGraph, min_separation: float) -> float:
    separation = finite_real(min_separation, "min_separation (metres)", SeparationError)
    shortest = graph.shortest_leg
    if separation < 0.0 or separation > shortest:
        short = [
            f"{name!r} ({length!r} m)"
            for name, length in zip(graph.names, graph.lengths, strict=True)
            if length < separation
        ]
        why = f": legs {', '.join(short)} would be too short to serve as sidings" if short else ""
        raise SeparationError(
            f"min_separation must be between 0 m and the shortest leg {shortest!r} m, "
            f"got {separation!r} m{why}"
        )
    return separation
