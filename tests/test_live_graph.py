"""Live runs on a track graph (issue 37): the master, simulated vehicles and a real broker on the H.

The H's side edges b and e curve (6.5 m between nodes 6.4 m apart), so their inner nodes have no
position: the vehicles drive there by the edges' lengths and say where they are by their last node
and ``distanceSinceLastNode``, as line-guided vehicles do; :class:`ClosestApproach` places them on
the track by those (:func:`~trajgen.live.places.snapshot_point`).
"""

from __future__ import annotations

import concurrent.futures
import functools
import json
import math
from types import SimpleNamespace

import pytest

from tests.support.graph_cases import EXAMPLES
from tests.support.helpers import stop_bound
from tests.support.live import FAST, HOP_S, Tap, logged_serve, new_broker, serve_with_vehicle_processes
from tests.support.vda5050_reference import schema_errors
from topology import EdgePoint, TrackGraph
from trajgen.cli import main
from trajgen.errors import InputError
from trajgen.export.vda5050.graph_path import point_id
from trajgen.live.driven_path import DrivenPath
from trajgen.live.master import LiveMaster, LiveOutcome
from trajgen.live.mqtt import BrokerSettings, VehicleIdentity
from trajgen.live.places import live_goal, restart_place, snapshot_point, start_place
from trajgen.live.session import LiveDemo, live_plan
from trajgen.live.vehicle import StopFault
from trajgen.scenario import load_scenario

pytestmark = pytest.mark.slow

H = EXAMPLES / "h.toml"
#: What a command says of a place on an edge the H does not have.
NOT_ON_THE_H = "edge 'zz' is not on the track: expected one of ['a', 'b', 'm', 'c', 'e']"


@functools.cache
def h_plan():
    """The H and its exact plan for execution, once per test process."""
    scenario = load_scenario(H)
    return scenario, live_plan(scenario, method="exact")


def _drive(*, at=(), faults=((), ())):
    scenario, verified = h_plan()
    demo = LiveDemo(scenario, verified, method="exact", faults=faults, **FAST)
    demo.__enter__()
    try:
        return demo.run(at=at)
    finally:
        demo.__exit__()


def _final_points(outcome, track: TrackGraph) -> list[EdgePoint]:
    return [
        snapshot_point(track, v.snapshot.node, v.snapshot.next_node, v.snapshot.along)
        for v in outcome.vehicles
    ]


# -- the parts, closed form ---------------------------------------------------------------------------


def _node(node_id, released=True, x=None, y=None):
    position = None if x is None else SimpleNamespace(x=x, y=y)
    return SimpleNamespace(node_id=node_id, released=released, node_position=position, sequence_id=0)


def _edge(length, orientation=0.0):
    return SimpleNamespace(length=length, orientation=orientation)


def test_a_driven_path_without_positions_goes_by_edge_lengths_and_turns_where_orientation_flips():
    nodes = [_node("b:1"), _node("b:3"), _node("b:4.5"), _node("b:2")]
    edges = [_edge(2.0), _edge(1.5), _edge(2.5, math.pi)]
    path = DrivenPath(nodes, edges)
    assert path.arcs == [0.0, 2.0, 3.5, 6.0]
    assert [path.reversal(k) for k in range(4)] == [False, False, True, False]
    assert path.point(1.0) is None  # no position to give
    assert path.place(4.0, 2) == ("b:4.5", "b:2", 0.5)


def test_a_driven_path_takes_a_curved_edge_by_its_length_and_a_straight_one_by_its_positions():
    nodes = [_node("J1", x=0.0, y=0.0), _node("B", x=-5.0, y=-4.0), _node("J2", x=3.0, y=4.0)]
    path = DrivenPath(nodes, [_edge(6.5), _edge(5.0)])  # 6.5 m between nodes 6.403 m apart: a curve
    assert path.arcs == pytest.approx([0.0, 6.5, 6.5 + math.hypot(8.0, 8.0)])
    assert path.point(3.0) is None  # on the curve: not on the chord
    x, y, _ = path.point(6.5 + math.hypot(8.0, 8.0) / 2)
    assert (x, y) == pytest.approx((-1.0, 0.0))


def test_a_snapshot_is_placed_on_the_track_from_its_nodes():
    track = load_scenario(H).track
    assert snapshot_point(track, "m:2", "m:4.5", 1.0) == track.point("m:3")
    assert snapshot_point(track, "J2", "m:4.5", 1.0) == track.point("m:7")  # m runs J1 -> J2
    assert snapshot_point(track, "b:6", "B", 0.25) == track.point("b:6.25")
    assert snapshot_point(track, "J1", "", 0.0) == track.point("J1")
    assert snapshot_point(track, "m:7.5", "J2", 3.0) == track.point("J2")  # not past the next node
    with pytest.raises(InputError, match=r"nodes 'A' and 'D' share no edge of the track"):
        snapshot_point(track, "A", "D", 1.0)


