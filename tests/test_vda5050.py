"""VDA 5050 orders: valid and accepted messages, paths on the route, safe releases, factsheet limits, CLI.

On Y tracks, and through the command on junctions of 4 to 8 legs (nodes placed by the leg angles);
then on track graphs (order paths, claims and releases).

The messages are checked against references of the ``vda5050-sdk`` package
(:mod:`tests.support.vda5050_reference`): the official schemas, the sdk's pydantic models, and its
order acceptance (VDA 5050 figure 8).
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import itertools
import json
import math
import re
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError
from vda5050.domain.order import AcceptanceDecision

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.fleets import FLEETS, SEPARATION, fleet
from tests.support.graph_cases import TINY_BACK_OFF, random_routes, verified_example
from tests.support.graph_rows import ScenarioFile
from tests.support.star_scenarios import CROSSING, STAR_SCENARIOS, toml_text
from tests.support.vda5050_reference import SimulatedVehicle, parse_order, schema_errors
from topology import JUNCTION_INDEX, Homotopy, TrackGraph, plan_graph
from trajgen import Exact, Optimal, Toppra, certify, make_schedule, parse_scenario, run
from trajgen.cli import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK, main
from trajgen.errors import InputError, OptionError, OutputError, UnverifiedScheduleError
from trajgen.export.vda5050 import (
    MANIFEST_NAME,
    NodeKind,
    Vda5050Options,
    node_id,
    order_paths,
    order_releases,
    render_manifest,
    render_orders,
    write_orders,
)
from trajgen.export.vda5050.files import order_files
from trajgen.export.vda5050.graph_path import GraphOrderPath, point_id
from trajgen.export.vda5050.release import BaseRelease
from trajgen.model.junction_route import junction_graph_route
from trajgen.scenario import PLAUSIBLE, load_scenario
from trajgen.scenario.factsheet import MAX_FACTSHEET_BYTES, read_factsheet

SWAP = REPO / "examples" / "swap.toml"
START = datetime(2025, 5, 1, 8, 0, tzinfo=UTC)
OPTIONS = Vda5050Options(start_time=START, map_id="hall-1", manufacturers=("Acme", "Acme"))


def scenario_data(legs, first, second, *, separation=1.5, angles=None) -> dict:
    """A scenario as parsed TOML: ``first``/``second`` are (start, goal, v, a, j)."""
    track = {"legs": dict(zip("ABC", legs, strict=True))}
    if angles is not None:
        track["angles_deg"] = dict(zip("ABC", angles, strict=True))
    vehicles = [
        {"name": name, "start": start, "goal": goal, "max_velocity": v, "max_acceleration": a, "max_jerk": j}
        for name, (start, goal, v, a, j) in zip(("agv1", "agv2"), (first, second), strict=True)
    ]
    return {"track": track, "safety": {"min_separation": separation}, "vehicle": vehicles}


UNEQUAL = scenario_data((12.0, 8.0, 15.0), ("A:12", "B:8", 1.0, 0.5, 1.0), ("B:8", "A:12", 0.7, 0.35, 0.6))
PARKED = scenario_data((10.0, 10.0, 10.0), ("A:10", "B:10", 1.0, 0.5, 1.0), ("C:10", "C:10", 1.0, 0.5, 1.0))
#: case -> (scenario data or None for the demo swap, method)
CASES = {
    "swap-optimal": (None, Optimal()),
    "swap-exact": (None, Exact()),
    "swap-toppra": (None, Toppra()),
    "unequal-other-class": (UNEQUAL, Optimal()),
    "unequal-paper-class": (UNEQUAL, Optimal(homotopy="planned")),
    "angled-shared-leg": (
        scenario_data(
            (9.0, 6.0, 11.0),
            ("A:3", "C:7", 1.2, 0.6, 1.5),
            ("A:8", "B:5", 0.8, 0.4, 0.8),
            separation=2.0,
            angles=(0.0, 100.0, 250.0),
        ),
        Optimal(),
    ),
    "one-vehicle-parked": (PARKED, Exact()),
    # (a vehicle parked inside a leg is moved by the planner's retraction: there its order drives it)
    "one-vehicle-parked-optimal": (PARKED, Optimal()),
    "start-is-goal": (
        scenario_data((10.0, 10.0, 10.0), ("A:10", "A:10", 1.0, 0.5, 1.0), ("B:10", "B:10", 1.0, 0.5, 1.0)),
        Optimal(),
    ),
    # inside the legs the planner's route retracts to the boundary and back: its orders drive it
    "start-is-goal-inside": (
        scenario_data((10.0, 10.0, 10.0), ("A:4", "A:4", 1.0, 0.5, 1.0), ("B:6", "B:6", 1.0, 0.5, 1.0)),
        Exact(),
    ),
}


@functools.cache
def case(name: str):
    """(scenario, verified schedule, plan, messages as dicts, manifest) of a case, computed once."""
    data, method = CASES[name]
    scenario = load_scenario(SWAP) if data is None else parse_scenario(data, source=name)
    verified = run(scenario, method=method).verified
    plan = order_releases(verified)
    messages = render_orders(verified, scenario.names, options=OPTIONS, releases=plan)
    manifest = json.loads(render_manifest(verified, scenario.names, messages, options=OPTIONS, releases=plan))
    return scenario, verified, plan, messages, manifest


def documents(name: str) -> list[dict]:
    return [json.loads(message.data) for message in case(name)[3]]


def by_vehicle(name: str) -> dict[str, list[dict]]:
    out: dict[str, list[dict]] = {}
    for document in documents(name):
        out.setdefault(document["serialNumber"], []).append(document)
    return out


# ---- geometry read back from the messages, independently of the exporter --------------------------------


def track_position(graph, x: float, y: float) -> tuple[int, float]:
    """(leg, s) of a point of the drawn track, from the leg angles."""
    s = math.hypot(x, y)
    if s < 1e-9:
        return JUNCTION_INDEX, 0.0
    angle = math.degrees(math.atan2(y, x)) % 360.0
    leg = min(range(3), key=lambda k: abs((graph.angles_deg[k] % 360.0 - angle + 180.0) % 360.0 - 180.0))
    return leg, s


def gap(a: tuple[int, float, float], b: tuple[int, float, float]) -> float:
    """Track distance between stretches (leg, low, high); JUNCTION_INDEX is the point O."""
    if a[0] == b[0] and a[0] != JUNCTION_INDEX:
        return max(0.0, b[1] - a[2], a[1] - b[2])
    return a[1] + b[1]


def stretch(p: tuple[int, float], q: tuple[int, float]) -> tuple[int, float, float]:
    leg = p[0] if p[0] != JUNCTION_INDEX else q[0]
    if p[0] != JUNCTION_INDEX and q[0] != JUNCTION_INDEX:
        assert p[0] == q[0], "an edge passes the junction without a node O"
    return (leg, min(p[1], q[1]), max(p[1], q[1]))


def vehicle_paths(name: str):
    """Per vehicle: node positions (leg, s) by sequence id, and its messages' (first, decision point) seqs."""
    scenario = case(name)[0]
    graph = scenario.track
    paths = []
    for vehicle in scenario.names:
        messages = by_vehicle(name)[vehicle]
        positions = {}
        for document in messages:
            for node in document["nodes"]:
                place = track_position(graph, node["nodePosition"]["x"], node["nodePosition"]["y"])
                positions.setdefault(node["sequenceId"], place)
                assert positions[node["sequenceId"]] == pytest.approx(place)
        nodes = [positions[seq] for seq in sorted(positions)]
        paths.append(nodes)
    return paths


