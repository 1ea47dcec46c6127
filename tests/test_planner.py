"""The planner of ALGORITHM.md: worked example, stored references, properties."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from tests.support.strategies import configurations, queries, tracks
from topology import (
    Cell,
    Configuration,
    Homotopy,
    Instruction,
    Position,
    Region,
    WayRound,
    YGraph,
    boundary_angle,
    classify,
    is_antipodal,
    plan,
    retract,
)
from topology.errors import OptionError
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


def test_quadrangle_retraction_is_radial():
    track = YGraph(REFERENCE_TRACK)
    path = retract(track, conf("A:2", "C:6"))
    end = path[-1]
    assert end.second == track.endpoint("C")  # 6/15 > 2/10
    assert end.first.s == pytest.approx(2.0 * 15.0 / 6.0)
    assert end.first.s / end.second.s == pytest.approx(2.0 / 6.0)


# -- properties over random tracks, separations and queries -------------------------------------------


def _segment_samples(graph: YGraph, a: Configuration, b: Configuration, count: int = 33):
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


def check_route(graph: YGraph, start: Configuration, goal: Configuration, separation: float, route) -> None:
    """Exact endpoints, separation along every segment, and retraction + one arc + reversed retraction."""
    assert route.waypoints[0] == start
    assert route.waypoints[-1] == goal
    floor = min(graph.separation(start), graph.separation(goal), graph.shortest_leg)
    assert floor >= separation
    for a, b in zip(route.waypoints, route.waypoints[1:], strict=False):
        assert graph.distance(a.first, b.first) + graph.distance(a.second, b.second) > 0.0
        for sample in _segment_samples(graph, a, b):
            assert graph.separation(sample) >= floor - 1e-9 * graph.perimeter
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
        legs[0] + abs(route.arc_length) + legs[1], abs=1e-9 * graph.perimeter
    )


@given(queries())
def test_route_properties(query):
    graph, start, goal, separation = query
    route = plan(graph, start, goal, min_separation=separation)
    check_route(graph, start, goal, separation, route)
    assert route.homotopy is Homotopy.PLANNED
    assert abs(route.arc_length) <= graph.perimeter / 2 * (1 + 1e-9)


def test_a_round_off_away_from_one_boundary_point_is_no_other_class():
    # a float's step from the junction: both retract to one boundary point, up to 7e-15 m of round-off
    graph = YGraph({"A": 1.4581779460430724, "B": 2.4581779460430724, "C": 27.0})
    start = Configuration(Position("B", 2.225073858507e-311), Position("A", 1.0))
    goal = Configuration(Position(None, 0.0), Position("A", 1.4581779460430724))
    assert abs(plan(graph, start, goal).arc_length) < 1e-12
    with pytest.raises(OptionError, match=r"both retract to the same boundary point"):
        plan(graph, start, goal, homotopy="other")


@given(queries())
def test_the_other_class_goes_the_other_way_round_the_circle(query):
    graph, start, goal, separation = query
    paper = plan(graph, start, goal, min_separation=separation)
    same_point = abs(paper.arc_length) <= SAME_POINT_TOLERANCE * graph.perimeter
    if same_point:  # no other way round but a full turn
        with pytest.raises(OptionError, match=r"both retract to the same boundary point"):
            plan(graph, start, goal, min_separation=separation, homotopy="other")
    assume(not same_point)
    other = plan(graph, start, goal, min_separation=separation, homotopy="other")
    check_route(graph, start, goal, separation, other)
    assert other.homotopy is Homotopy.OTHER
    assert other.instruction is paper.instruction  # the paper's instruction, named either way
    assert {paper.way_round, other.way_round} == {WayRound.COUNTERCLOCKWISE, WayRound.CLOCKWISE}
    # the two shortest classes: together once round the circle, the paper's the shorter (or equal)
    tolerance = 1e-9 * graph.perimeter
    assert abs(paper.arc_length) + abs(other.arc_length) == pytest.approx(graph.perimeter, abs=tolerance)
    # (counterclockwise within the antipodal tolerance either side of half a turn: up to 2 x longer)
    assert abs(paper.arc_length) <= abs(other.arc_length) + 2 * tolerance
    assert other.regions != paper.regions


def test_the_other_class_of_a_query_that_stays_at_one_boundary_point_is_refused():
    graph = YGraph({"A": 10.0, "B": 10.0, "C": 10.0})
    start, goal = conf("A:5", "B:5"), conf("A:6", "B:6")  # both retract radially to P(A, B)
    assert plan(graph, start, goal).arc_length == 0.0
    same_point = r"homotopy 'other' from .* both retract to the same boundary point"
    with pytest.raises(OptionError, match=same_point):
        plan(graph, start, goal, homotopy="other")
    # round-off: the paper's arc is -0.0 here, so "the other way" would be a full turn
    tiny = YGraph({"A": 1.0, "B": 1.0, "C": 1.0})
    near, far = conf("A:0.1", "B:0.3"), conf(f"A:{1 / 3}", "B:1")
    assert plan(tiny, near, far).arc_length == 0.0
    with pytest.raises(OptionError, match=same_point):
        plan(tiny, near, far, homotopy="other")
    with pytest.raises(
        OptionError, match=r"homotopy 'both' is unknown: expected one of \['planned', 'other'\]"
    ):
        plan(graph, start, goal, homotopy="both")


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