def test_a_vehicle_on_a_graph_knows_its_node_and_is_placed_by_it_after_a_restart():
    track = load_scenario(H).track
    assert start_place(track, "A") == (None, "A")
    assert start_place(track, "b:3.25") == (None, "b:3.25")
    assert point_id(track, track.point("e:1.0000004")) == "e:1"  # to the micrometre
    state = SimpleNamespace(last_node_id="b:3.25", agv_position=None)
    assert restart_place(track, state) == track.point("b:3.25")
    with pytest.raises(InputError, match=r"zz"):
        restart_place(track, SimpleNamespace(last_node_id="zz:1", agv_position=None))


@pytest.mark.parametrize(
    ("goal", "match"),
    [
        ("C", r"live goal must be 2 positions on the track, one per vehicle, got 'C'"),
        (("C", "zz:1"), r"zz"),
        (("C", "c:7"), r"c:7|7"),
    ],
    ids=["one", "unknown-edge", "off-the-edge"],
)
def test_a_bad_live_goal_on_a_graph_is_refused_naming_it(goal, match):
    with pytest.raises(InputError, match=match):
        live_goal(load_scenario(H).track, goal, 2)


# -- live runs on the H --------------------------------------------------------------------------------


def test_the_h_driven_live_reaches_its_goals_keeping_the_separation_every_message_schema_valid():
    scenario, verified = h_plan()
    demo = LiveDemo(scenario, verified, method="exact", **FAST)
    demo.__enter__()
    tap = Tap(demo.broker.url)
    try:
        outcome = demo.run()
    finally:
        tap.close()
        demo.__exit__()
    run = outcome.run
    assert run.outcome is LiveOutcome.GOALS_REACHED
    assert math.isfinite(outcome.closest)  # compared at every cycle both drove
    assert outcome.closest >= scenario.limits.min_separation - 1e-6
    assert run.ignored == 0
    assert run.makespan <= run.planned * 1.05 + 1.0, (run.makespan, run.planned)
    for kind in ("order", "state", "connection"):
        documents = tap.of(kind)
        assert documents, kind
        for document in documents:
            assert schema_errors(document, kind) == [], (kind, document.get("headerId"))
    orders = tap.of("order")
    # the curved side edges' inner nodes carry no position; every edge carries its length
    assert any(node.get("nodePosition") is None for order in orders for node in order["nodes"])
    assert all(edge.get("length") is not None for order in orders for edge in order["edges"])
    states = tap.of("state")
    assert any("agvPosition" not in state for state in states)  # on a curve: its node and distance only
    assert _final_points(outcome, scenario.track) == list(scenario.goal)


def test_a_stop_fault_on_the_h_makes_the_other_wait_and_costs_at_most_the_online_bound():
    scenario, _ = h_plan()
    duration = 6.0
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        free, stopped = pool.map(
            lambda faults: _drive(faults=faults), [((), ()), ((StopFault(4.0, duration),), ())]
        )
    assert stopped.run.outcome is LiveOutcome.GOALS_REACHED
    assert math.isfinite(stopped.closest)
    assert stopped.closest >= scenario.limits.min_separation - 1e-6
    latency = 2 * HOP_S * FAST["time_scale"]
    assert stopped.run.makespan <= free.run.makespan + stop_bound(scenario, duration) + latency
    assert stopped.run.makespan > free.run.makespan + 0.5 * duration  # the stop did hold the run up


def test_a_broker_restart_and_a_new_goal_on_the_h_are_survived_and_reached():
    scenario, _ = h_plan()
    track = scenario.track
    restarted = []

    def restart(demo):
        restarted.append(demo.clock.now())  # the clock's time: the log's counts from the first order
        demo.broker.restart(down_for=0.3)

    goal = ("C", "b:2")
    outcome = _drive(at=[(6.0, restart), (12.0, lambda demo: demo.master.request_goal(goal))])
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    assert outcome.run.replans == 1
    assert math.isfinite(outcome.closest)
    assert outcome.closest >= scenario.limits.min_separation - 1e-6
    records = list(outcome.log.records())
    assert restarted
    # the latest orders sent again once the broker is back
    again = [r for r in records if r["event"] == "order" and r["resent"]]
    assert {r["vehicle"] for r in again} == {"agv1", "agv2"}
    assert [r["goal"] for r in records if r["event"] == "replan"] == ["(C, b:2)"]
    assert _final_points(outcome, track) == [track.point("C"), track.point("b:2")]