# ---- the messages ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_every_message_validates_against_the_order_schema(name):
    for document in documents(name):
        assert schema_errors(document) == []
        assert document["version"] == "2.1.0"
        stamp = document["timestamp"]
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z", stamp), stamp
        assert datetime.fromisoformat(stamp) >= START


def test_the_schema_check_is_not_vacuous():
    document = documents("swap-optimal")[0]
    broken = {**document, "nodes": [{**document["nodes"][0], "sequenceId": -1}]}
    assert schema_errors(broken) == ["nodes/0/sequenceId: -1 is less than the minimum of 0"]
    assert schema_errors({k: v for k, v in document.items() if k != "edges"}) == [
        ": 'edges' is a required property"
    ]


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_every_message_parses_as_the_sdks_order_unchanged(name):
    for document in documents(name):
        order = parse_order(document)  # refuses a field it lacks, a wrong type, or a changed value
        assert (order.order_id, order.order_update_id) == (document["orderId"], document["orderUpdateId"])


def edge_field(document: dict, key: str, value) -> dict:
    """``document`` with its first edge's ``key`` set to ``value`` (removed for ``None``)."""
    broken = copy.deepcopy(document)
    broken["edges"][0].pop(key, None)
    if value is not None:
        broken["edges"][0][key] = value
    return broken


#: mutation -> (message of swap-optimal's agv1 order, the error and its message)
BROKEN_FOR_THE_MODEL = {
    "no-released": (lambda d: edge_field(d, "released", None), ValidationError, r"edges\.0\.released"),
    "unknown-orientation-type": (
        lambda d: edge_field(d, "orientationType", "SIDEWAYS"),
        ValidationError,
        r"edges\.0\.orientationType",
    ),
    "misspelt-field": (
        lambda d: edge_field(d, "maxspeed", 1.0),
        ValueError,
        r"does not define: \['edges\[0\]\.maxspeed'\]",
    ),
    "coerced-value": (lambda d: {**d, "orderUpdateId": "0"}, ValueError, "back unchanged"),
}


@pytest.mark.parametrize(
    ("mutate", "error", "match"), BROKEN_FOR_THE_MODEL.values(), ids=list(BROKEN_FOR_THE_MODEL)
)
def test_the_sdk_model_check_is_not_vacuous(mutate, error, match):
    document = documents("swap-optimal")[0]
    parse_order(document)
    with pytest.raises(error, match=match):
        parse_order(mutate(document))


def start_xy(scenario, vehicle: int) -> tuple[float, float]:
    """Where vehicle ``vehicle`` (0 or 1) stands before its first order (m), from the leg angles."""
    position = scenario.start[vehicle]
    if position.leg is None:
        return 0.0, 0.0
    angle = math.radians(scenario.track.angles_deg[scenario.track.index(position.leg)])
    return position.s * math.cos(angle), position.s * math.sin(angle)


def start_point(name: str, vehicle: str) -> tuple[float, float]:
    """Where ``vehicle`` of case ``name`` stands before its first order (m), from the scenario."""
    scenario = case(name)[0]
    return start_xy(scenario, scenario.names.index(vehicle))


def decisions(name: str, vehicle: str, messages: list[dict]) -> list[AcceptanceDecision]:
    """The sdk's acceptance decisions of ``messages`` sent in turn to ``vehicle`` standing at its start."""
    receiver = SimulatedVehicle(messages[0], *start_point(name, vehicle), map_id=OPTIONS.map_id)
    return [receiver.receive(message).decision for message in messages]


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_each_vehicle_accepts_its_order_as_new_and_each_update_as_stitched(name):
    for vehicle, messages in by_vehicle(name).items():
        expected = [AcceptanceDecision.ACCEPT_NEW] + [AcceptanceDecision.ACCEPT_UPDATE] * (len(messages) - 1)
        assert decisions(name, vehicle, messages) == expected, vehicle


def without_stitching_node(update: dict) -> dict:
    """The update starting at the node after its stitching node."""
    return {**update, "nodes": update["nodes"][1:], "edges": update["edges"][1:]}


def stitched_one_node_early(previous: dict, update: dict) -> dict:
    """The update starting at the base node before the previous message's last one."""
    last_base = max(k for k, node in enumerate(previous["nodes"]) if node["released"])
    nodes = [previous["nodes"][last_base - 1], *update["nodes"]]
    return {**update, "nodes": nodes, "edges": [previous["edges"][last_base - 1], *update["edges"]]}


def moved_first_node(order: dict, metres: float) -> dict:
    """The order with its first node moved ``metres`` along x (its edge left as it is)."""
    broken = copy.deepcopy(order)
    broken["nodes"][0]["nodePosition"]["x"] += metres
    return broken


def on_map(order: dict, map_id: str) -> dict:
    """The order with every node placed on map ``map_id``."""
    broken = copy.deepcopy(order)
    for node in broken["nodes"]:
        node["nodePosition"]["mapId"] = map_id
    return broken


#: mutation -> (case, vehicle, messages sent in turn (from the vehicle's messages), decision on the last)
BROKEN_FOR_THE_VEHICLE = {
    "update-without-its-stitching-node": (
        "swap-optimal",
        "agv1",
        lambda m: [m[0], without_stitching_node(m[1])],
        AcceptanceDecision.REJECT_NOT_CONTINUATION,
    ),
    "update-stitched-one-node-early": (
        "swap-optimal",
        "agv1",
        lambda m: [m[0], stitched_one_node_early(m[0], m[1])],
        AcceptanceDecision.REJECT_NOT_CONTINUATION,
    ),
    "update-repeating-the-order-update-id": (
        "swap-optimal",
        "agv2",
        lambda m: [m[0], {**m[1], "orderUpdateId": m[0]["orderUpdateId"]}],
        AcceptanceDecision.IGNORE_DUPLICATE,
    ),
    "older-update-after-a-newer": (
        "angled-shared-leg",
        "agv2",
        lambda m: [m[0], m[1], m[2], m[1]],
        AcceptanceDecision.REJECT_DEPRECATED,
    ),
    "update-under-a-new-order-id": (
        "swap-exact",
        "agv1",
        lambda m: [m[0], {**m[1], "orderId": "another-order"}],
        AcceptanceDecision.REJECT_BUSY,
    ),
    "first-node-away-from-the-vehicle": (
        "swap-exact",
        "agv1",
        lambda m: [moved_first_node(m[0], 0.01)],
        AcceptanceDecision.REJECT_NOT_REACHABLE,
    ),
    "order-on-another-map": (
        "swap-exact",
        "agv2",
        lambda m: [on_map(m[0], "hall-2")],
        AcceptanceDecision.REJECT_MAP_UNAVAILABLE,
    ),
}


