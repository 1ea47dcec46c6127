"""VDA 5050 orders on track graphs: valid, accepted, and safe whatever the vehicles' timing."""

from __future__ import annotations

import dataclasses
import functools
import json
import math
from datetime import UTC, datetime

import numpy as np
import pytest
from vda5050.domain.order import AcceptanceDecision

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.graph_cases import TINY_BACK_OFF, random_routes, verified_example
from tests.support.graph_rows import ScenarioFile
from tests.support.vda5050_reference import SimulatedVehicle, parse_order, schema_errors
from topology import TrackGraph, plan_graph
from trajgen import certify
from trajgen.cli import main
from trajgen.export.vda5050 import Vda5050Options, render_manifest, render_orders
from trajgen.export.vda5050.graph_path import GraphOrderPath
from trajgen.export.vda5050.path import NodeKind
from trajgen.export.vda5050.release import BaseRelease, order_releases
from trajgen.methods import make_schedule
from trajgen.scenario import load_scenario

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]
OPTIONS = Vda5050Options(start_time=datetime(2026, 1, 1, tzinfo=UTC), map_id="plant")


@functools.cache
def _case(name: str, method: str):
    scenario, verified = verified_example(name, method)
    releases = order_releases(verified)
    messages = render_orders(verified, scenario.names, options=OPTIONS, releases=releases)
    return scenario, verified, releases, messages


def _documents(name: str, method: str) -> dict[str, list[dict]]:
    scenario, _, _, messages = _case(name, method)
    out: dict[str, list[dict]] = {vehicle: [] for vehicle in scenario.names}
    for message in messages:
        out[scenario.names[message.vehicle]].append(json.loads(message.data))
    return out


@pytest.mark.parametrize("method", ["exact", "toppra", pytest.param("optimal", marks=pytest.mark.slow)])
@pytest.mark.parametrize("name", FEASIBLE)
def test_every_graph_order_is_valid_and_each_vehicle_accepts_its_order_and_every_update(name, method):
    scenario = _case(name, method)[0]
    for vehicle, documents in _documents(name, method).items():
        for document in documents:
            assert schema_errors(document) == []
            parse_order(document)  # the sdk's model takes it unchanged
        start = scenario.track.xy(scenario.start[scenario.names.index(vehicle)])
        receiver = SimulatedVehicle(documents[0], *start, map_id=OPTIONS.map_id)
        decisions = [receiver.receive(document).decision for document in documents]
        expected = [AcceptanceDecision.ACCEPT_NEW] + [AcceptanceDecision.ACCEPT_UPDATE] * (len(documents) - 1)
        assert decisions == expected, vehicle


@pytest.mark.parametrize("name", FEASIBLE)
def test_graph_nodes_sit_at_junctions_parking_points_and_reversals_with_their_x_and_y(name):
    scenario, verified, releases, _ = _case(name, "exact")
    track = scenario.track
    for vehicle, path in enumerate(releases.paths):
        graph_path = verified.schedule.paths[vehicle]
        travels = [node.travel for node in path.nodes]
        # every node of the track the path passes, every reversal, each move's end
        for k in range(1, graph_path.edges.size):
            assert min(abs(t - graph_path.starts[k]) for t in travels) < 1e-9
        assert travels[0] == 0.0
        assert travels[-1] == pytest.approx(graph_path.length)
        reversals = [n.travel for n in path.nodes if NodeKind.REVERSAL in n.kinds]
        assert reversals == pytest.approx(list(graph_path.cusps))
        for document in _documents(name, "exact")[scenario.names[vehicle]]:
            for node in document["nodes"]:
                index = node["sequenceId"] // 2
                assert node["nodeId"] == path.node_id(index)
                if not path.placed(index):  # inside a curved edge: where it is, the scenario does not say
                    assert "nodePosition" not in node
                    assert track.node_at(path.nodes[index].point) is None
                    edge = track.edges[path.nodes[index].point.edge]
                    start, end = (track.coordinates[n] for n in track.ends(path.nodes[index].point.edge))
                    assert edge.length > math.dist(start, end)
                    continue
                x, y = track.xy(path.nodes[index].point)
                assert (node["nodePosition"]["x"], node["nodePosition"]["y"]) == pytest.approx(
                    (x, y), abs=1e-9
                )
        # an order edge's length is the path's travel between its nodes; reversed after a turn back
        for edge in path.edges:
            a, b = path.nodes[edge.index], path.nodes[edge.index + 1]
            assert edge.length == pytest.approx(b.travel - a.travel)
            assert sum(high - low for _, low, high in edge.stretches) == pytest.approx(edge.length)
            assert edge.backward == (graph_path.heading(0.5 * (a.travel + b.travel))[0] < 0)


