"""The retract graph ``G_k`` of a junction of 3 to 8 legs (topology/retract_graph.py, STAR-JUNCTIONS.md).

Its vertices, edges and lengths against the graph rebuilt from the text
(:class:`tests.support.star_spec.SpecGraph`), its geodesics on a Y (``G_3``, the 12-cycle), the
perturbation of its lengths, and locating a configuration on it. The planner that walks it is
in ``test_planner.py``.
"""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given

from tests.support.helpers import legs_id
from tests.support.star_spec import (
    AT_O,
    ETA,
    LEGS4,
    SpecGraph,
    assert_same_waypoints,
    drop_zero_steps,
    indexed,
    named,
    plan_indexed,
    spec_retract,
    travel,
    walk_length,
)
from tests.support.strategies import queries
from topology import Instruction, StarGraph, plan
from topology.errors import PositionError
from topology.retract_graph import TIE_TOLERANCE

# -- the graph: vertices, edges, lengths, weights -----------------------------------------------------


@pytest.mark.parametrize("k", range(3, 9), ids=legs_id)
def test_the_retract_graph_has_the_size_and_edges_of_the_spec(k):
    lengths = [1.0 + 0.7 * j for j in range(k)]
    graph = StarGraph({f"l{j}": length for j, length in enumerate(lengths)})
    rg, spec = graph.retract_graph, SpecGraph(graph.lengths)
    vertices, edges = len(rg.vertices), len(rg.edges)
    assert vertices == k * (k + 1)
    assert edges == 2 * k * (k - 1)
    assert edges - vertices + 1 == (k - 1) * (k - 2) - 1  # first Betti number: 1, 5, 11, 19, 29, 41
    assert np_finite(rg.distances)  # connected
    # the documented order: peaks P(i, j) in (i, j) order, then V1(0..k-1), then V2(0..k-1)
    peaks = [(i, lengths[i], j, lengths[j]) for i, j in itertools.permutations(range(k), 2)]
    assert list(rg.vertices) == [
        *peaks,
        *((AT_O, 0.0, j, lengths[j]) for j in range(k)),
        *((i, lengths[i], AT_O, 0.0) for i in range(k)),
    ]
    for p, (i, _, j, _) in enumerate(peaks):  # edge 2p: vehicle 1 runs leg i; 2p + 1: vehicle 2 runs leg j
        assert rg.vertices[rg.edges[2 * p][1]] == (AT_O, 0.0, j, lengths[j])
        assert rg.edge_lengths[2 * p] == lengths[i]
        assert rg.vertices[rg.edges[2 * p + 1][1]] == (i, lengths[i], AT_O, 0.0)
        assert rg.edge_lengths[2 * p + 1] == lengths[j]
    # the same graph as the spec's, edge for edge, with the same lengths
    ours = sorted(
        (spec.vertices[a], spec.vertices[b], spec.lengths_of_edges[e]) for e, (a, b) in enumerate(spec.edges)
    )
    theirs = sorted(
        (rg.vertices[a], rg.vertices[b], float(rg.edge_lengths[e])) for e, (a, b) in enumerate(rg.edges)
    )
    assert ours == theirs
    assert rg.edge_lengths.sum() == pytest.approx(graph.boundary_length)
    assert rg.total_length == pytest.approx(rg.perturbed_lengths.sum())
    factors = rg.perturbed_lengths / rg.edge_lengths
    assert all(abs(w) <= 1.0 for w in rg.weights)
    if k == 3:  # the circle: exact lengths, w = +1 counterclockwise
        assert all(factors == 1.0)
        cycle = graph.cycle.vertex_tuples
        successor = {cycle[n]: cycle[(n + 1) % 12] for n in range(12)}
        for e, (a, b) in enumerate(rg.edges):
            assert rg.weights[e] == (1.0 if successor[rg.vertices[a]] == rg.vertices[b] else -1.0)
    else:
        assert all((factors >= 1.0) & (factors < 1.0 + ETA))
        assert len(set(factors.tolist())) == edges  # generic
    for c, configuration in zip(rg.vertices, rg.vertex_configurations, strict=True):
        assert graph.configuration(c) == configuration == named(graph, c)
    # the boundary's vertices: the 12-cycle's order for a Y, those of G_k for more legs
    if k == 3:
        assert set(graph.boundary_vertices) == set(rg.vertex_configurations)
    else:
        assert graph.boundary_vertices == rg.vertex_configurations


