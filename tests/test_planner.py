"""The planner of ALGORITHM.md and STAR-JUNCTIONS.md on junctions of 3 to 8 legs.

The worked example and stored references on a Y, the properties of every route over random
tracks of 3 to 8 legs (a test of a property that holds for any number of legs is parametrized
over it: ``legs3`` a Y, ``legs4-8`` stars of 4 to 8 legs drawn at random), the three rules on
``G_k`` checked against the graph rebuilt from the text (:mod:`tests.support.star_spec`), the
continuity of each instruction, and the other class. ``G_k`` itself is in ``test_retract_graph.py``.
"""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from tests.support.continuity import CONTINUITY_BOUND, continuity_cases
from tests.support.helpers import legs_id
from tests.support.star_spec import (
    ETA,
    LEGS4,
    Point,
    SpecGraph,
    boundary_walk,
    check_valid_route,
    first_three_tie,
    first_two_tie,
    indexed,
    plan_indexed,
    scaled_indexed,
    spec_retract,
    tied_routes,
    travel,
    walk_length,
)
from tests.support.strategies import configurations, queries, star_queries, tracks
from topology import (
    Cell,
    Configuration,
    Homotopy,
    Instruction,
    Position,
    Region,
    StarGraph,
    WayRound,
    YGraph,
    boundary_angle,
    classify,
    is_antipodal,
    plan,
    retract,
)
from topology.errors import OptionError, TrackError
from topology.retract_graph import TIE_TOLERANCE
from topology.route import SAME_POINT_TOLERANCE


def conf(first: str, second: str) -> Configuration:
    return Configuration(Position.parse(first), Position.parse(second))


def waypoint_texts(route) -> list[tuple[str, str]]:
    return [(str(w.first), str(w.second)) for w in route.waypoints]


def assert_waypoints_close(route, expected: list[tuple[str, str]], tol: float = 1e-9) -> None:
    assert len(route.waypoints) == len(expected), waypoint_texts(route)
    for got, (first, second) in zip(route.waypoints, expected, strict=True):
        for p, text in zip(got, (first, second), strict=True):
            q = Position.parse(text)
            assert p.leg == q.leg, waypoint_texts(route)
            assert p.s == pytest.approx(q.s, abs=tol), waypoint_texts(route)


# -- closed form: the worked example and the cycle ---------------------------------------------------


def test_worked_example_of_algorithm_section_7():
    track = YGraph({"A": 1.0, "B": 1.0, "C": 1.0})
    route = plan(track, conf("A:1", "B:1"), conf("B:1", "A:1"))
    assert route.instruction is Instruction.COUNTERCLOCKWISE
    assert waypoint_texts(route) == [
        ("A:1", "B:1"),
        ("A:1", "O"),
        ("A:1", "C:1"),
        ("O", "C:1"),
        ("B:1", "C:1"),
        ("B:1", "O"),
        ("B:1", "A:1"),
    ]
    assert route.travel == (2.0, 4.0)
    assert [str(r) for r in route.regions] == ["Q(A,B)", "Q(A,C)", "Q(B,C)", "Q(B,A)"]


def test_boundary_cycle_is_the_oriented_cycle_of_section_4():
    track = YGraph({"A": 2.0, "B": 3.0, "C": 5.0})
    expected = [
        "P(A,B)",
        "V2(A)",
        "P(A,C)",
        "V1(C)",
        "P(B,C)",
        "V2(B)",
        "P(B,A)",
        "V1(A)",
        "P(C,A)",
        "V2(C)",
        "P(C,B)",
        "V1(B)",
    ]

    def name(c: Configuration) -> str:
        if c.first.leg is None:
            return f"V1({c.second.leg})"
        if c.second.leg is None:
            return f"V2({c.first.leg})"
        return f"P({c.first.leg},{c.second.leg})"

    assert [name(v) for v in track.boundary_vertices] == expected
    assert track.perimeter == pytest.approx(4 * (2.0 + 3.0 + 5.0))
    # each edge moves one vehicle along one whole leg
    vertices = track.boundary_vertices + track.boundary_vertices[:1]
    angles = (*track.boundary_vertex_angles, track.perimeter)
    for k in range(12):
        a, b = vertices[k], vertices[k + 1]
        moved = [p for p, q in zip(a, b, strict=True) if p != q]
        assert len(moved) == 1
        length = track.distance(a.first, b.first) + track.distance(a.second, b.second)
        assert angles[k + 1] - angles[k] == pytest.approx(length)
        assert length in track.lengths