def test_the_claims_gap_equals_the_least_track_distance_between_sampled_points():
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    track = scenario.track
    path = GraphOrderPath(track, (), ())
    rng = np.random.default_rng(7)
    lengths = [edge.length for edge in track.edges]
    for _ in range(200):
        claims = []
        for _ in range(2):
            stretches = []
            for _ in range(rng.integers(1, 3)):
                edge = int(rng.integers(len(lengths)))
                low, high = np.sort(rng.uniform(0.0, lengths[edge], 2))
                stretches.append((edge, float(low), float(high)))
            claims.append(tuple(stretches))
        sampled, slack = math.inf, math.inf
        for (ea, la, ha), (eb, lb, hb) in ((a, b) for a in claims[0] for b in claims[1]):
            sa, sb = np.meshgrid(np.linspace(la, ha, 41), np.linspace(lb, hb, 41))
            distances = track.distances(np.full(sa.size, ea), sa.ravel(), np.full(sb.size, eb), sb.ravel())
            if distances.min() < sampled:
                # the track distance is 1-Lipschitz in each point: between samples at most this lower
                sampled, slack = float(distances.min()), 0.5 * ((ha - la) + (hb - lb)) / 40
        gap = path.gap(*claims)
        assert gap <= sampled + 1e-9
        assert gap >= sampled - slack - 1e-9


def test_the_claims_gap_is_the_track_graphs_own_distance_at_the_corners_to_the_bit():
    """The release rule's gaps in plain floats are the track's own distances at the stretches' ends.

    Issue 48: readying a plan (off the master's lock) measures its gaps in plain floats; they are
    bit for bit what :meth:`TrackGraph.distances` gives, on seeded random graphs.
    """
    import random

    from trajgen.scenario.graph_sampling import random_graph_track

    rng = np.random.default_rng(11)
    for seed in range(20):
        track = random_graph_track(random.Random(seed), junctions=1 + seed % 4, loops=seed % 3)
        path = GraphOrderPath(track, (), ())
        lengths = [edge.length for edge in track.edges]
        for _ in range(50):
            claims = []
            for _ in range(2):
                edge = int(rng.integers(len(lengths)))
                low, high = np.sort(rng.uniform(0.0, lengths[edge], 2))
                claims.append(((edge, float(low), float(high)),))
            (ea, la, ha), (eb, lb, hb) = claims[0][0], claims[1][0]
            if ea == eb and la <= hb and lb <= ha:
                assert path.gap(*claims) == 0.0
                continue
            corners = [(sa, sb) for sa in (la, ha) for sb in (lb, hb)]
            expected = track.distances([ea] * 4, [c[0] for c in corners], [eb] * 4, [c[1] for c in corners])
            assert path.gap(*claims) == float(expected.min())


@pytest.mark.parametrize("method", ["exact", "toppra", pytest.param("optimal", marks=pytest.mark.slow)])
@pytest.mark.parametrize(
    "name",
    [  # the H in the fast set, every example end to end
        pytest.param(name, marks=() if name == "h" else pytest.mark.slow) for name in FEASIBLE
    ],
)
def test_the_releases_keep_the_separation_whatever_the_timing_and_never_deadlock(name, method):
    """Both vehicles driven at random paces, each only within its released base, 10 seeded runs.

    The separation is measured by the tests' own track distance (from the scenario file alone).
    """
    scenario, verified, releases, _ = _case(name, method)
    own = ScenarioFile(EXAMPLES / f"{name}.toml")
    names = [edge.name for edge in scenario.track.edges]
    for seed in range(10):
        closest = _drive_at_random_paces(
            verified, releases, lambda a, b: own.distance(*_named(names, a, b)), seed
        )
        # at every sample (one vehicle moves per step, the distance is 1-Lipschitz in its travel)
        assert closest >= scenario.limits.min_separation - 1e-9, (seed, closest)