@pytest.mark.parametrize(
    ("name", "vehicle", "broken", "decision"),
    BROKEN_FOR_THE_VEHICLE.values(),
    ids=list(BROKEN_FOR_THE_VEHICLE),
)
def test_the_acceptance_refuses_a_broken_message(name, vehicle, broken, decision):
    sent = broken(by_vehicle(name)[vehicle])
    accepted = [AcceptanceDecision.ACCEPT_NEW] + [AcceptanceDecision.ACCEPT_UPDATE] * (len(sent) - 1)
    # the messages before the broken one are the exporter's own, accepted; the broken one is not
    assert decisions(name, vehicle, sent) == [*accepted[:-1], decision]


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_sequence_ids_and_the_base_horizon_split(name):
    for messages in by_vehicle(name).values():
        for document in messages:
            nodes, edges = document["nodes"], document["edges"]
            assert len(edges) == len(nodes) - 1
            first = nodes[0]["sequenceId"]
            assert [n["sequenceId"] for n in nodes] == list(range(first, first + 2 * len(nodes), 2))
            assert [e["sequenceId"] for e in edges] == [n["sequenceId"] + 1 for n in nodes[:-1]]
            for edge, start, end in zip(edges, nodes, nodes[1:], strict=False):
                assert (edge["startNodeId"], edge["endNodeId"]) == (start["nodeId"], end["nodeId"])
                assert edge["edgeId"] == f"{start['nodeId']}->{end['nodeId']}"
                # an edge is released exactly when both its nodes are
                assert edge["released"] == (start["released"] and end["released"])
            released = [n["released"] for n in nodes]
            assert released[0] is True
            assert released == sorted(released, reverse=True)  # the base, then the horizon


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_updates_continue_from_the_last_base_node(name):
    scenario = case(name)[0]
    for vehicle, messages in by_vehicle(name).items():
        assert [m["orderUpdateId"] for m in messages] == list(range(len(messages)))
        assert [m["headerId"] for m in messages] == list(range(len(messages)))
        assert {m["orderId"] for m in messages} == {f"trajgen-{vehicle}"}
        assert {m["manufacturer"] for m in messages} == {"Acme"}
        assert [m["timestamp"] for m in messages] == sorted(m["timestamp"] for m in messages)
        assert messages[0]["nodes"][0]["sequenceId"] == 0
        for previous, update in itertools.pairwise(messages):
            last_base = [n for n in previous["nodes"] if n["released"]][-1]
            assert update["nodes"][0] == last_base  # the stitching node, unchanged
            horizon = previous["nodes"][previous["nodes"].index(last_base) :]
            assert [n["nodeId"] for n in update["nodes"]] == [n["nodeId"] for n in horizon]
            assert len([n for n in update["nodes"] if n["released"]]) > 1  # it releases something
        assert all(n["released"] for n in messages[-1]["nodes"])  # the last message releases the rest
    assert set(by_vehicle(name)) == set(scenario.names)


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_start_and_goal_nodes_are_the_scenarios(name):
    scenario = case(name)[0]
    for vehicle, nodes in enumerate(vehicle_paths(name)):
        graph = scenario.track
        for position, node in ((scenario.start[vehicle], nodes[0]), (scenario.goal[vehicle], nodes[-1])):
            leg = JUNCTION_INDEX if position.leg is None else graph.index(position.leg)
            assert node == pytest.approx((leg, position.s), abs=1e-9)


def collapsed_route(route, vehicle: int) -> list[tuple[int, float]]:
    """The vehicle's own waypoints of the route, consecutive equal ones collapsed."""
    out = []
    for waypoint in route.indexed_waypoints:
        place = (waypoint[2 * vehicle], waypoint[2 * vehicle + 1])
        place = (JUNCTION_INDEX, 0.0) if place[1] == 0.0 else place
        if not out or out[-1] != place:
            out.append(place)
    # a waypoint the vehicle passes without stopping or turning is no node
    return [p for k, p in enumerate(out) if k in (0, len(out) - 1) or p[0] == JUNCTION_INDEX or turns(out, k)]


def legs_visited(places) -> list[int]:
    """The legs a path drives on, in order, each stay once."""
    legs = [leg for leg, _ in places if leg != JUNCTION_INDEX]
    return [leg for k, leg in enumerate(legs) if k == 0 or legs[k - 1] != leg]


def turns(places, k) -> bool:
    """Whether the vehicle reverses at ``places[k]`` (each segment stays on one leg)."""
    (_, sa), (_, sb), (_, sc) = places[k - 1], places[k], places[k + 1]
    return (sb - sa) * (sc - sb) < 0


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_node_positions_follow_the_schedules_route(name):
    _, verified, plan, _, _ = case(name)
    schedule = verified.schedule
    radius = schedule.limits.min_separation
    for vehicle, nodes in enumerate(vehicle_paths(name)):
        path = plan.paths[vehicle]
        # the nodes read back from the messages are the plan's, where the schedule is at the node's time
        assert [leg for leg, _ in nodes] == [n.leg for n in path.nodes]
        assert [s for _, s in nodes] == pytest.approx([n.s for n in path.nodes], abs=1e-9)
        for node in path.nodes:
            state = schedule.state([node.arrival, node.departure])
            for k in range(2):
                on_leg = int(state.leg[vehicle, k]) in (node.leg, JUNCTION_INDEX) or node.s == 0.0
                assert on_leg
                assert float(state.s[vehicle, k]) == pytest.approx(node.s, abs=2e-6)
        route_places = collapsed_route(schedule.route, vehicle)
        kept = [
            (n.leg, n.s) for n in path.nodes if n.kinds != (NodeKind.HOLD,) and n.kinds != (NodeKind.STOP,)
        ]
        if isinstance(schedule.method, Exact):  # exact follows the waypoints
            assert [p[0] for p in kept] == [p[0] for p in route_places]
            for ours, theirs in zip(kept, route_places, strict=True):
                assert ours == pytest.approx(theirs, abs=1e-9)
        else:  # the same legs in the same order; optimal may reverse shallower, or not at all
            assert legs_visited(kept) == legs_visited(route_places)
        for node in path.nodes:
            if NodeKind.HOLD in node.kinds:
                assert node.s == radius


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_max_speed_covers_the_schedule_and_keeps_the_limit(name):
    _, verified, plan, _, _ = case(name)
    schedule = verified.schedule
    for vehicle, path in enumerate(plan.paths):
        limit = schedule.limits.vehicles[vehicle].max_velocity
        messages = by_vehicle(name)[case(name)[0].names[vehicle]]
        speeds = {e["sequenceId"]: e["maxSpeed"] for m in messages for e in m["edges"]}
        lengths = {e["sequenceId"]: e["length"] for m in messages for e in m["edges"]}
        assert sorted(speeds) == [2 * k + 1 for k in range(len(path.edges))]
        for k, (a, b) in enumerate(zip(path.nodes, path.nodes[1:], strict=False)):
            times = np.linspace(a.departure, b.arrival, 4001)
            sampled = float(np.max(np.abs(schedule.state(times).velocity[vehicle])))
            # the verifier lets a schedule exceed a limit by 1e-6 of it; maxSpeed never does
            assert sampled <= speeds[2 * k + 1] + 1e-6 * limit
            assert speeds[2 * k + 1] <= limit
            assert speeds[2 * k + 1] <= sampled + 2e-3  # the edge's own peak, not just the limit
            travelled = abs(
                schedule.state(b.arrival).axis[vehicle, 0] - schedule.state(a.departure).axis[vehicle, 0]
            )
            assert lengths[2 * k + 1] == pytest.approx(travelled, abs=2e-6)


# ---- the releases ------------------------------------------------------------------------------------------