# -- stored reference routes (computed by hand from ALGORITHM.md) -------------------------------------

REFERENCE_TRACK = {"A": 10.0, "B": 8.0, "C": 15.0}
REFERENCES = [
    pytest.param(
        ("A:3", "B:2"),
        ("C:4", "C:9"),
        1.5,
        Instruction.SHORTEST,
        [
            ("A:3", "B:2"),
            ("A:10", f"B:{20 / 3!r}"),
            ("A:10", "O"),
            ("A:10", "C:15"),
            ("O", "C:15"),
            ("O", "C:9"),
            ("C:4", "C:9"),
        ],
        (21.0, 32.0 + 1 / 3),
        id="quadrangle-to-triangle-ccw",
    ),
    pytest.param(
        ("B:5", "B:2"),
        ("C:1", "A:1"),
        0.0,
        Instruction.SHORTEST,
        [
            ("B:5", "B:2"),
            ("B:5", "O"),
            ("B:8", "O"),
            ("B:8", "A:10"),
            ("O", "A:10"),
            ("C:10", "A:10"),
            ("C:1", "A:1"),
        ],
        (30.0, 21.0),
        id="triangle-to-quadrangle-ccw",
    ),
    pytest.param(
        ("A:10", "O"),
        ("A:10", "B:8"),
        0.0,
        Instruction.SHORTEST,
        [("A:10", "O"), ("A:10", "B:8")],
        (0.0, 8.0),
        id="valley-to-peak-clockwise",
    ),
    pytest.param(
        ("A:10", "C:15"),
        ("C:15", "A:10"),
        1.5,
        Instruction.COUNTERCLOCKWISE,
        [
            ("A:10", "C:15"),
            ("O", "C:15"),
            ("B:8", "C:15"),
            ("B:8", "O"),
            ("B:8", "A:10"),
            ("O", "A:10"),
            ("C:15", "A:10"),
        ],
        (10.0 + 8.0 + 8.0 + 15.0, 15.0 + 10.0),
        id="swap-A-C",
    ),
    pytest.param(  # the instruction is continuous, so it goes out to the boundary and back
        ("A:4", "O"),
        ("A:4", "O"),
        0.0,
        Instruction.SHORTEST,
        [("A:4", "O"), ("A:10", "O"), ("A:4", "O")],
        (12.0, 0.0),
        id="start-is-goal-interior",
    ),
    pytest.param(
        ("A:10", "B:3"),
        ("A:10", "B:3"),
        0.0,
        Instruction.SHORTEST,
        [("A:10", "B:3")],
        (0.0, 0.0),
        id="start-is-goal-boundary",
    ),
    pytest.param(  # a hair off a vertex: the arc must still pass that vertex, not loop round
        ("C:1e-200", "A:10"),
        ("O", "A:10"),
        0.0,
        Instruction.SHORTEST,
        [("C:1e-200", "A:10"), ("O", "A:10")],
        (1e-200, 0.0),
        id="hair-off-a-vertex",
    ),
]


@pytest.mark.parametrize(("start", "goal", "separation", "instruction", "expected", "travel"), REFERENCES)
def test_reference_routes(start, goal, separation, instruction, expected, travel):
    track = YGraph(REFERENCE_TRACK)
    route = plan(track, conf(*start), conf(*goal), min_separation=separation)
    assert route.instruction is instruction
    assert_waypoints_close(route, expected)
    assert route.travel == pytest.approx(travel, abs=1e-9)