@pytest.mark.slow
def test_the_releases_on_seeded_random_graphs_keep_the_separation_whatever_the_timing():
    """12 random trees and graphs with loops (no node coordinates): exact and toppra, 3 paces each."""
    for seed, route, limits in random_routes(12, 3000):
        for method in ("exact", "toppra"):
            verified = certify(make_schedule(route, limits, method=method))
            releases = order_releases(verified)
            track = route.track

            def distance(a, b, track=track):
                return float(track.distances([a[0]], [a[1]], [b[0]], [b[1]])[0])

            for pace in range(3):
                closest = _drive_at_random_paces(verified, releases, distance, pace)
                assert closest >= limits.min_separation - 1e-9, (seed, method, pace, closest)


def _named(names, a, b):
    return (names[a[0]], a[1]), (names[b[0]], b[1])


def _drive_at_random_paces(verified, releases, distance, seed: int, step: float = 0.05) -> float:
    """Both vehicles driven at random paces, each only within its released base; the least distance.

    ``distance((edge, s), (edge, s))``: the track distance the caller trusts, metres.
    """
    paths = verified.schedule.paths
    rng = np.random.default_rng(seed)
    rule = BaseRelease(releases.paths, verified.schedule.limits.min_separation)
    travel = [0.0, 0.0]
    closest = math.inf
    for _ in range(200_000):
        if rule.reached == list(rule.last):
            return closest
        limits = [releases.paths[v].nodes[rule.released[v]].travel for v in (0, 1)]
        movable = [v for v in (0, 1) if travel[v] < limits[v] - 1e-12]
        assert movable, f"deadlock at nodes {rule.reached} (seed {seed})"
        v = int(rng.choice(movable))
        travel[v] = min(travel[v] + rng.uniform(0.2, 1.0) * step, limits[v])
        nodes = releases.paths[v].nodes
        while rule.reached[v] < rule.released[v] and nodes[rule.reached[v] + 1].travel <= travel[v] + 1e-12:
            rule.reach(v, rule.reached[v] + 1)
        where = []
        for u in (0, 1):
            edge, s = paths[u].locate(travel[u])
            where.append((int(edge[0]), float(s[0])))
        closest = min(closest, distance(*where))
    pytest.fail(f"not at the goals after 200,000 steps (seed {seed})")