def interleavings(name: str):
    """Every state of both vehicles driving their bases in any order and timing, messages on their triggers.

    Yields (reached node index, delivered message count) per vehicle. A message is delivered once the
    vehicle its manifest entry names has reached the trigger node; a vehicle moves on to its next node
    only if that node is released.
    """
    scenario, _, _, messages, manifest = case(name)
    names = scenario.names
    entries = [[e for e in manifest["messages"] if e["vehicle"] == vehicle] for vehicle in names]
    docs = [[json.loads(m.data) for m in messages if m.vehicle == v] for v in (0, 1)]
    released = [
        [max(n["sequenceId"] for n in d["nodes"] if n["released"]) // 2 for d in docs[v]] for v in (0, 1)
    ]
    last = [len(p) - 1 for p in vehicle_paths(name)]
    start = ((0, 0), (1, 1))
    seen = {start}
    stack = [start]
    while stack:
        state = stack.pop()
        (reached, delivered) = state
        successors = []
        for v in (0, 1):
            base = released[v][delivered[v] - 1]
            if reached[v] < min(base, last[v]):
                successors.append(((*reached[:v], reached[v] + 1, *reached[v + 1 :]), delivered))
            if delivered[v] < len(entries[v]):
                trigger = entries[v][delivered[v]]["trigger"]
                other = names.index(trigger["vehicle"])
                if reached[other] * 2 >= trigger["sequence_id"]:
                    successors.append((reached, (*delivered[:v], delivered[v] + 1, *delivered[v + 1 :])))
        yield state, released, last, bool(successors)
        for successor in successors:
            if successor not in seen:
                seen.add(successor)
                stack.append(successor)


def claims(paths, released, state):
    (reached, delivered) = state
    out = []
    for v in (0, 1):
        nodes = paths[v]
        base = released[v][delivered[v] - 1]
        claim = [(nodes[reached[v]][0], nodes[reached[v]][1], nodes[reached[v]][1])]
        claim += [stretch(nodes[j], nodes[j + 1]) for j in range(reached[v], base)]
        out.append(claim)
    return out


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_released_track_stays_apart_in_every_interleaving(name):
    scenario = case(name)[0]
    separation = scenario.limits.min_separation
    paths = vehicle_paths(name)
    finished = False
    count = 0
    for state, released, last, can_move in interleavings(name):
        count += 1
        first, second = claims(paths, released, state)
        closest = min(gap(a, b) for a in first for b in second)
        assert closest >= separation - 1e-9, f"claims {closest} m apart in {state}"
        # the junction in particular: released, not yet passed, while the other is near it
        for v, claim in enumerate((first, second)):
            other = (second, first)[v]
            if any(c[1] == 0.0 for c in claim[1:]):
                assert min(c[1] for c in other) >= separation - 1e-9
        done = list(state[0]) == last and list(state[1]) == [len(r) for r in released]
        finished |= done
        assert can_move or done, f"deadlock in {state}"
    assert finished
    assert count > 1 or all(len(path) == 1 for path in paths)


def junction_passages(verified, period: float = 1e-3) -> list[int]:
    """The vehicles in the order they pass through the junction (from one leg to another) in the schedule."""
    schedule = verified.schedule
    state = schedule.state(np.arange(0.0, schedule.duration + period, period))
    events = []
    for v in (0, 1):
        on_leg = state.leg[v] != JUNCTION_INDEX
        legs, times = state.leg[v][on_leg], state.t[on_leg]
        events += [(float(times[k]), v) for k in np.nonzero(legs[1:] != legs[:-1])[0]]
    return [v for _, v in sorted(events)]


def passages(path: list[tuple[int, float]]) -> list[int]:
    """Indices of the nodes at which a path passes through the junction from one leg to another."""
    return [
        j
        for j in range(1, len(path) - 1)
        if path[j][0] == JUNCTION_INDEX and path[j - 1][0] != path[j + 1][0]
    ]


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_the_junction_is_released_in_the_order_the_schedule_passes_it(name):
    _, verified, _, _, manifest = case(name)
    order = junction_passages(verified)
    o_nodes = [passages(path) for path in vehicle_paths(name)]
    assert [len(o_nodes[v]) for v in (0, 1)] == [order.count(v) for v in (0, 1)]
    # in every interleaving, each passage of the junction comes after the other's earlier passages
    for (reached, _), _, _, _ in interleavings(name):
        passed = [sum(1 for j in o_nodes[v] if j <= reached[v]) for v in (0, 1)]
        for v in (0, 1):
            if passed[v]:
                kth = [k for k, who in enumerate(order) if who == v][passed[v] - 1]
                assert passed[1 - v] >= order[:kth].count(1 - v), (reached, order)
    # the updates that release a passage of the junction are sent in the schedule's order
    assert [e["send_at_s"] for e in manifest["messages"]] == sorted(
        e["send_at_s"] for e in manifest["messages"]
    )


def test_the_demo_swap_in_detail():
    manifest = case("swap-optimal")[4]
    agv1, agv2 = by_vehicle("swap-optimal")["agv1"], by_vehicle("swap-optimal")["agv2"]
    assert [n["nodeId"] for n in agv1[0]["nodes"]] == ["A:10", "A:1.5", "O", "B:1.5", "B:10"]
    assert [n["released"] for n in agv1[0]["nodes"]] == [True, True, False, False, False]
    assert [n["nodePosition"]["y"] for n in agv1[0]["nodes"]] == [10.0, 1.5, 0.0, -0.75, -5.0]
    assert agv1[0]["edges"][2]["direction"] == "B"
    # agv2 passes the junction first, parks just past the separation on C, and turns back
    ids = [n["nodeId"] for n in agv2[0]["nodes"]]
    assert ids[:3] == ["B:10", "B:1.5", "O"]
    assert ids[3].startswith("C:1.5")
    assert ids[4:] == ["O", "A:1.5", "A:10"]
    assert agv2[0]["edges"][3]["orientation"] == math.pi  # it backs out of C
    first_update = manifest["messages"][2]
    assert first_update["vehicle"] == "agv1"
    assert first_update["trigger"] == {"vehicle": "agv2", "node_id": ids[3], "sequence_id": 6}
    assert first_update["send_at_s"] == pytest.approx(13.756, abs=0.01)
    assert agv1[1]["timestamp"] == "2025-05-01T08:00:13.757Z"
    assert manifest["planned_duration_s"] >= manifest["schedule_duration_s"]
    assert agv1[0]["edges"][0]["maxSpeed"] < 1.0  # optimal's peak on that edge, below the limit


def test_exact_needs_no_waits_and_optimal_says_how_long_it_waits():
    exact = case("swap-exact")[4]
    assert all(e["wait_s"] == 0.0 for e in exact["messages"])
    assert exact["planned_duration_s"] == exact["schedule_duration_s"]
    _, _, plan, _, optimal = case("swap-optimal")
    ends = [
        path.nodes[-1].arrival + sum(e["wait_s"] for e in optimal["messages"] if e["vehicle"] == name)
        for path, name in zip(plan.paths, ("agv1", "agv2"), strict=True)
    ]
    assert min(e["wait_s"] for e in optimal["messages"][2:]) > 0.5
    assert optimal["planned_duration_s"] == pytest.approx(max(ends), abs=1e-5)


def test_the_other_class_is_exported_on_its_own_route():
    _, verified, plan, _, _ = case("unequal-other-class")
    assert verified.schedule.route.homotopy is Homotopy.OTHER
    paper = case("unequal-paper-class")[1]
    assert paper.schedule.route.homotopy is Homotopy.PLANNED
    other_nodes = [n.leg for n in plan.paths[1].nodes]
    paper_nodes = [n.leg for n in case("unequal-paper-class")[2].paths[1].nodes]
    assert other_nodes != paper_nodes


def test_a_parked_vehicle_gets_one_node_and_no_edges():
    assert by_vehicle("one-vehicle-parked-optimal")["agv2"] == by_vehicle("one-vehicle-parked")["agv2"]
    agv2 = by_vehicle("one-vehicle-parked")["agv2"]
    assert len(agv2) == 1
    assert [n["nodeId"] for n in agv2[0]["nodes"]] == ["C:10"]
    assert agv2[0]["edges"] == []
    start_is_goal = by_vehicle("start-is-goal")
    assert {v: [n["nodeId"] for n in d[0]["nodes"]] for v, d in start_is_goal.items()} == {
        "agv1": ["A:10"],
        "agv2": ["B:10"],
    }


def test_node_ids_are_stable_and_readable():
    graph = case("swap-optimal")[0].track
    assert node_id(graph, JUNCTION_INDEX, 0.0) == "O"
    assert node_id(graph, 0, 10.0) == "A:10"
    assert node_id(graph, 2, 1.5000009912) == "C:1.500001"
    first = render_orders(case("swap-optimal")[1], ("agv1", "agv2"), options=OPTIONS)
    assert [m.data for m in first] == [m.data for m in case("swap-optimal")[3]]  # same input, same bytes


# ---- options, files, atomic writing -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"start_time": datetime(2025, 5, 1, 8, 0)}, "time zone aware"),
        ({"start_time": "2025-05-01T08:00:00Z"}, "time zone aware"),
        ({"start_time": START, "map_id": ""}, "map_id must be a non-empty"),
        ({"start_time": START, "order_id": "a\nb"}, "order_id must be a non-empty printable"),
        ({"start_time": START, "manufacturers": "Acme"}, "manufacturers must be a sequence of strings"),
        ({"start_time": START, "serial_numbers": ("SN1", 2)}, r"serial_numbers\[1\]"),
        ({"start_time": START, "first_header_id": -1}, "first_header_id must be an integer"),
        ({"start_time": START, "first_header_id": True}, "first_header_id must be an integer"),
        ({"start_time": datetime(9999, 12, 31, tzinfo=UTC)}, "start_time .* is out of range"),
        (
            {"start_time": datetime(1, 1, 1, tzinfo=timezone(timedelta(hours=14)))},
            "start_time .* is out of range: expected a time from the years 1970 to 9000",
        ),
        ({"start_time": START, "serial_numbers": ("SN1", "SN1")}, "vehicles 1 and 2 are both 'SN1'"),
        ({"start_time": START, "serial_numbers": ("a/b", "SN2")}, "serial number 'a/b' is not allowed"),
        ({"start_time": START, "manufacturers": ("x/y", "Acme")}, r"manufacturer 'x/y' has '/', '#' or '\+'"),
    ],
    ids=[
        "naive",
        "text",
        "empty-map",
        "newline",
        "one-manufacturer",
        "serial-type",
        "negative",
        "bool",
        "year-9999",
        "year-1",
        "same-serial",
        "serial-slash",
        "manufacturer-slash",
    ],
)
def test_bad_options_are_refused(options, match):
    with pytest.raises(OptionError, match=match):
        Vda5050Options(**options)