@pytest.mark.parametrize(
    ("first", "second", "cell"),
    [
        pytest.param("A:1", "A:2", Cell.TRIANGLE, id="triangle"),
        pytest.param("A:10", "A:2", Cell.TRIANGLE, id="triangle-with-endpoint"),
        pytest.param("O", "B:2", Cell.RAY, id="ray"),
        pytest.param("A:1", "B:2", Cell.QUADRANGLE, id="quadrangle"),
        pytest.param("A:10", "B:2", Cell.BOUNDARY, id="edge"),
        pytest.param("A:10", "C:15", Cell.PEAK, id="peak"),
        pytest.param("O", "C:15", Cell.VALLEY, id="valley"),
    ],
)
def test_classify(first, second, cell):
    assert classify(YGraph(REFERENCE_TRACK), conf(first, second)) is cell


@pytest.mark.parametrize(
    ("track", "start", "end"),
    [
        pytest.param(YGraph(REFERENCE_TRACK), ("A:2", "C:6"), ("A:5", "C:15"), id="legs3"),  # 6/15 > 2/10
        pytest.param(StarGraph(LEGS4), ("N:3", "S:1"), ("N:6", "S:2"), id="legs4"),  # 1/2 > 3/10
    ],
)
def test_quadrangle_retraction_is_radial(track, start, end):
    c = conf(*start)
    path = retract(track, c)
    # ALGORITHM.md section 3 from its text, for any number of legs
    assert [indexed(track, w) for w in path] == spec_retract(indexed(track, c), track.lengths)
    # radially out until the vehicle nearer its leg's end reaches it
    first, second = path[-1]
    expected = conf(*end)
    assert second == expected.second
    assert first.leg == expected.first.leg
    assert first.s == pytest.approx(expected.first.s)
    assert first.s / second.s == pytest.approx(c.first.s / c.second.s)


# -- properties over random tracks, separations and queries -------------------------------------------


def _segment_samples(graph: StarGraph, a: Configuration, b: Configuration, count: int = 33):
    """Positions along one route segment, interpolated independently of Route.at."""
    legs = []
    for p, q in zip(a, b, strict=True):
        assert p.leg is None or q.leg is None or p.leg == q.leg, "a vehicle changed legs inside a segment"
        legs.append(p.leg if p.leg is not None else q.leg)
    for k in range(count + 1):
        f = k / count
        interpolated = [
            min(max((1.0 - f) * p.s + f * q.s, min(p.s, q.s)), max(p.s, q.s))
            for p, q in zip(a, b, strict=True)
        ]
        yield Configuration(
            *(Position(leg if s > 0 else None, s) for leg, s in zip(legs, interpolated, strict=True))
        )


def check_route(
    graph: StarGraph, start: Configuration, goal: Configuration, separation: float, route
) -> None:
    """Exact endpoints, separation along every segment, and retraction + one arc + reversed retraction.

    For any number of legs (the arc is the route on ``G_k``, the circle of a Y).
    """
    assert route.waypoints[0] == start
    assert route.waypoints[-1] == goal
    floor = min(graph.separation(start), graph.separation(goal), graph.shortest_leg)
    assert floor >= separation
    for a, b in zip(route.waypoints, route.waypoints[1:], strict=False):
        assert graph.distance(a.first, b.first) + graph.distance(a.second, b.second) > 0.0
        for sample in _segment_samples(graph, a, b):
            assert graph.separation(sample) >= floor - 1e-9 * graph.boundary_length
    into = retract(graph, start)
    out = retract(graph, goal)
    legs = [
        sum(
            graph.distance(p.first, q.first) + graph.distance(p.second, q.second)
            for p, q in itertools.pairwise(r)
        )
        for r in (into, out)
    ]
    assert route.length == pytest.approx(
        legs[0] + abs(route.arc_length) + legs[1], abs=1e-9 * graph.boundary_length
    )


#: Random queries (graph, start, goal, min_separation) by the number of legs: a Y, and stars of 4 to
#: 8 legs (each example draws its number of legs).
RANDOM_QUERIES = {"legs3": queries(), "legs4-8": star_queries()}