def test_export_vda5050_writes_a_graphs_orders_and_manifest(tmp_path, capsys):
    out = tmp_path / "orders"
    args = [
        "export-vda5050",
        str(EXAMPLES / "h.toml"),
        "--out",
        str(out),
        "--start-time",
        "2026-01-01T00:00:00Z",
    ]
    assert main([*args, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["method"] == "exact"
    assert summary["vehicles"]["agv1"]["nodes"] == [
        "A",
        "a:1.5",
        "J1",
        "m:1.5",
        "m:6.5",
        "J2",
        "c:1.5",
        "J2",
        "e:1.5",
        "D",
    ]
    assert summary["vehicles"]["agv2"]["nodes"] == ["D", "e:1.5", "J2", "m:6.5", "m:1.5", "J1", "a:1.5", "A"]
    manifest = json.loads((out / "manifest.json").read_text())
    assert [m["file"] for m in manifest["messages"]] == [
        "agv1/order-000.json",
        "agv2/order-000.json",
        "agv2/order-001.json",
        "agv1/order-001.json",
    ]
    # agv2 drives up to the edge of J2's zone at once, and on once agv1 is parked at c:1.5, 1.5 m past
    # J2; agv1 goes back once agv2 is 1.5 m past J2 on its way to J1
    assert manifest["messages"][1]["decision_point"] == {"node_id": "e:1.5", "sequence_id": 2}
    assert manifest["messages"][2]["trigger"] == {"vehicle": "agv1", "node_id": "c:1.5", "sequence_id": 12}
    assert manifest["messages"][3]["trigger"] == {"vehicle": "agv2", "node_id": "m:6.5", "sequence_id": 6}
    first = json.loads((out / "agv1" / "order-000.json").read_text())
    assert [e.get("direction") for e in first["edges"]] == [None, None, "m", None, None, "c", None, "e", None]
    assert [e["orientation"] for e in first["edges"]] == [0.0] * 6 + [math.pi] * 3
    assert first["nodes"][1]["nodeDescription"] == "hold: the minimum separation from junction J1"
    assert first["nodes"][6]["nodeDescription"] == "reversal, hold: the minimum separation from junction J2"


def test_a_graph_without_coordinates_has_orders_without_node_positions(tmp_path):
    track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    verified = certify(make_schedule(route, Limits((agv, agv), 1.5), method="exact"))
    messages = render_orders(verified, ("one", "two"), options=OPTIONS)
    for message in messages:
        document = json.loads(message.data)
        assert schema_errors(document) == []
        assert all("nodePosition" not in node for node in document["nodes"])
    manifest = json.loads(render_manifest(verified, ("one", "two"), messages, options=OPTIONS))
    assert manifest["vehicles"]["one"]["nodes"][0] == "A"
    assert manifest["vehicles"]["one"]["nodes"][-1] == "B"


@pytest.mark.slow
@pytest.mark.parametrize("name", FEASIBLE)
def test_the_optimal_plans_orders_with_their_waits_run_faster_than_moving_one_vehicle_at_a_time(name):
    """The hold nodes at the edge of each junction's zone let a vehicle come up while the other passes."""
    _, _, releases, _ = _case(name, "optimal")
    _, exact, _, _ = _case(name, "exact")
    assert releases.planned_duration < exact.schedule.duration


def test_a_vehicle_that_backs_off_a_micrometre_gets_orders_that_keep_the_separation(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_BACK_OFF)
    scenario = load_scenario(path)
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    releases = order_releases(verified)
    # its start, its parking point 1 µm back and its goal are three nodes, not one
    assert [releases.paths[1].node_id(k) for k in range(len(releases.paths[1].nodes))] == [
        "b:1.499999",
        "b:1.5",
        "b:1.499999",
    ]
    track = scenario.track

    def distance(a, b):
        return float(track.distances([a[0]], [a[1]], [b[0]], [b[1]])[0])

    for pace in range(5):
        closest = _drive_at_random_paces(verified, releases, distance, pace)
        assert closest >= scenario.limits.min_separation - 1e-9


def test_nodes_less_than_a_micrometre_apart_keep_distinct_ids(tmp_path):
    """A back-off of 0.1 µm: ids to the nanometre on that edge, so no edge runs from a node to itself."""
    path = tmp_path / "tinier.toml"
    path.write_text(TINY_BACK_OFF.replace("b:1.499999", "b:1.4999999"))
    scenario = load_scenario(path)
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    releases = order_releases(verified)
    ids = [releases.paths[1].node_id(k) for k in range(len(releases.paths[1].nodes))]
    assert ids == ["b:1.4999999", "b:1.5", "b:1.4999999"]
    # agv1's ids stay to the micrometre where nothing is that close
    assert all(
        len(i.partition(":")[2].partition(".")[2]) <= 6 for i in map(releases.paths[0].node_id, range(3))
    )
    messages = render_orders(verified, scenario.names, options=OPTIONS, releases=releases)
    for message in messages:
        for edge in json.loads(message.data)["edges"]:
            assert edge["startNodeId"] != edge["endNodeId"], edge
    # a chain of places 0.8 nm apart spans 1.6 nm: its ends are distinct places with distinct ids
    chain = (1.5000000002, 1.5000000010, 1.5000000018)
    path = releases.paths[1]
    nodes = tuple(
        dataclasses.replace(path.nodes[0], point=dataclasses.replace(path.nodes[0].point, s=s)) for s in chain
    )
    chained = dataclasses.replace(path, nodes=nodes, edges=path.edges[:2])
    ids = [chained.node_id(k) for k in range(3)]
    assert ids[0] != ids[2], ids