def test_a_vehicle_named_like_the_manifest_is_refused_before_anything_is_computed(tmp_path):
    with pytest.raises(OptionError, match=r"vehicle name 'Manifest.json' is the manifest's file name"):
        order_paths(("Manifest.json", "agv2"), tmp_path)


def test_options_shape_the_header():
    options = Vda5050Options(
        start_time=datetime(2025, 5, 1, 10, 0, tzinfo=timezone(timedelta(hours=2))),
        order_id="job7",
        serial_numbers=("SN-1", "SN-2"),
        first_header_id=41,
    )
    _, verified, plan, _, _ = case("swap-exact")
    messages = render_orders(verified, ("agv1", "agv2"), options=options, releases=plan)
    first = json.loads(messages[0].data)
    assert first["timestamp"] == "2025-05-01T08:00:00.000Z"  # in UTC
    assert (first["serialNumber"], first["orderId"], first["headerId"]) == ("SN-1", "job7-agv1", 41)
    assert str(messages[-1].path) == "agv2/order-001.json"


def test_renderers_take_only_verified_schedules():
    schedule = case("swap-exact")[1].schedule
    with pytest.raises(UnverifiedScheduleError):
        order_releases(schedule)
    with pytest.raises(UnverifiedScheduleError):
        render_orders(schedule, ("agv1", "agv2"), options=OPTIONS)


def test_write_orders_writes_every_file_and_the_manifest(tmp_path):
    _, verified, _, messages, manifest = case("swap-optimal")
    paths = write_orders(verified, ("agv1", "agv2"), tmp_path / "out", options=OPTIONS)
    names = sorted(str(p.relative_to(tmp_path / "out")) for p in paths)
    assert names == sorted([MANIFEST_NAME, *(str(m.path) for m in messages)])
    written = json.loads((tmp_path / "out" / MANIFEST_NAME).read_text(encoding="utf-8"))
    assert written == manifest
    assert [e["file"] for e in written["messages"]] == [str(m.path) for m in messages]


def test_a_failed_write_writes_nothing(tmp_path):
    verified = case("swap-optimal")[1]
    out = tmp_path / "out"
    (out / "agv2" / "order-001.json").mkdir(parents=True)  # a folder where an update goes
    (out / "agv1").mkdir()
    (out / "agv1" / "order-000.json").write_text("old", encoding="utf-8")
    with pytest.raises(OutputError, match=r"order-001\.json"):
        write_orders(verified, ("agv1", "agv2"), out, options=OPTIONS)
    assert (out / "agv1" / "order-000.json").read_text(encoding="utf-8") == "old"
    assert sorted(p.name for p in out.rglob("*")) == ["agv1", "agv2", "order-000.json", "order-001.json"]


def test_a_failure_while_committing_writes_nothing(tmp_path, monkeypatch):
    import os

    verified = case("swap-optimal")[1]
    calls = []
    real_replace = os.replace

    def failing_replace(source, target):
        if Path(target).suffix == ".json":  # an order or the manifest, not a journal
            calls.append(target)
        if len(calls) == 3:  # the third file: two are already in place
            raise OSError(28, "No space left on device")
        return real_replace(source, target)

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(OutputError, match="No space left on device"):
        write_orders(verified, ("agv1", "agv2"), tmp_path / "out", options=OPTIONS)
    monkeypatch.undo()
    assert len(calls) >= 3
    assert list(tmp_path.rglob("*")) == []  # no file, no hidden leftover, no folder


# ---- factsheets ------------------------------------------------------------------------------------------


def factsheet(speed=1.2, acceleration=0.8, deceleration=0.6) -> dict:
    """A complete VDA 5050 2.1.0 factsheet (valid against factsheet.schema)."""
    return {
        "headerId": 1,
        "timestamp": "2025-05-01T08:00:00.00Z",
        "version": "2.1.0",
        "manufacturer": "Acme",
        "serialNumber": "SN-1",
        "typeSpecification": {
            "seriesName": "Y-100",
            "agvKinematic": "DIFF",
            "agvClass": "CARRIER",
            "maxLoadMass": 500,
            "localizationTypes": ["NATURAL"],
            "navigationTypes": ["VIRTUAL_LINE_GUIDED"],
        },
        "physicalParameters": {
            "speedMin": 0.01,
            "speedMax": speed,
            "accelerationMax": acceleration,
            "decelerationMax": deceleration,
            "heightMax": 0.4,
            "width": 0.8,
            "length": 1.2,
        },
        "protocolLimits": {
            "maxStringLens": {},
            "maxArrayLens": {},
            "timing": {"minOrderInterval": 0.5, "minStateInterval": 0.5},
        },
        "protocolFeatures": {"optionalParameters": [], "agvActions": []},
        "agvGeometry": {},
        "loadSpecification": {},
    }