@pytest.mark.parametrize("legs", RANDOM_QUERIES)
@given(data=st.data())
def test_route_properties(legs, data):
    graph, start, goal, separation = data.draw(RANDOM_QUERIES[legs], label="query")
    route = plan(graph, start, goal, min_separation=separation)
    check_route(graph, start, goal, separation, route)
    check_valid_route(graph, start, goal, separation, route)  # ALGORITHM.md section 5, indexed form
    assert route.homotopy is Homotopy.PLANNED
    assert route.instruction in Instruction.of_track(graph)
    if graph.leg_count == 3:  # at most half round the circle
        assert abs(route.arc_length) <= graph.perimeter / 2 * (1 + 1e-9)
    else:  # no way round on G_k
        assert route.way_round is (WayRound.NOT_APPLICABLE if route.arc_length > 0 else WayRound.NONE)


@given(queries())
def test_a_star_of_three_legs_plans_exactly_as_the_y(query):
    graph, start, goal, separation = query
    star = StarGraph(graph.legs)
    assert star.cycle is not None
    assert star.angles_deg == graph.angles_deg
    for homotopy in ("planned", "other"):
        try:
            expected = plan(graph, start, goal, min_separation=separation, homotopy=homotopy)
        except OptionError:
            with pytest.raises(OptionError, match="both retract to the same boundary point"):
                plan(star, start, goal, min_separation=separation, homotopy=homotopy)
            continue
        got = plan(star, start, goal, min_separation=separation, homotopy=homotopy)
        assert got.instruction is expected.instruction
        assert got.waypoints == expected.waypoints
        assert got.indexed_waypoints == expected.indexed_waypoints
        assert got.arc_length == expected.arc_length
        assert got.way_round is expected.way_round
        assert got.region_keys == expected.region_keys


@given(star_queries())
def test_the_route_on_g_k_is_shortest_up_to_the_perturbation(query):
    graph, start, goal, separation = query
    route = plan(graph, start, goal, min_separation=separation)
    spec = SpecGraph.of(graph)
    walk = boundary_walk(route, spec)
    length = walk_length(walk)
    tolerance = 1e-9 * graph.boundary_length
    assert route.arc_length == pytest.approx(length, abs=tolerance)
    assert route.length == pytest.approx(
        sum(walk_length(spec_retract(indexed(graph, c), graph.lengths)) for c in (start, goal)) + length,
        abs=tolerance,
    )
    rg = graph.retract_graph
    for c in (walk[0], walk[-1]):  # the planner locates the ends where the spec does
        got, expected = rg.locate(c), spec.locate(c)
        if expected.vertex >= 0:
            assert rg.vertices[got.vertex] == spec.vertices[expected.vertex]
        else:
            peak, valley = (rg.vertices[v] for v in rg.edges[got.edge])
            assert (peak, valley) == tuple(spec.vertices[v] for v in spec.edges[expected.edge])
            assert got.offset == pytest.approx(expected.offset, abs=1e-12 * graph.boundary_length)
    shortest = spec.length(spec.locate(walk[0]), spec.locate(walk[-1]))
    assert length >= shortest - tolerance
    assert length <= (1 + ETA) * shortest + tolerance
    # and shortest under the perturbed lengths, up to the tie tolerance
    perturbed = spec.length(spec.locate(walk[0]), spec.locate(walk[-1]), perturbed=True)
    walked = math.fsum(
        travel(a, b) * spec.factors[spec.common_edge(a, b)] for a, b in itertools.pairwise(walk)
    )
    assert walked <= perturbed + TIE_TOLERANCE * spec.total_perturbed + 1e-12


def test_a_separation_of_the_shortest_leg_is_accepted():
    crossing = StarGraph(LEGS4)
    start = Configuration(Position("N", 10.0), Position("W", 10.0))
    route = plan(crossing, start, start.swapped(), min_separation=2.0)
    check_valid_route(crossing, start, start.swapped(), 2.0, route)


