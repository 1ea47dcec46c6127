"""The execution form of a vehicle's path on a track graph, and the graph metric it uses.

Checked against the vectorised forms the schedules use, and against dense sampling.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.graph_cases import random_routes, verified_example
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath

FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


def _cases():
    """Every example's route and 12 seeded random ones (trees and loops), with both paths."""
    for name in FEASIBLE:
        scenario, verified = verified_example(name, "exact")
        yield name, scenario.track, verified.schedule.route
    for seed, route, _ in random_routes(12, 5000):
        yield f"seed {seed}", route.track, route


CASES = list(_cases())


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_place_axis_and_heading_agree_with_the_schedules_path(name, track, route):
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        p = np.linspace(0.0, path.length, 401)
        edges, s = path.locate(p)
        for k, q in enumerate(p):
            edge, along, heading, axis, _ = fast.place(float(q))
            assert fast.locate(float(q)) == (edge, along)
            assert track.distances([edge], [along], [edges[k]], [s[k]])[0] <= 1e-9, (name, q)
            assert axis == pytest.approx(float(path.axis(q)[0]), abs=1e-9)
            assert fast.heading(float(q)) == heading
        assert fast.stops == tuple(path.cusps)
        assert fast.length == path.length


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_a_place_projects_back_to_its_travel_and_an_axis_value_to_its_travel(name, track, route):
    metric = GraphMetric(track)
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track, axis_start=3.0)
        for q in np.linspace(0.0, path.length, 97):
            q = float(q)
            edge, s = fast.locate(q)
            assert fast.project(edge, s, q, metric) == pytest.approx(q, abs=1e-9), (name, q)
            if fast.edges:
                velocity = fast.heading(q)  # moving on along its path
                assert fast.travel_at_axis(fast.axis(q), max(q - 1e-3, 0.0), velocity) == pytest.approx(
                    q, abs=1e-9
                )


def test_a_position_off_the_path_does_not_project_and_one_past_its_end_runs_on():
    """Off the path: None. Past the goal along the last edge: travel beyond the length.

    The same for the edge's end node given on another of its edges (the same node).
    """
    ran_on, nodes_elsewhere = 0, 0
    for _, track, route in CASES:
        metric = GraphMetric(track)
        fast = GraphVehiclePath.from_path(graph_paths(route)[0], track)
        if not fast.edges:
            continue
        used = set(fast.edges) | set(graph_paths(route)[1].edges.tolist())
        for other in (k for k in range(track.edge_count) if k not in used):
            midway = 0.5 * track.length(other)
            if metric.distance(other, midway, *fast.locate(0.0)) > midway + 1e-6:  # not a neighbour
                assert fast.project(other, midway, 0.0, metric) is None
        k = len(fast.edges) - 1
        edge, ahead = fast.edges[k], (1.0 if fast.s_to[k] > fast.s_from[k] else -1.0)
        top = track.length(edge)
        room = top - fast.s_to[k] if ahead > 0 else fast.s_to[k]
        if room > 0.25:
            ran_on += 1
            end = fast.s_to[k] + ahead * 0.25
            assert fast.project(edge, end, fast.length, metric) == pytest.approx(fast.length + 0.25)
        node = track.ends(edge)[1 if ahead > 0 else 0]
        at_node = fast.length + room
        assert fast.project(edge, top if ahead > 0 else 0.0, at_node, metric) == pytest.approx(at_node)
        for neighbour in range(track.edge_count):
            u, v = track.ends(neighbour)
            if neighbour == edge or node not in (u, v) or neighbour in fast.edges:
                continue
            nodes_elsewhere += 1
            given = 0.0 if u == node else track.length(neighbour)
            assert fast.project(neighbour, given, at_node, metric) == pytest.approx(at_node), (
                edge,
                neighbour,
            )
    assert ran_on >= 3, ran_on
    assert nodes_elsewhere >= 3, nodes_elsewhere