def write_factsheet_scenario(folder: Path, sheet: str | None = "agv.json", extra: str = "") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    text = SWAP.read_text(encoding="utf-8")
    first = text.index("max_velocity")
    end = text.index("max_jerk", first)
    line = f'factsheet = "{sheet}"\n{extra}' if sheet is not None else extra
    path = folder / "scenario.toml"
    path.write_text(text[:first] + line + text[end:], encoding="utf-8")
    return path


def test_the_test_factsheet_is_valid_against_the_factsheet_schema():
    assert schema_errors(factsheet(), "factsheet") == []
    broken = factsheet()
    del broken["physicalParameters"]["speedMax"]
    assert schema_errors(broken, "factsheet") == ["physicalParameters: 'speedMax' is a required property"]


def test_limits_are_read_from_a_factsheet(tmp_path):
    (tmp_path / "sheets").mkdir()
    (tmp_path / "sheets" / "agv.json").write_text(json.dumps(factsheet(1.2, 0.8, 0.6)), encoding="utf-8")
    scenario = load_scenario(write_factsheet_scenario(tmp_path, "sheets/agv.json"))
    first, second = scenario.limits.vehicles
    assert (first.max_velocity, first.max_acceleration, first.max_jerk) == (1.2, 0.6, 1.0)  # min(acc, dec)
    assert (second.max_velocity, second.max_acceleration) == (1.0, 0.5)  # the scenario's own
    sheet = read_factsheet(
        tmp_path / "sheets" / "agv.json",
        velocity_range=PLAUSIBLE["max_velocity"],
        acceleration_range=PLAUSIBLE["max_acceleration"],
    )
    assert (sheet.speed_max, sheet.acceleration_max, sheet.deceleration_max) == (1.2, 0.8, 0.6)
    assert sheet.max_acceleration == 0.6


def bad_sheet(document) -> bytes:
    return document if isinstance(document, bytes) else json.dumps(document).encode("utf-8")


def without(key: str) -> dict:
    sheet = factsheet()
    del sheet["physicalParameters"][key]
    return sheet


def with_value(key: str, value) -> dict:
    sheet = factsheet()
    sheet["physicalParameters"][key] = value
    return sheet


BAD_FACTSHEETS = {
    "not-json": (b"{speedMax: 1}", r"agv\.json: not valid JSON"),
    "not-utf8": (b'{"a": "\xff"}', r"agv\.json: is not UTF-8 text: byte 0xff"),
    "array": (b"[1, 2]", r"agv\.json: the document is list \[1, 2\]: expected a JSON object"),
    "no-physical": ({"version": "2.1.0"}, r"has no 'physicalParameters'"),
    "physical-not-object": ({"physicalParameters": [1]}, r"'physicalParameters' is list \[1\]"),
    "missing-speed": (without("speedMax"), r"physicalParameters has no 'speedMax': expected a number of m/s"),
    "missing-deceleration": (without("decelerationMax"), r"has no 'decelerationMax'"),
    "text-speed": (
        with_value("speedMax", "fast"),
        r"physicalParameters\.speedMax is str 'fast': expected a number",
    ),
    "bool-acceleration": (with_value("accelerationMax", True), r"accelerationMax is bool True"),
    "zero-speed": (
        with_value("speedMax", 0),
        r"physicalParameters\.speedMax is 0: expected 0\.0001 to 100 m/s",
    ),
    "huge-deceleration": (with_value("decelerationMax", 1e6), r"decelerationMax is 1000000\.0: expected"),
    "overflowing-int": (with_value("speedMax", 10**400), r"speedMax is 1000.*: expected 0\.0001 to 100"),
    "infinite": (b'{"physicalParameters": {"speedMax": 1e999}}', r"speedMax is inf: expected"),
    "nan": (b'{"physicalParameters": {"speedMax": NaN}}', r"not valid JSON: NaN is not a JSON number"),
    "duplicate": (
        b'{"physicalParameters": {}, "physicalParameters": {}}',
        r"key 'physicalParameters' is given",
    ),
    "nested": (b"[" * 100_000 + b"]" * 100_000, r"nested too deeply|not valid JSON"),
}


@pytest.mark.parametrize(("content", "match"), BAD_FACTSHEETS.values(), ids=list(BAD_FACTSHEETS))
def test_bad_factsheets_are_input_errors_naming_file_key_and_value(tmp_path, content, match):
    (tmp_path / "agv.json").write_bytes(bad_sheet(content))
    with pytest.raises(InputError, match=match) as error:
        load_scenario(write_factsheet_scenario(tmp_path))
    assert "[[vehicle]] 1" in str(error.value)
    assert "agv.json" in str(error.value)


@pytest.mark.parametrize(
    ("setup", "match"),
    [
        ("missing", r"factsheet .*agv\.json: cannot read the factsheet: No such file"),
        ("folder", r"agv\.json: is not a regular file"),
        ("large", rf"agv\.json: is {MAX_FACTSHEET_BYTES + 1:,} bytes: expected a factsheet of at most"),
    ],
    ids=["missing", "folder", "too-large"],
)
def test_unreadable_factsheets_are_refused_unread(tmp_path, setup, match):
    if setup == "folder":
        (tmp_path / "agv.json").mkdir()
    elif setup == "large":
        (tmp_path / "agv.json").write_bytes(b" " * (MAX_FACTSHEET_BYTES + 1))
    with pytest.raises(InputError, match=match):
        load_scenario(write_factsheet_scenario(tmp_path))


@pytest.mark.parametrize(
    ("sheet", "extra", "match"),
    [
        ("agv.json", "max_velocity = 1.0\n", r"gives both 'factsheet' and \['max_velocity'\]"),
        (None, "", r"missing required key\(s\) \['max_velocity', 'max_acceleration'\] \(or a VDA 5050"),
        (None, "max_velocity = 1.0\n", r"missing required key\(s\) \['max_acceleration'\]"),
    ],
    ids=["both", "neither", "no-acceleration"],
)
def test_a_vehicle_takes_its_limits_from_one_place(tmp_path, sheet, extra, match):
    (tmp_path / "agv.json").write_text(json.dumps(factsheet()), encoding="utf-8")
    with pytest.raises(InputError, match=match):
        load_scenario(write_factsheet_scenario(tmp_path, sheet, extra))


def test_a_factsheet_does_not_replace_the_jerk(tmp_path):
    (tmp_path / "agv.json").write_text(json.dumps(factsheet()), encoding="utf-8")
    path = write_factsheet_scenario(tmp_path)
    text = path.read_text(encoding="utf-8").replace("max_jerk = 1.0\n", "", 1)
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=r"\[\[vehicle\]\] 1 is missing required key\(s\) \['max_jerk'\]"):
        load_scenario(path)


# ---- the command line --------------------------------------------------------------------------------------


def test_the_command_writes_the_orders(tmp_path, capsys):
    out = tmp_path / "orders"
    argv = ["export-vda5050", str(SWAP), "--out", str(out), "--start-time", "2025-05-01T08:00:00Z", "--json"]
    argv += ["--manufacturer", "Acme", "--serial-number", "agv2=SN-2", "--map-id", "hall-1"]
    argv += ["--method", "exact", "--first-header-id", "7", "--order-id", "job"]
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["computed_by"] == "exact"
    assert len(summary["files"]) == 5
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*.json")) == [
        "agv1/order-000.json",
        "agv1/order-001.json",
        "agv2/order-000.json",
        "agv2/order-001.json",
        "manifest.json",
    ]
    update = json.loads((out / "agv2" / "order-001.json").read_text(encoding="utf-8"))
    assert (update["serialNumber"], update["manufacturer"]) == ("SN-2", "Acme")
    assert (update["headerId"], update["orderId"], update["orderUpdateId"]) == (8, "job-agv2", 1)
    assert summary["start_time"] == "2025-05-01T08:00:00.000Z"
    assert update["nodes"][0]["nodePosition"]["mapId"] == "hall-1"
    assert summary["messages"][3]["trigger"]["vehicle"] == "agv1"
    assert main(["export-vda5050", str(SWAP), "--out", str(out), "--method", "exact"]) == EXIT_OK
    assert "at the start, base to A:1.5" in capsys.readouterr().out