# -- the command line ---------------------------------------------------------------------------------


def test_serve_drives_two_vehicle_processes_through_the_h_over_a_real_broker(tmp_path, capsys):
    with new_broker() as broker:
        tap = Tap(broker.url)
        try:
            status, outputs, vehicles = serve_with_vehicle_processes(
                str(H),
                ["--broker", broker.url, "--time-scale", "25"],
                vehicle=["--state-rate", "2", "--exit-at-goal", "--timeout", "600"],
                serve=logged_serve(tmp_path),
            )
        finally:
            tap.close()
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["outcome"] == "goals-reached"
    assert summary["method"] == "exact"
    assert all(p.returncode == 0 for p in vehicles), outputs
    assert all("at its goal" in out for out, _ in outputs), outputs
    assert "0.000 m past node D" in outputs[0][0], outputs
    assert "x=0.000 m, y=6.000 m, 0.000 m past node A" in outputs[1][0], outputs  # A has coordinates
    for kind in ("order", "state", "connection"):
        documents = tap.of(kind)
        assert documents, kind
        for document in documents:
            assert schema_errors(document, kind) == [], (kind, document.get("headerId"))
    first = next(s for s in tap.of("state") if s["serialNumber"] == "agv1")
    assert first["lastNodeId"] == "A"  # before its first order: the node it stands at
    records = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert records[-1]["outcome"] == "goals-reached"
    assert (tmp_path / "run.png").read_bytes()[:4] == b"\x89PNG"


def test_a_goal_off_the_graph_is_refused_before_serve_connects(capsys):
    status = main(["serve", str(H), "--broker", "mqtt://127.0.0.1:1", "--goal-at", "5=C,zz:1"])
    assert status == 2
    assert (
        "edge 'zz' is not on the track: expected one of ['a', 'b', 'm', 'c', 'e']" in capsys.readouterr().err
    )


def test_demo_live_runs_the_built_in_h(tmp_path, capsys):
    fast = ["--time-scale", "25", "--state-rate", "1"]
    status = main(
        ["demo", "--scenario", "h", "--live", "--method", "exact", *fast, "--output", str(tmp_path)]
    )
    out = capsys.readouterr().out
    assert status == 0, out
    assert "goals-reached" in out
    assert (tmp_path / "live-run.png").read_bytes()[:4] == b"\x89PNG"


def test_a_vehicle_started_off_the_graph_is_refused_before_it_connects(capsys):
    status = main(["vehicle", str(H), "agv1", "--broker", "mqtt://127.0.0.1:1", "--start", "zz:1"])
    assert status == 2
    assert (
        "edge 'zz' is not on the track: expected one of ['a', 'b', 'm', 'c', 'e']" in capsys.readouterr().err
    )


def test_a_start_within_a_micrometre_of_a_node_is_that_node_as_the_master_reads_it_back():
    """A vehicle reports the node id its place reads back as.

    ``--start west:0.0000004`` was reported as ``west:0``, which the master reads back as node W and
    starts its order there: the vehicle refused every order as not reachable.
    """
    track = load_scenario(EXAMPLES / "passing-loop.toml").track
    for text in ("west:0.0000004", "west:0", "W", "west:2.5"):
        _, node = start_place(track, text)
        assert point_id(track, track.point(node)) == node, text
    assert start_place(track, "west:0.0000004")[1] == "W"


def test_a_bad_goal_at_on_a_graph_says_the_graphs_form(capsys):
    assert main(["serve", str(H), "--broker", "mqtt://127.0.0.1:1", "--goal-at", "C,b:2"]) == 2
    assert (
        "expected T=EDGE:S,EDGE:S (T seconds of the run >= 0, then both vehicles' new goals, e.g. 20=C,b:2)"
        in (capsys.readouterr().err)
    )


def test_a_live_goal_too_close_is_refused_naming_the_separation_the_plan_keeps():
    scenario, verified = h_plan()

    ids = (VehicleIdentity("unspecified", "agv1"), VehicleIdentity("unspecified", "agv2"))
    master = LiveMaster(
        scenario, plan=verified, identities=ids, broker=BrokerSettings.from_url("mqtt://127.0.0.1:1")
    )
    with pytest.raises(
        InputError,
        match=r"goal \(C, c:5\) leaves the vehicles 1\.000 m apart: expected at least 1\.600 m "
        r"\(the separation the plan keeps\)",
    ):
        master.request_goal(("C", "c:5"))