def test_the_metric_agrees_with_the_tracks_vectorised_distances():
    rng = np.random.default_rng(7)
    for _, track, _ in CASES:
        metric = GraphMetric(track)
        lengths = np.array([track.length(k) for k in range(track.edge_count)])
        ea, eb = rng.integers(0, track.edge_count, 200), rng.integers(0, track.edge_count, 200)
        sa, sb = rng.random(200) * lengths[ea], rng.random(200) * lengths[eb]
        expected = track.distances(ea, sa, eb, sb)
        got = [
            metric.distance(int(a), float(x), int(b), float(y))
            for a, x, b, y in zip(ea, sa, eb, sb, strict=True)
        ]
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_the_stretch_distance_is_the_least_over_dense_samples_of_both_stretches():
    rng = np.random.default_rng(11)
    for _, track, _ in CASES[:8]:
        metric = GraphMetric(track)
        for _ in range(30):
            stretches = []
            for _ in range(2):
                edge = int(rng.integers(0, track.edge_count))
                low, high = sorted(rng.random(2) * track.length(edge))
                stretches.append((edge, float(low), float(high)))
            a, b = stretches
            u, w = np.linspace(a[1], a[2], 60), np.linspace(b[1], b[2], 60)
            uu, ww = (x.ravel() for x in np.meshgrid(u, w))
            sampled = track.distances(np.full(uu.size, a[0]), uu, np.full(ww.size, b[0]), ww).min()
            exact = metric.stretch_distance(a, b)
            # a lower bound, and within the sampling step of the samples' least
            step = max(a[2] - a[1], b[2] - b[1]) / 59.0
            assert exact <= sampled + 1e-12
            assert exact >= sampled - step - 1e-12


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_a_sweep_holds_every_place_of_its_travel_range_and_no_more(name, track, route):
    metric = GraphMetric(track)
    rng = np.random.default_rng(3)
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        for _ in range(20):
            low, high = sorted(rng.uniform(-0.5, path.length + 0.5, 2))
            swept = fast.sweep(float(low), float(high))
            samples = np.linspace(low, high, 200)
            places = [_run_on(fast, float(q)) for q in samples]
            for edge, s in places:
                assert metric.set_distance(swept, ((edge, s, s),)) <= 1e-9, (name, low, high)
            # every end of a stretch is within a sample step of a place driven
            step = (high - low) / 199.0 + 1e-9
            for edge, lo, hi in swept:
                for end in (lo, hi):
                    assert min(metric.distance(edge, end, e, s) for e, s in places) <= step + 1e-9


def _run_on(fast: GraphVehiclePath, q: float) -> tuple[int, float]:
    """Where travel ``q`` puts the vehicle, running on along the end segments' edges (clipped)."""
    if not fast.edges:
        return fast.home
    k = 0 if q < 0.0 else (len(fast.edges) - 1 if q > fast.length else fast.segment(q))
    sign = 1.0 if fast.s_to[k] > fast.s_from[k] else -1.0
    s = fast.s_from[k] + sign * (q - fast.starts[k])
    if 0.0 <= q <= fast.length:
        return fast.locate(q)
    return fast.edges[k], min(max(s, 0.0), fast.edge_lengths[fast.edges[k]])


def test_an_axis_given_the_other_way_round_flips_every_heading():
    _, track, route = CASES[0]
    path = graph_paths(route)[1]
    along = GraphVehiclePath.from_path(path, track)
    direction = 1 if path.s_to[0] > path.s_from[0] else -1
    against = GraphVehiclePath.from_path(path, track, axis_start=2.0, orientation=-direction)
    assert against.headings == tuple(-h for h in along.headings)
    for q in np.linspace(0.0, path.length, 21):
        assert against.axis(float(q)) == pytest.approx(2.0 - along.axis(float(q)))


def test_a_vehicle_that_stays_put_sweeps_its_home_and_any_travel_off_it_is_overrun():
    """Its path does not say which way it would go: travel off 0 is all overrun, in any direction."""
    still = 0
    for _, track, route in CASES:
        for path in graph_paths(route):
            if path.edges.size:
                continue
            still += 1
            fast = GraphVehiclePath.from_path(path, track)
            assert fast.sweep(-1.0, 0.5) == ((path.home.edge, path.home.s, path.home.s),)
            assert fast.overrun(-1.0, 0.5) == 1.0
            assert fast.overrun(0.0, 0.0) == 0.0
            assert all(fast.locate(q) == fast.home for q in (-1.0, 0.0, 1.0))
    assert still >= 1


def test_the_overrun_is_what_runs_past_the_end_segments_edge_ends_only():
    """Within the end segments' edges the sweep holds the run-on: no overrun; past them, the rest."""
    for _, track, route in CASES:
        fast = GraphVehiclePath.from_path(graph_paths(route)[0], track)
        if not fast.edges:
            continue
        assert fast.overrun(0.0, fast.length) == 0.0
        k = len(fast.edges) - 1
        room = track.length(fast.edges[k]) - fast.s_to[k] if fast.s_to[k] > fast.s_from[k] else fast.s_to[k]
        assert fast.overrun(0.0, fast.length + room) == pytest.approx(0.0, abs=1e-12)
        assert fast.overrun(0.0, fast.length + room + 0.3) == pytest.approx(0.3)
        top = track.length(fast.edges[0])
        back = fast.s_from[0] if fast.s_to[0] > fast.s_from[0] else top - fast.s_from[0]
        assert fast.overrun(-back - 0.2, fast.length) == pytest.approx(0.2)


@pytest.mark.parametrize(("name", "track", "route"), CASES, ids=[c[0] for c in CASES])
def test_the_branch_is_the_edge_the_vehicle_is_on_once_it_leaves_its_segment(name, track, route):
    for path in graph_paths(route):
        fast = GraphVehiclePath.from_path(path, track)
        for k in range(len(fast.edges)):
            end = fast.starts[k + 1] if k + 1 < len(fast.edges) else fast.length
            middle = 0.5 * (fast.starts[k] + end)
            after = fast.place(min(end + 1e-6, fast.length))[0] if k + 1 < len(fast.edges) else fast.edges[k]
            assert fast.place(middle)[4] == after, (name, k)