def np_finite(array) -> bool:
    return bool((array < math.inf).all())


def test_locating_a_configuration_off_the_boundary_is_a_position_error():
    graph = StarGraph(LEGS4).retract_graph
    with pytest.raises(PositionError, match=r"configuration \(0, 3\.0, 2, 1\.0\) is not on the boundary"):
        graph.locate((0, 3.0, 2, 1.0))


# -- k = 3: the geodesic machinery of G_3 is the cycle planner ------------------------------------------


@given(queries())
def test_on_a_y_the_geodesic_of_g3_is_the_cycle_planners_route(query):
    graph, start, goal, separation = query
    route = plan(graph, start, goal, min_separation=separation)
    rg = graph.retract_graph
    into = spec_retract(indexed(graph, start), graph.lengths)
    out = spec_retract(indexed(graph, goal), graph.lengths)
    geodesic = rg.shortest(rg.locate(into[-1]), rg.locate(out[-1]))
    expected = drop_zero_steps([*into, *(rg.vertices[v] for v in geodesic.vertices), *out[::-1]])
    assert_same_waypoints(route.indexed_waypoints, expected)
    assert_same_waypoints([indexed(graph, c) for c in route.waypoints], expected)
    perimeter = graph.perimeter
    assert geodesic.length == pytest.approx(abs(route.arc_length), abs=1e-9 * perimeter)
    assert geodesic.perturbed_length == pytest.approx(geodesic.length, rel=1e-12)  # exact on the circle
    assert (geodesic.tied == 2) == (route.instruction is Instruction.COUNTERCLOCKWISE)
    assert geodesic.tied in (1, 2)
    if geodesic.tied == 2:  # the paper's rule: counterclockwise, half a turn
        assert route.arc_length == pytest.approx(perimeter / 2, abs=1e-9 * perimeter)


# -- k >= 4: the perturbation of the lengths ------------------------------------------------------------


def test_the_perturbation_breaks_the_exact_ties_of_an_even_crossing():
    # N <-> S swap on equal legs: four routes of exactly 60 m (via W or E, vehicle 1 or 2 first)
    crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    spec = SpecGraph.of(crossing)
    n, w, s, e = range(4)
    start, goal = (n, 10.0, s, 10.0), (s, 10.0, n, 10.0)
    routes = [
        [
            start,
            (AT_O, 0.0, s, 10.0),
            (m, 10.0, s, 10.0),
            (m, 10.0, AT_O, 0.0),
            (m, 10.0, n, 10.0),
            (AT_O, 0.0, n, 10.0),
            goal,
        ]
        for m in (w, e)
    ] + [
        [
            start,
            (n, 10.0, AT_O, 0.0),
            (n, 10.0, m, 10.0),
            (AT_O, 0.0, m, 10.0),
            (s, 10.0, m, 10.0),
            (s, 10.0, AT_O, 0.0),
            goal,
        ]
        for m in (w, e)
    ]
    assert [walk_length(r) for r in routes] == [60.0] * 4
    assert spec.length(spec.locate(start), spec.locate(goal)) == 60.0
    perturbed = [
        math.fsum(travel(a, b) * spec.factors[spec.common_edge(a, b)] for a, b in itertools.pairwise(r))
        for r in routes
    ]
    assert (
        min(abs(a - b) for a, b in itertools.combinations(perturbed, 2))
        > 1e3 * TIE_TOLERANCE * spec.total_perturbed
    )
    route = plan_indexed(crossing, start, goal)
    assert route.instruction is Instruction.SHORTEST  # no exact tie survives the perturbation
    assert list(route.indexed_waypoints) == routes[perturbed.index(min(perturbed))]
    assert route.length == route.arc_length == 60.0