def test_the_command_with_a_factsheet(tmp_path, capsys):
    (tmp_path / "agv.json").write_text(json.dumps(factsheet(0.8, 0.4, 0.5)), encoding="utf-8")
    scenario = write_factsheet_scenario(tmp_path)
    argv = [
        "export-vda5050",
        str(scenario),
        "--out",
        str(tmp_path / "o"),
        "--start-time",
        "2025-05-01T08:00Z",
    ]
    assert main([*argv, "--method", "exact", "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    speeds = [
        e["maxSpeed"]
        for path in (tmp_path / "o" / "agv1").iterdir()
        for e in json.loads(path.read_text(encoding="utf-8"))["edges"]
    ]
    assert max(speeds) == 0.8  # the factsheet's speedMax
    assert summary["duration_s"] > 67.5  # slower than the demo's 1.0 m/s


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--start-time", "2025-05-01T08:00:00"], "has no time zone"),
        (["--start-time", "tomorrow"], "is not an ISO 8601 time"),
        (["--serial-number", "agv9=X"], "names no vehicle of the scenario"),
        (["--map-id", ""], "map_id must be a non-empty"),
        (["--homotopy", "planned", "--method", "exact"], "applies to the method 'optimal' only"),
        (["--serial-number", "SN1"], "names no vehicle: expected NAME=SERIAL"),
        (["--start-time", "9999-12-31T23:59:59Z"], "is out of range"),
    ],
    ids=[
        "naive-time",
        "bad-time",
        "unknown-vehicle",
        "empty-map",
        "homotopy-exact",
        "bare-serial",
        "far-future",
    ],
)
def test_bad_options_exit_2_and_write_nothing(tmp_path, capsys, extra, match):
    out = tmp_path / "orders"
    assert main(["export-vda5050", str(SWAP), "--out", str(out), *extra]) == EXIT_BAD_INPUT
    assert re.search(match, capsys.readouterr().err)
    assert not out.exists()