def test_a_round_off_away_from_one_boundary_point_is_no_other_class():
    # a float's step from the junction: both retract to one boundary point, up to 7e-15 m of round-off
    graph = YGraph({"A": 1.4581779460430724, "B": 2.4581779460430724, "C": 27.0})
    start = Configuration(Position("B", 2.225073858507e-311), Position("A", 1.0))
    goal = Configuration(Position(None, 0.0), Position("A", 1.4581779460430724))
    assert abs(plan(graph, start, goal).arc_length) < 1e-12
    with pytest.raises(OptionError, match=r"both retract to the same boundary point"):
        plan(graph, start, goal, homotopy="other")


@pytest.mark.parametrize("legs", RANDOM_QUERIES)
@given(data=st.data())
def test_the_other_class_is_the_next_shortest_way(legs, data):
    """Round the circle the other way on a Y; the second-shortest simple route on ``G_k`` of a star."""
    graph, start, goal, separation = data.draw(RANDOM_QUERIES[legs], label="query")
    paper = plan(graph, start, goal, min_separation=separation)
    if graph.leg_count == 3:
        same_point = abs(paper.arc_length) <= SAME_POINT_TOLERANCE * graph.perimeter
        apart = not same_point
    else:
        spec = SpecGraph.of(graph)
        walk = boundary_walk(paper, spec)
        x, y = spec.locate(walk[0]), spec.locate(walk[-1])
        distance = spec.length(x, y)
        same_point = distance <= 64 * 2.3e-16 * spec.total_perturbed
        apart = distance > 1e-9 * spec.total_perturbed
    if same_point:  # one boundary point: no other way but a full turn, no route
        with pytest.raises(OptionError, match=r"both retract to the same boundary point"):
            plan(graph, start, goal, min_separation=separation, homotopy="other")
    assume(apart)
    other = plan(graph, start, goal, min_separation=separation, homotopy="other")
    check_route(graph, start, goal, separation, other)
    check_valid_route(graph, start, goal, separation, other)
    assert other.homotopy is Homotopy.OTHER
    assert other.instruction is paper.instruction  # the paper's instruction, named either way
    assert other.region_keys != paper.region_keys  # another class
    tolerance = 1e-9 * graph.boundary_length
    if graph.leg_count == 3:
        assert {paper.way_round, other.way_round} == {WayRound.COUNTERCLOCKWISE, WayRound.CLOCKWISE}
        # the two shortest classes: together once round the circle, the paper's the shorter (or equal)
        assert abs(paper.arc_length) + abs(other.arc_length) == pytest.approx(graph.perimeter, abs=tolerance)
        # (counterclockwise within the antipodal tolerance either side of half a turn: up to 2 x longer)
        assert abs(paper.arc_length) <= abs(other.arc_length) + 2 * tolerance
        assert other.regions != paper.regions
        return
    length = walk_length(boundary_walk(other, spec))
    assert other.arc_length == pytest.approx(length, abs=tolerance)
    # not shorter than the paper's route beyond the perturbation
    assert length >= paper.arc_length / (1 + ETA) - tolerance
    # the second-shortest simple route: the shortest one that leaves out a step of the paper's
    second = min(
        spec.length(x, y, banned={frozenset((spec.node(a, x, y), spec.node(b, x, y)))})
        for a, b in itertools.pairwise(walk)
    )
    assert second - tolerance <= length <= (1 + ETA) * second + tolerance


#: Queries whose start and goal retract to one boundary point, by the number of legs: (track, start, goal).
ONE_BOUNDARY_POINT = {
    "legs3": [
        # both retract radially to P(A, B)
        (YGraph({"A": 10.0, "B": 10.0, "C": 10.0}), ("A:5", "B:5"), ("A:6", "B:6")),
        # round-off: the paper's arc is -0.0 here, so "the other way" would be a full turn
        (YGraph({"A": 1.0, "B": 1.0, "C": 1.0}), ("A:0.1", "B:0.3"), (f"A:{1 / 3}", "B:1")),
    ],
    "legs4": [
        # both radially to P(N, S)
        (StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}), ("N:5", "S:5"), ("N:6", "S:6")),
        # on G_4 already, and the same point
        (StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}), ("N:10", "S:4"), ("N:5", "S:2")),
    ],
}


@pytest.mark.parametrize("legs", ONE_BOUNDARY_POINT)
def test_the_other_class_of_a_query_that_stays_at_one_boundary_point_is_refused(legs):
    same_point = r"homotopy 'other' from .* both retract to the same boundary point"
    for graph, start, goal in ONE_BOUNDARY_POINT[legs]:
        route = plan(graph, conf(*start), conf(*goal))
        assert route.arc_length == 0.0
        assert route.way_round is WayRound.NONE
        with pytest.raises(OptionError, match=same_point):
            plan(graph, conf(*start), conf(*goal), homotopy="other")
    graph, start, goal = ONE_BOUNDARY_POINT[legs][0]
    with pytest.raises(
        OptionError, match=r"homotopy 'both' is unknown: expected one of \['planned', 'other'\]"
    ):
        plan(graph, conf(*start), conf(*goal), homotopy="both")


@given(queries())
def test_counterclockwise_iff_boundary_goal_is_swapped_boundary_start(query):
    graph, start, goal, separation = query
    route = plan(graph, start, goal, min_separation=separation)
    b0 = retract(graph, start)[-1]
    b1 = retract(graph, goal)[-1]
    gap = sum(graph.distance(p, q) for p, q in zip(b1, b0.swapped(), strict=True))
    tolerance = 1e-9 * graph.perimeter
    if gap <= 0.5 * tolerance:
        assert route.instruction is Instruction.COUNTERCLOCKWISE
        assert route.arc_length == pytest.approx(graph.perimeter / 2, abs=tolerance)
    elif gap >= 2 * tolerance:
        assert route.instruction is Instruction.SHORTEST
        assert abs(route.arc_length) < graph.perimeter / 2
    assert is_antipodal(graph, b0, b1) == (route.instruction is Instruction.COUNTERCLOCKWISE)


@given(data=st.data())
def test_swapping_is_a_half_turn(data):
    graph = data.draw(tracks())
    boundary = retract(graph, data.draw(configurations(graph)))[-1]
    half = graph.perimeter / 2
    delta = (boundary_angle(graph, boundary.swapped()) - boundary_angle(graph, boundary)) % graph.perimeter
    assert delta == pytest.approx(half, abs=1e-9 * graph.perimeter)


def test_boundary_angle_of_a_star_is_a_clear_error():
    crossing = StarGraph(LEGS4)
    with pytest.raises(TrackError, match="no boundary circle"):
        boundary_angle(crossing, Configuration(Position("N", 10.0), Position("S", 1.0)))


@given(data=st.data())
def test_retraction_ends_on_the_boundary_and_never_decreases_separation(data):
    graph = data.draw(tracks())
    configuration = data.draw(configurations(graph))
    path = retract(graph, configuration)
    assert path[0] == configuration
    assert classify(graph, path[-1]).on_boundary
    separations = [graph.separation(c) for c in path]
    assert separations == sorted(separations)


def _nudge(graph: YGraph, position: Position, step: float) -> Position:
    """Move a vehicle ``step`` metres outward (``step < 0``: toward, and past, the junction)."""
    if position.leg is None:
        return Position(graph.names[0], abs(step))
    s = position.s + step
    if s >= 0.0:
        return Position(position.leg, min(s, graph.length(position.leg)))
    other = graph.names[(graph.index(position.leg) + 1) % 3]
    return Position(other, -s)