def test_a_bad_factsheet_exits_2_and_writes_nothing(tmp_path, capsys):
    (tmp_path / "agv.json").write_text(json.dumps(with_value("speedMax", -1)), encoding="utf-8")
    scenario = write_factsheet_scenario(tmp_path)
    out = tmp_path / "orders"
    assert main(["export-vda5050", str(scenario), "--out", str(out)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "agv.json: physicalParameters.speedMax is -1: expected 0.0001 to 100 m/s" in err
    assert not out.exists()


def test_an_output_path_that_is_a_file_exits_2_before_computing(tmp_path, capsys):
    (tmp_path / "orders").write_text("a file", encoding="utf-8")
    assert main(["export-vda5050", str(SWAP), "--out", str(tmp_path / "orders")]) == EXIT_BAD_INPUT
    assert "exists and is not a folder" in capsys.readouterr().err


def test_an_internal_failure_exits_1_and_writes_nothing(tmp_path, capsys, monkeypatch):
    import trajgen.export.vda5050.files

    def broken(*args, **kwargs):
        raise RuntimeError("renderer broke")

    monkeypatch.setattr(trajgen.export.vda5050.files, "order_files", broken)
    out = tmp_path / "orders"
    assert main(["export-vda5050", str(SWAP), "--out", str(out), "--method", "exact"]) == EXIT_FAILURE
    assert "internal failure: RuntimeError: renderer broke" in capsys.readouterr().err
    assert not out.exists()


# ---- the command on junctions of 4 to 8 legs ---------------------------------------------------------------

#: export-vda5050's default --map-id (docs/formats/vda5050.md): the map the vehicles have
DEFAULT_MAP_ID = "trajgen"


def assert_each_vehicle_accepts_its_orders(scenario, folder) -> None:
    """The sdk's acceptance takes each vehicle's first order as new and each update as stitched."""
    for vehicle, name in enumerate(scenario.names):
        paths = sorted((folder / name).glob("order-*.json"))
        messages = [json.loads(path.read_text(encoding="utf-8")) for path in paths]
        receiver = SimulatedVehicle(messages[0], *start_xy(scenario, vehicle), map_id=DEFAULT_MAP_ID)
        got = [receiver.receive(message).decision for message in messages]
        expected = [AcceptanceDecision.ACCEPT_NEW] + [AcceptanceDecision.ACCEPT_UPDATE] * (len(paths) - 1)
        assert got == expected, name


@pytest.mark.slow
def test_export_vda5050_on_k_legs_validates_and_places_nodes_by_angle(tmp_path, capsys):
    data = STAR_SCENARIOS[5]
    path = tmp_path / "five.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    scenario = load_scenario(path)
    out = tmp_path / "vda"
    argv = ["export-vda5050", str(path), "--out", str(out), "--method", "exact"]
    assert main([*argv, "--start-time", "2025-05-01T08:00:00Z"]) == EXIT_OK
    capsys.readouterr()
    orders = sorted(out.glob("*/order-*.json"))
    assert {p.parent.name for p in orders} == set(scenario.names)
    legs_seen = set()
    for order_path in orders:
        order = json.loads(order_path.read_text(encoding="utf-8"))
        assert schema_errors(order) == []
        parse_order(order)
        for node in order["nodes"]:
            position = node["nodePosition"]
            if node["nodeId"] == "O":
                assert (position["x"], position["y"]) == (0.0, 0.0)
                continue
            leg, s = node["nodeId"].split(":")
            legs_seen.add(leg)
            angle = math.radians(scenario.track.angles_deg[scenario.track.index(leg)])
            assert position["x"] == pytest.approx(float(s) * math.cos(angle), abs=1e-6)
            assert position["y"] == pytest.approx(float(s) * math.sin(angle), abs=1e-6)
            assert 0.0 < float(s) <= scenario.track.length(leg)
        for edge in order["edges"]:
            if "direction" in edge:
                assert edge["direction"] in scenario.track.names
    assert {"A", "D"} <= legs_seen <= set(scenario.track.names)
    assert_each_vehicle_accepts_its_orders(scenario, out)
    manifest = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    assert manifest  # written with the orders


@pytest.mark.slow
def test_export_vda5050_on_a_crossing_with_optimal(tmp_path, capsys):
    out = tmp_path / "vda"
    argv = ["export-vda5050", str(CROSSING), "--out", str(out), "--start-time", "2025-05-01T08:00:00Z"]
    assert main(argv) == EXIT_OK
    capsys.readouterr()
    orders = sorted(out.glob("*/order-*.json"))
    assert len(orders) >= 4  # each vehicle's first order and at least one update each
    for order_path in orders:
        order = json.loads(order_path.read_text(encoding="utf-8"))
        assert schema_errors(order) == []
        parse_order(order)
        assert {n["nodeId"].split(":")[0] for n in order["nodes"]} <= {"O", "N", "W", "S", "E"}
    assert_each_vehicle_accepts_its_orders(load_scenario(CROSSING), out)


def test_schedules_of_every_method_can_be_certified_and_exported():
    scenario = load_scenario(SWAP)
    for method in (Exact(jerk=False), Toppra(grid_points=60)):
        verified = certify(make_schedule(scenario.route(), scenario.limits, method=method))
        messages = render_orders(verified, scenario.names, options=OPTIONS)
        for message in messages:
            document = json.loads(message.data)
            assert schema_errors(document) == []
            parse_order(document)


def test_the_options_name_every_vehicle_or_the_export_refuses_them():
    three = Vda5050Options(start_time=START, manufacturers=("A", "B", "C"))
    assert [three.manufacturer(v) for v in range(3)] == ["A", "B", "C"]
    one = Vda5050Options(start_time=START, manufacturers=("Acme",))
    assert [one.manufacturer(v) for v in range(5)] == ["Acme"] * 5  # one manufacturer for every vehicle
    with pytest.raises(OptionError, match=r"manufacturers: 3 given: expected one, or one per vehicle \(2\)"):
        three.check_vehicles(2)
    serials = Vda5050Options(start_time=START, serial_numbers=("S1",))
    with pytest.raises(OptionError, match=r"serial_numbers: 1 given: expected one per vehicle \(2\)"):
        serials.check_vehicles(2)


def test_manufacturers_and_serial_numbers_of_unlike_counts_are_refused():
    with pytest.raises(OptionError, match=r"manufacturers: 2 given for 3 serial numbers: expected one"):
        Vda5050Options(start_time=START, manufacturers=("a", "b"), serial_numbers=("x", "y", "z"))


# -- track graphs: order paths, claims and releases ------------------------------------------------------


EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]
GRAPH_OPTIONS = Vda5050Options(start_time=datetime(2026, 1, 1, tzinfo=UTC), map_id="plant")


@functools.cache
def _case(name: str, method: str):
    scenario, verified = verified_example(name, method)
    releases = order_releases(verified)
    messages = render_orders(verified, scenario.names, options=GRAPH_OPTIONS, releases=releases)
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
        receiver = SimulatedVehicle(documents[0], *start, map_id=GRAPH_OPTIONS.map_id)
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
    """Every vehicle driven at random paces, each only within its released base; the least distance.

    ``distance((edge, s), (edge, s))``: the track distance the caller trusts, metres; the least over
    every pair.
    """
    paths = verified.schedule.paths
    count = len(paths)
    rng = np.random.default_rng(seed)
    rule = BaseRelease(releases.paths, verified.schedule.limits.min_separation)
    travel = [0.0] * count
    closest = math.inf
    for _ in range(200_000):
        if rule.reached == list(rule.last):
            return closest
        limits = [releases.paths[v].nodes[rule.released[v]].travel for v in range(count)]
        movable = [v for v in range(count) if travel[v] < limits[v] - 1e-12]
        assert movable, f"deadlock at nodes {rule.reached} (seed {seed})"
        v = int(rng.choice(movable))
        travel[v] = min(travel[v] + rng.uniform(0.2, 1.0) * step, limits[v])
        nodes = releases.paths[v].nodes
        while rule.reached[v] < rule.released[v] and nodes[rule.reached[v] + 1].travel <= travel[v] + 1e-12:
            rule.reach(v, rule.reached[v] + 1)
        where = []
        for u in range(count):
            edge, s = paths[u].locate(travel[u])
            where.append((int(edge[0]), float(s[0])))
        closest = min(closest, *(distance(a, b) for a, b in itertools.combinations(where, 2)))
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
    messages = render_orders(verified, ("one", "two"), options=GRAPH_OPTIONS)
    for message in messages:
        document = json.loads(message.data)
        assert schema_errors(document) == []
        assert all("nodePosition" not in node for node in document["nodes"])
    manifest = json.loads(render_manifest(verified, ("one", "two"), messages, options=GRAPH_OPTIONS))
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
    messages = render_orders(verified, scenario.names, options=GRAPH_OPTIONS, releases=releases)
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


# -- any number of vehicles below the planners ------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_a_fleet_gets_an_order_per_vehicle_and_its_releases_keep_every_pair_apart_whatever_the_timing(
    case, method
):
    """Three or four vehicles: each order valid and taken, and the bases released node by node."""
    verified, route = case.verified(method), case.route()
    releases = order_releases(verified)
    assert len(releases.paths) == case.count
    messages = render_orders(verified, route.names, options=GRAPH_OPTIONS, releases=releases)
    documents: dict[str, list[dict]] = {name: [] for name in route.names}
    for message in messages:
        documents[route.names[message.vehicle]].append(json.loads(message.data))
    track = route.track
    for vehicle, name in enumerate(route.names):
        assert documents[name], name
        for document in documents[name]:
            assert schema_errors(document) == []
            parse_order(document)
        receiver = SimulatedVehicle(
            documents[name][0], *track.xy(route.start[vehicle]), map_id=GRAPH_OPTIONS.map_id
        )
        decisions = [receiver.receive(document).decision for document in documents[name]]
        assert decisions == [AcceptanceDecision.ACCEPT_NEW] + [AcceptanceDecision.ACCEPT_UPDATE] * (
            len(decisions) - 1
        )

    def distance(a, b):
        return float(track.distances([a[0]], [a[1]], [b[0]], [b[1]])[0])

    for pace in range(3):
        closest = _drive_at_random_paces(verified, releases, distance, pace)
        assert closest >= SEPARATION - 1e-9, (pace, closest)


def test_the_node_plan_of_a_fleet_follows_the_schedules_order_of_arrivals():
    """The convoy: the front vehicle first, then the middle one, then the last (each behind the next)."""
    case = fleet("convoy-of-3")
    releases = order_releases(case.verified("exact"))
    order = [(release.vehicle, release.update) for release in releases.releases if release.update]
    assert order == [(1, 1), (0, 1)]  # agv2 once agv3 is at its goal, agv1 once agv2 is
    assert releases.releases[2].decision_point == 1  # agv3's whole path at once


# -- a junction's route timed on its track graph (issue 49: one order path) ---------------------------------


def test_the_swaps_exact_schedule_timed_on_its_track_graph_gives_the_junctions_order_files_byte_for_byte():
    """The track graph's order path, on a junction's track graph, writes the junction's golden files.

    A leg's end is named by its leg and metres (``A:10``) and a hold by its metres from the junction,
    as on the junction; the nodes, holds, times and releases are the track graph's rules.
    """
    scenario = load_scenario(REPO / "examples" / "swap.toml")
    route = junction_graph_route(scenario.route(), names=scenario.names)
    verified = certify(Exact().schedule_graph(route, scenario.limits))
    options = Vda5050Options(start_time=datetime(2026, 5, 1, 8, 0, tzinfo=UTC))
    made = order_files(verified, scenario.names, Path("out"), options=options)
    stored = REPO / "tests" / "data" / "golden-vda5050" / "swap-exact"
    names = sorted(path.relative_to(stored) for path in stored.rglob("*.json"))
    assert names == sorted(path.relative_to("out") for path in made)
    for name in names:
        assert made[Path("out") / name] == (stored / name).read_bytes(), name


def test_a_junctions_leg_end_is_named_by_its_leg_and_metres_and_its_junction_by_its_name():
    track = load_scenario(REPO / "examples" / "crossing.toml").track.track_graph()
    assert point_id(track, track.point("E-end")) == "E:10"
    assert point_id(track, track.point("E:10")) == "E:10"
    assert point_id(track, track.point("O")) == "O"
    assert point_id(track, track.point("N:2.5")) == "N:2.5"
    assert track.point(point_id(track, track.point("W-end"))) == track.point("W-end")  # it reads back