@given(data=st.data())
def test_each_instruction_is_continuous_in_the_start(data):
    graph, start, goal, separation = data.draw(queries())
    vehicle = data.draw(st.sampled_from([0, 1]))
    step = data.draw(st.sampled_from([1e-7, -1e-7]))
    moved = list(start)
    moved[vehicle] = _nudge(graph, moved[vehicle], step)
    nudged = Configuration(*moved)
    # a motion of 1e-7 m inside the valid space: no vehicle passes through the other
    same_leg = start.first.leg is not None and start.first.leg == start.second.leg
    if same_leg and nudged.first.leg == nudged.second.leg:
        assume((start.first.s - start.second.s) * (nudged.first.s - nudged.second.s) > 0)
    assume(graph.separation(nudged) >= max(separation, 1e-6))
    # continuity is topological: near the junction the radial retraction magnifies a
    # perturbation by up to (leg length) / s; keep starts where that gain is below 100
    for c in (start, nudged):
        if classify(graph, c) is Cell.QUADRANGLE:
            ratio = max(c.first.s / graph.length(c.first.leg), c.second.s / graph.length(c.second.leg))
            assume(ratio * min(graph.lengths) >= 0.01 * max(graph.lengths))
    # a swap query moves its goal with the start, to stay in the counterclockwise domain
    nudged_goal = nudged.swapped() if goal == start.swapped() else goal
    a = plan(graph, start, goal, min_separation=separation)
    b = plan(graph, nudged, nudged_goal, min_separation=separation)
    assume(a.instruction == b.instruction)  # both inside one instruction's domain
    # the shortest instruction switches direction only through a tiny arc (continuous there)
    assume(math.copysign(1, a.arc_length) == math.copysign(1, b.arc_length) or abs(a.arc_length) < 1e-3)
    for k in range(101):
        tau = k / 100
        p, q = a.at(tau), b.at(tau)
        moved = graph.distance(p.first, q.first) + graph.distance(p.second, q.second)
        assert moved <= 1e-4, (tau, str(p), str(q))


#: Cases per (kind, k) in the test of the star's instructions, and the least share of them that must be
#: comparable (both queries under one instruction and class).
CONTINUITY_CASES = 100
COMPARABLE = {"generic": 0.3, "tie": 0.1, "vertex": 0.9}


@pytest.mark.parametrize("k", [4, 6, 8], ids=legs_id)
@pytest.mark.parametrize("kind", ["generic", "tie", "vertex"])
def test_each_instruction_is_continuous_on_its_domain(kind, k):
    compared = [c for c in continuity_cases(kind, k, CONTINUITY_CASES) if c is not None]
    assert len(compared) >= COMPARABLE[kind] * CONTINUITY_CASES
    if kind == "tie":
        assert all(c.first.instruction is Instruction.TWO_TIED for c in compared)
    if kind == "generic":
        assert sum(c.first.instruction is Instruction.SHORTEST for c in compared) >= 0.9 * len(compared)
    worst = max(compared, key=lambda c: c.normalized)
    assert worst.normalized <= CONTINUITY_BOUND, (worst.first.waypoints, worst.second.waypoints)


@given(queries(), st.floats(0.0, 1.0))
def test_at_is_proportional_to_travel(query, tau):
    graph, start, goal, separation = query
    route = plan(graph, start, goal, min_separation=separation)
    here = route.at(tau)
    travelled_start = graph.distance(start.first, here.first) + graph.distance(start.second, here.second)
    travelled_goal = graph.distance(here.first, goal.first) + graph.distance(here.second, goal.second)
    # along the route, travel from the start is tau * length, so the direct distance is at most that
    assert travelled_start <= tau * route.length + 1e-9 * graph.perimeter
    assert travelled_goal <= (1 - tau) * route.length + 1e-9 * graph.perimeter


def test_regions_of_a_route_through_a_triangle():
    track = YGraph(REFERENCE_TRACK)
    route = plan(track, conf("A:3", "B:2"), conf("C:4", "C:9"), min_separation=1.5)
    assert route.regions == (Region("A", "B"), Region("A", "C"), Region("C", "C", 1))


def test_route_on_one_ray_has_empty_region_sequence():
    track = YGraph(REFERENCE_TRACK)
    route = plan(track, conf("O", "A:2"), conf("O", "A:7"))
    assert route.regions == ()
    assert route.travel == pytest.approx((0.0, 8.0 + 3.0))


# -- the three rules on G_k of a star ----------------------------------------------------------------------

#: Fixed tracks of 4 to 8 legs (a 4-way crossing first), lengths in metres.
FIXED_TRACKS = {
    4: {"N": 12.0, "W": 7.5, "S": 9.0, "E": 15.0},
    5: {"N": 12.0, "W": 7.5, "S": 9.0, "E": 15.0, "U": 4.0},
    6: {"N": 12.0, "W": 7.5, "S": 9.0, "E": 15.0, "U": 4.0, "V": 20.0},
    7: {"N": 12.0, "W": 7.5, "S": 9.0, "E": 15.0, "U": 4.0, "V": 20.0, "X": 6.5},
    8: {"N": 12.0, "W": 7.5, "S": 9.0, "E": 15.0, "U": 4.0, "V": 20.0, "X": 6.5, "Y": 11.0},
}


def check_tied_choice(graph: StarGraph, spec: SpecGraph, x: Point, y: Point, count: int, instruction):
    """Plan from x to y (on G_k and pulled inside); check the rule and the tie, independently computed."""
    tied = tied_routes(spec, x, y)
    assert len(tied) == count
    lengths = [d for d, _ in tied]
    assert max(lengths) - min(lengths) <= 1e-9 * spec.total_perturbed  # equal perturbed lengths
    walks = [spec.walk(x, vertices, y) for _, vertices in tied]
    for a, b in itertools.combinations(walks, 2):
        assert a != b  # pairwise different routes ...
        assert [c for c in a if c in spec.index] != [c for c in b if c in spec.index]  # ... and vertex paths
    for factor in (1.0, 0.75):  # on G_k, and from inside (the same retractions)
        start, goal = (scaled_indexed(spec.configuration(p), factor) for p in (x, y))
        route = plan_indexed(graph, start, goal)
        assert route.instruction is instruction
        walk = boundary_walk(route, spec)
        vertex_paths = [[c for c in w if c in spec.index] for w in walks]
        assert [c for c in walk if c in spec.index] in vertex_paths  # one of the tied routes
        if count == 2:  # rule 2: the larger integral of w
            chosen = vertex_paths.index([c for c in walk if c in spec.index])
            integrals = [spec.w_integral(w) for w in walks]
            assert integrals[chosen] == max(integrals)
            assert abs(integrals[0] - integrals[1]) > 1e-9  # the two differ by a cycle of non-zero w


@pytest.mark.parametrize("k", sorted(FIXED_TRACKS), ids=legs_id)
def test_the_three_instructions_all_occur(k):
    graph = StarGraph(FIXED_TRACKS[k])
    spec = SpecGraph.of(graph)
    assert Instruction.of_track(graph) == (Instruction.SHORTEST, Instruction.TWO_TIED, Instruction.MANY_TIED)
    # rule 1: a generic query, one shortest route
    x, y = Point(edge=1, offset=1.0), Point(edge=len(spec.edges) // 2, offset=2.0)
    check_tied_choice(graph, spec, x, y, 1, Instruction.SHORTEST)
    check_tied_choice(graph, spec, *first_two_tie(spec), 2, Instruction.TWO_TIED)
    check_tied_choice(graph, spec, *first_three_tie(spec), 3, Instruction.MANY_TIED)


@pytest.mark.parametrize("k", range(3, 9), ids=legs_id)
def test_instructions_of_a_track(k):
    star = StarGraph({f"l{j}": 5.0 for j in range(k)})
    expected = (
        (Instruction.SHORTEST, Instruction.COUNTERCLOCKWISE)
        if k == 3
        else (Instruction.SHORTEST, Instruction.TWO_TIED, Instruction.MANY_TIED)
    )
    assert Instruction.of_track(star) == expected
    if k == 3:
        assert Instruction.of_track(YGraph({"A": 1.0, "B": 2.0, "C": 3.0})) == expected
