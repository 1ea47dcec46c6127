"""Live runs over VDA 5050 on a real MQTT broker (amqtt in the test process; mosquitto when installed).

Every run drives two simulated vehicles with the master on a broker, at a time scale that keeps each
test under 20 s. Safety is checked on the vehicles' true positions (every control cycle), never on
what they reported.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import json
import logging
import math
import re
import time

import pytest

from tests.support.helpers import REPO, execution_plan, scenario_vehicle, stop_bound
from tests.support.live import FAST, HOP_S, Tap, logged_serve, new_broker, serve_with_vehicle_processes
from tests.support.vda5050_reference import schema_errors
from topology import Configuration, Position
from trajgen.cli import main
from trajgen.errors import InputError, LiveError
from trajgen.export.vda5050.release import BaseRelease, order_releases
from trajgen.live.clock import LEAD, RunClock
from trajgen.live.master import LiveMaster, LiveOutcome
from trajgen.live.mqtt import BrokerSettings, Topic, VehicleIdentity, make_client
from trajgen.live.orders import horizon_length
from trajgen.live.session import ClosestApproach, LiveDemo, identities, position_xy
from trajgen.live.vehicle import SimulatedVehicle, StopFault, VehicleSnapshot

pytestmark = pytest.mark.slow

#: Time scale and state rate (Hz of the run) of the runs whose makespan is checked: states on every
#: node reached carry the progress, so ~50 messages/s through amqtt (bench_live.py: +3.5 to +7.2 %).
STRICT = {"time_scale": 4.0, "state_rate": 2.0, "period": 0.02}


def _demo(name: str, method: str, *, faults=((), ()), **settings) -> LiveDemo:
    scenario, verified = execution_plan(name, method)
    demo = LiveDemo(scenario, verified, method="exact", faults=faults, **(settings or FAST))
    return demo.__enter__()


def _drive(name: str, method: str, *, at=(), faults=((), ()), **settings):
    """The scenario driven live to its goals (``at``: actions during the run), its broker stopped after."""
    demo = _demo(name, method, faults=faults, **settings)
    try:
        return demo.run(at=at)
    finally:
        demo.__exit__()


def _separation(name: str) -> float:
    return execution_plan(name, "exact")[0].limits.min_separation


def _fault_free_run(name: str) -> tuple:
    """``(outcome, tap)`` of the scenario's optimal plan driven live at :data:`STRICT`, no fault."""
    demo = _demo(name, "optimal", **STRICT)
    tap = Tap(demo.broker.url)
    try:
        return demo.run(), tap
    finally:
        tap.close()
        demo.__exit__()


@pytest.fixture
def optimal_plans() -> tuple[str, ...]:
    """The scenarios whose optimal plans for execution are solved before the test (its runs only)."""
    names = ("swap", "crossing")
    for name in names:
        execution_plan(name, "optimal")
    return names


def test_fault_free_runs_are_safe_schema_valid_and_close_to_their_plans(optimal_plans):
    """The swap and the crossing, each on a broker of its own, at once (the runs wait on the clock)."""
    names = optimal_plans
    with concurrent.futures.ThreadPoolExecutor(len(names)) as pool:
        runs = dict(zip(names, pool.map(_fault_free_run, names), strict=True))
    for name, (outcome, tap) in runs.items():
        run = outcome.run
        assert run.outcome is LiveOutcome.GOALS_REACHED, name
        assert math.isfinite(outcome.closest), name  # compared at every cycle both drove
        assert outcome.closest >= _separation(name) - 1e-9, name
        assert run.makespan <= run.planned * 1.05 + 1.0, (name, run.makespan, run.planned)
        assert run.ignored == 0, name
        for kind, schema in (("order", "order"), ("state", "state"), ("connection", "connection")):
            documents = tap.of(kind)
            assert documents, (name, kind)
            for document in documents:
                assert schema_errors(document, schema) == [], (name, kind, document.get("headerId"))
        scenario = execution_plan(name, "optimal")[0]
        for order in tap.of("order"):  # a short horizon: the vehicle's stop from full speed, a node at least
            v = scenario.names.index(order["serialNumber"])
            horizon = [edge["length"] for edge in order["edges"] if not edge["released"]]
            last = order["nodes"][-1]["nodePosition"]
            goal = (scenario.goal.first, scenario.goal.second)[v]
            at_goal = math.dist((last["x"], last["y"]), position_xy(scenario.track, goal)) < 1e-6
            assert horizon or at_goal, (name, order["headerId"])
            if horizon:
                assert sum(horizon) - horizon[-1] < horizon_length(scenario.limits.vehicles[v]), name
        updates = [d for d in tap.of("order") if d["orderUpdateId"] > 0]
        assert updates, name  # the base was released in steps
        for update in updates:  # stitched at the previous decision point: the first node is released
            assert update["nodes"][0]["released"] is True, name
        scenario = execution_plan(name, "optimal")[0]
        goals = (scenario.goal.first, scenario.goal.second)
        for vehicle, goal in zip(outcome.vehicles, goals, strict=True):
            place = (vehicle.snapshot.x, vehicle.snapshot.y)
            assert math.dist(place, position_xy(scenario.track, goal)) < 1e-6, name


def test_a_broker_restart_mid_run_is_survived_and_the_latest_orders_are_sent_again():
    restarted = []

    def restart(demo):
        restarted.append(demo.clock.now())  # the clock's time: the log's counts from the first order
        demo.broker.restart(down_for=0.3)

    outcome = _drive("swap", "exact", at=[(12.0, restart)])
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    assert math.isfinite(outcome.closest)  # compared at every cycle both drove
    assert outcome.closest >= _separation("swap") - 1e-9
    records = list(outcome.log.records())
    assert restarted
    # the latest orders sent again once the broker is back
    again = [r for r in records if r["event"] == "order" and r["resent"]]
    assert {r["vehicle"] for r in again} == {"agv1", "agv2"}


def test_a_vehicle_that_drops_off_holds_the_other_at_its_released_base_until_it_is_back():
    outcome = _drive(
        "crossing",
        "exact",
        at=[
            (3.0, lambda demo: demo.vehicles[0].drop_connection()),
            (20.0, lambda demo: demo.vehicles[0].restore_connection()),
        ],
    )
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    assert math.isfinite(outcome.closest)  # compared at every cycle both drove
    assert outcome.closest >= _separation("crossing") - 1e-9
    records = list(outcome.log.records())
    broken = next(r["t"] for r in records if r["event"] == "connection" and r["state"] == "CONNECTIONBROKEN")
    back = next(
        r["t"]
        for r in records
        if r["event"] == "connection"
        and r["vehicle"] == "agv1"
        and r["state"] == "ONLINE"
        and r["t"] > broken
    )
    released = [r for r in records if r["event"] == "order" and not r["resent"] and broken < r["t"] < back]
    assert released == []  # nothing released to either vehicle while agv1 was away
    frontier = max(
        r["frontier_m"] for r in records if r["event"] == "order" and r["vehicle"] == "agv2" and r["t"] < back
    )
    waiting = [
        r for r in records if r["event"] == "state" and r["vehicle"] == "agv2" and broken < r["t"] < back
    ]
    assert waiting
    assert max(r["along_m"] for r in waiting) <= frontier + 1e-6
    assert not waiting[-1]["driving"]  # it stood at its released base


def test_a_stop_fault_makes_the_other_wait_and_costs_at_most_the_online_bound():
    scenario = execution_plan("crossing", "exact")[0]
    duration = 6.0
    # the run without the fault and the run with it, each on a broker of its own, at once
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        free, stopped = pool.map(
            lambda faults: _drive("crossing", "exact", faults=faults),
            [((), ()), ((StopFault(8.0, duration),), ())],
        )
    free = free.run
    assert stopped.run.outcome is LiveOutcome.GOALS_REACHED
    assert math.isfinite(stopped.closest)
    assert stopped.closest >= scenario.limits.min_separation - 1e-9
    latency = 2 * HOP_S * FAST["time_scale"]  # seconds of the run: a state and an update, scaled
    assert stopped.run.makespan <= free.makespan + stop_bound(scenario, duration) + latency


def test_a_new_goal_mid_run_stops_both_at_their_bases_and_replans_from_there():
    scenario = execution_plan("swap", "exact")[0]
    goal = Configuration(Position("C", 8.0), Position("A", 10.0))
    outcome = _drive("swap", "exact", at=[(10.0, lambda demo: demo.master.request_goal(goal))])
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    assert outcome.run.replans == 1
    assert math.isfinite(outcome.closest)  # compared at every cycle both drove
    assert outcome.closest >= scenario.limits.min_separation - 1e-9
    for vehicle, position in zip(outcome.vehicles, (goal.first, goal.second), strict=True):
        assert (
            math.dist((vehicle.snapshot.x, vehicle.snapshot.y), position_xy(scenario.track, position)) < 1e-6
        )


# -- the master alone, fed states by the test: what it takes and what it ignores ---------------------


def connection_message(identity: VehicleIdentity, state: str) -> bytes:
    """A vehicle's ``connection`` message saying ``state``."""
    return json.dumps(
        {
            "headerId": 7,
            "timestamp": "2026-11-26T10:00:00.000Z",
            "version": "2.1.0",
            "manufacturer": identity.manufacturer,
            "serialNumber": identity.serial_number,
            "connectionState": state,
        }
    ).encode()


class FakeVehicles:
    """A client that publishes states for both vehicles and reads the orders the master sends.

    :meth:`stand` says where each stands (its scenario start, no order): the master sends its first
    orders once every vehicle stands where the plan starts it.
    """

    def __init__(self, url: str, ids, *, online=(0, 1)) -> None:
        self.ids = ids
        self.orders: list[dict] = []
        self.header = 100
        self._client = make_client(BrokerSettings.from_url(url), f"fake-{id(self):x}")
        self._client.on_connect = lambda client, *_: [client.subscribe(i.topic(Topic.ORDER)) for i in ids]
        self._client.on_message = lambda c, u, m: self.orders.append(json.loads(m.payload))
        settings = BrokerSettings.from_url(url)
        self._client.connect(settings.host, settings.port)
        self._client.loop_start()
        for v in online:  # there, as a vehicle says (retained)
            self._client.publish(
                ids[v].topic(Topic.CONNECTION), connection_message(ids[v], "ONLINE"), qos=1, retain=True
            ).wait_for_publish(2.0)

    def stand(self, scenario, master, places=None, *, only=(0, 1)) -> None:
        """A state of each vehicle (``only`` those) standing at ``places`` (default: its scenario start).

        No order: as a vehicle says where it is before the run; sent once ``master`` listens.
        """
        assert _until(lambda: master.link.connected, 5.0)
        time.sleep(0.1)  # its subscriptions are in place
        starts = places if places is not None else (scenario.start.first, scenario.start.second)
        for v, place in enumerate(starts):
            if v not in only:
                continue
            x, y = position_xy(scenario.track, place)
            order = {"orderId": "", "orderUpdateId": 0, "nodes": [{"nodeId": "", "sequenceId": 0}]}
            position = {"positionInitialized": True, "x": x, "y": y, "theta": 0.0, "mapId": "trajgen"}
            self.publish(v, self.state(v, order, 0, agvPosition=position))

    def publish(self, v: int, payload: bytes, topic: str | None = None) -> None:
        self._client.publish(topic or self.ids[v].topic(Topic.STATE), payload).wait_for_publish(2.0)

    def send_order(self, v: int, payload: bytes) -> None:
        self._client.publish(self.ids[v].topic(Topic.ORDER), payload).wait_for_publish(2.0)

    def state(self, v: int, order: dict, node: int, *, header: int | None = None, **override) -> bytes:
        self.header += 1
        document = {
            "headerId": self.header if header is None else header,
            "timestamp": "2026-11-26T10:00:00.000Z",
            "version": "2.1.0",
            "manufacturer": self.ids[v].manufacturer,
            "serialNumber": self.ids[v].serial_number,
            "orderId": order["orderId"],
            "orderUpdateId": order["orderUpdateId"],
            "lastNodeId": order["nodes"][node]["nodeId"],
            "lastNodeSequenceId": order["nodes"][node]["sequenceId"],
            "nodeStates": [],
            "edgeStates": [],
            "driving": False,
            "actionStates": [],
            "batteryState": {"batteryCharge": 100.0, "charging": False},
            "operatingMode": "AUTOMATIC",
            "errors": [],
            "safetyState": {"eStop": "NONE", "fieldViolation": False},
        }
        document.update(override)
        return json.dumps(document).encode()

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


def _last_base(order: dict) -> int:
    return max(k for k, node in enumerate(order["nodes"]) if node["released"])


@contextlib.contextmanager
def _master_and_fakes(scenario, verified, **options):
    """The master on a broker with :class:`FakeVehicles` in place of the vehicles."""
    ids = identities(scenario.names)
    with new_broker() as broker:
        fake = FakeVehicles(broker.url, ids)
        master = LiveMaster(
            scenario, plan=verified, identities=ids, broker=BrokerSettings.from_url(broker.url), **options
        )
        master.start()
        fake.stand(scenario, master)
        try:
            yield master, fake
        finally:
            master.stop()
            fake.close()


def _releasing_vehicle(verified, spacing: float) -> int:
    """A vehicle whose arrival at its first decision point releases base (by the master's own rule)."""
    plan = order_releases(verified, spacing=spacing)
    for v in (0, 1):
        rule = BaseRelease(plan.paths, verified.schedule.limits.min_separation)
        if rule.reach(v, rule.released[v]):
            return v
    raise AssertionError("no first arrival releases anything")


#: States the master cannot trust (logged and ignored) or that put their vehicle off its plan (every
#: release held until a state puts it back): the kind, the state, the event it makes.
UNTRUSTED = {
    "malformed": (lambda fake, v, order, node: b'{"headerId": "not a number"', "ignored"),
    "foreign-manufacturer": (
        lambda fake, v, order, node: fake.state(v, order, node, manufacturer="acme"),
        "ignored",
    ),
    "out-of-order": (lambda fake, v, order, node: fake.state(v, order, node, header=1), "ignored"),
    "not-its-node": (
        lambda fake, v, order, node: fake.state(v, order, node, lastNodeId="B:7.25"),
        "off-plan",
    ),
    "odd-sequence-id": (
        lambda fake, v, order, node: fake.state(
            v, order, node, lastNodeSequenceId=order["nodes"][node]["sequenceId"] + 1
        ),
        "off-plan",
    ),
}


@pytest.mark.parametrize("kind", list(UNTRUSTED), ids=list(UNTRUSTED))
def test_an_untrusted_or_off_plan_state_is_logged_and_releases_nothing(kind):
    scenario, verified = execution_plan("swap", "exact")
    state, event = UNTRUSTED[kind]
    with _master_and_fakes(scenario, verified) as (master, fake):
        assert _until(lambda: {o["serialNumber"] for o in fake.orders} == set(scenario.names), 5.0)
        v = _releasing_vehicle(verified, master.spacing)
        orders = {o["serialNumber"]: o for o in fake.orders}
        first = orders[scenario.names[v]]
        fake.publish(1 - v, fake.state(1 - v, orders[scenario.names[1 - v]], 0))  # the other took its order
        assert _until(lambda: any(r["event"] == "state" for r in master.log.records()), 5.0)
        sent = len(fake.orders)
        node = _last_base(first)  # at its decision point: that releases base
        before = len(list(master.log.records()))
        # on one connection, so the master takes them in this order (and logs each as it takes it)
        fake.publish(v, fake.state(v, first, 0))  # genuine, at its start: releases nothing
        fake.publish(v, state(fake, v, first, node))
        fake.publish(v, fake.state(v, first, node))  # the genuine report does release
        assert _until(lambda: len(fake.orders) > sent, 5.0)
        assert master.result().ignored == (event == "ignored")
        records = list(master.log.records())[before:]
    # nothing released before the genuine report at the decision point: not on the untrusted one's account
    expected = ["state", event, "state", "order"] if event == "ignored" else ["state", event, "on-plan"]
    assert [r["event"] for r in records[: len(expected)]] == expected
    assert [r["node"] for r in records if r["event"] == "state"][:2] == [0, node]
    said = [r for r in master.log.records() if r["event"] == event]
    assert len(said) == 1
    assert said[0]["vehicle"] == scenario.names[v]


def test_a_state_on_a_topic_of_no_vehicle_of_the_run_never_reaches_the_master():
    scenario, verified = execution_plan("swap", "exact")
    with _master_and_fakes(scenario, verified) as (master, fake):
        time.sleep(0.5)
        sent = len(fake.orders)
        fake.publish(0, b"{}", topic=VehicleIdentity("acme", "agv9").topic(Topic.STATE))
        time.sleep(0.15)  # time for it to arrive, if it did
        assert len(fake.orders) == sent
    assert master.result().ignored == 0  # not subscribed: it never arrives


# -- the simulated vehicle ----------------------------------------------------------------------------


def _until(condition, seconds: float = 10.0) -> bool:
    """Wait until ``condition()`` holds (polled), at most ``seconds``; whether it did."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def _first_vehicle(scenario, ids, settings: BrokerSettings, clock: RunClock, **options) -> SimulatedVehicle:
    """The scenario's first vehicle, simulated and started (``options``: of :class:`SimulatedVehicle`)."""
    return scenario_vehicle(scenario, 0, ids[0], broker=settings, clock=clock, **options).start()


def _watcher(settings: BrokerSettings, topic: str, take):
    """A client that hands every message on ``topic`` to ``take``, connected and looping."""
    watcher = make_client(settings, f"watcher-{id(take):x}")
    watcher.on_connect = lambda client, *_: client.subscribe(topic)
    watcher.on_message = lambda client, userdata, message: take(message)
    watcher.connect(settings.host, settings.port)
    watcher.loop_start()
    return watcher


def test_the_vehicle_ignores_a_duplicate_order_and_refuses_an_update_that_does_not_continue_its_base():
    scenario, verified = execution_plan("swap", "exact")
    ids = identities(scenario.names)
    with new_broker() as broker:
        settings = BrokerSettings.from_url(broker.url)
        fake = FakeVehicles(broker.url, ids)
        clock = RunClock(FAST["time_scale"])
        vehicle = _first_vehicle(scenario, ids, settings, clock)
        master = LiveMaster(scenario, plan=verified, identities=ids, broker=settings, clock=clock)
        try:
            states = []
            watcher = _watcher(
                settings, ids[0].topic(Topic.STATE), lambda m: states.append(json.loads(m.payload))
            )
            master.start()
            fake.stand(scenario, master, only=(1,))  # agv1 is a simulated vehicle: it says where it stands
            assert _until(lambda: any(o["serialNumber"] == "agv1" for o in fake.orders))
            sent = next(o for o in fake.orders if o["serialNumber"] == "agv1")
            assert _until(lambda: states and states[-1]["orderId"] == sent["orderId"])
            assert states[-1]["orderUpdateId"] == 0
            assert states[-1]["errors"] == []
            # an update that does not start at the decision point: refused, as VDA 5050's figure 8 says
            document = json.loads(json.dumps(sent))
            document["orderUpdateId"] = 7
            document["headerId"] += 50
            document["nodes"] = document["nodes"][1:]
            document["edges"] = document["edges"][1:]
            fake.send_order(0, json.dumps(document).encode())
            assert _until(lambda: states[-1]["errors"])
            assert states[-1]["orderUpdateId"] == 0
            assert [e["errorType"] for e in states[-1]["errors"]] == ["orderUpdateError"]
            assert vehicle.rejections == 1
            # the same order again: a duplicate, ignored without an error
            fake.send_order(0, json.dumps(sent).encode())
            time.sleep(0.5)
            assert vehicle.rejections == 1
            # it never drives past its base
            base_end = _last_base(sent)
            assert states[-1]["lastNodeSequenceId"] <= 2 * base_end
            watcher.disconnect()
            watcher.loop_stop()
        finally:
            master.stop()
            vehicle.stop()
            fake.close()


def test_a_vehicle_reports_at_once_when_it_comes_to_rest_and_says_its_last_state_before_going_offline():
    scenario, verified = execution_plan("swap", "exact")
    ids = identities(scenario.names)
    with new_broker() as broker:
        settings = BrokerSettings.from_url(broker.url)
        clock = RunClock(5.0)
        rest = []  # run time of each cycle the vehicle ends at rest after moving
        moving = [False]

        def observe(snapshot: VehicleSnapshot) -> None:
            if abs(snapshot.velocity) > 1e-3:
                moving[0] = True
            elif moving[0]:
                moving[0] = False
                rest.append(snapshot.time)

        heard = []  # (run time of arrival, topic's last part, message)
        watcher = _watcher(
            settings,
            f"{ids[0].topic(Topic.STATE)[:-5]}#",
            lambda m: heard.append((clock.now(), m.topic.rsplit("/", 1)[1], json.loads(m.payload))),
        )
        # a state every 10 s of the run at most: any state sooner after stopping is the event's
        vehicle = _first_vehicle(scenario, ids, settings, clock, state_rate=0.1, observer=observe)
        master = LiveMaster(scenario, plan=verified, identities=ids, broker=settings, clock=clock)
        other = FakeVehicles(broker.url, ids, online=(1,))
        try:
            master.start()
            other.stand(scenario, master, only=(1,))  # it never drives: the master sends the first orders
            assert _until(lambda: rest and clock.now() > rest[0] + 2.0)
            # issue 35, item 10: ONLINE comes first, then its states
            assert heard[0][1] == "connection"
            assert heard[0][2]["connectionState"] == "ONLINE"
            assert heard[1][1] == "state"
            stood = [t for t, kind, m in heard if kind == "state" and not m["driving"] and t >= rest[0]]
            assert stood
            assert stood[0] - rest[0] < 1.0  # not at the next periodic state, 10 s later
            stopped_at = len(heard)
            vehicle.stop()
            assert _until(lambda: any(kind == "connection" for _, kind, _ in heard[stopped_at:]))
            after = [(kind, m) for _, kind, m in heard[stopped_at:]]
            assert [kind for kind, _ in after[:2]] == ["state", "connection"]
            assert not after[0][1]["driving"]
            assert after[1][1]["connectionState"] == "OFFLINE"
        finally:
            master.stop()
            vehicle.stop()
            other.close()
            watcher.disconnect()
            watcher.loop_stop()


# -- the command line ---------------------------------------------------------------------------------


def test_serve_drives_two_vehicle_processes_and_commits_its_log_and_picture(tmp_path, capsys, caplog):
    caplog.set_level(logging.INFO, logger="trajgen.live.master")
    with new_broker() as broker:
        status, outputs, vehicles = serve_with_vehicle_processes(
            str(REPO / "examples" / "swap.toml"),
            ["--broker", broker.url, "--time-scale", "25"],
            vehicle=["--state-rate", "1", "--exit-at-goal"],
            serve=logged_serve(tmp_path),
        )
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == ("exact", "exact", None)
    assert all(p.returncode == 0 for p in vehicles), outputs
    assert all("at its goal" in out for out, _ in outputs)
    records = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert records[-1]["event"] == "end"
    assert records[-1]["outcome"] == "goals-reached"
    assert (tmp_path / "run.png").read_bytes()[:4] == b"\x89PNG"
    # one clock: the run's time starts at the first order, for the log, the makespan and the vehicles;
    # planning and the wait for the broker are reported apart
    plan = next(r for r in records if r["event"] == "plan")
    assert plan["t"] == 0.0  # logged with the first orders, after the vehicles were heard
    for wait in ("broker_wait_s", "vehicle_wait_s"):
        assert plan[wait] == summary[wait] >= 0.0
    assert summary["planning_s"] > 0.0
    assert min(r["t"] for r in records) == 0.0
    assert next(r for r in records if r["event"] == "order")["t"] < 1.0  # its message built at 25x
    assert 0.0 <= records[-1]["t"] - summary["makespan_s"] < 2.0  # logged when the master stops
    # the vehicles' 2 s (50 s of the run) before serve are not in the makespan; vehicle processes that
    # fall behind on a loaded machine lengthen it (83 s seen beside two CPU hogs), they never shorten it
    assert 67.5 - 25.0 < summary["makespan_s"] < 67.5 + 2.0 * 25.0
    # the vehicles started 50 s of the run before the master: their time counts from the first order
    # too (a vehicle's clock may lose time on a loaded machine, never gain it)
    since = [float(re.search(r"([0-9.]+) s after its first order", out).group(1)) for out, _ in outputs]
    assert 0.0 < min(since) <= max(since) <= summary["makespan_s"] + 3.0
    # issue 35, item 10: a vehicle that leaves at its goal (--exit-at-goal) is said to be there
    said = [r.getMessage() for r in caplog.records if r.name == "trajgen.live.master"]
    assert not [line for line in said if "no base is released" in line], said


def test_demo_live_runs_broker_vehicles_and_master_in_one_command(tmp_path, capsys):
    fast = ["--time-scale", "20", "--state-rate", "1"]
    status = main(["demo", "--live", "--method", "exact", *fast, "--output", str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 0
    assert "goals-reached" in out
    assert "plan 67.500 s, exact; before the first order, planning took " in out  # said apart
    assert (tmp_path / "live-run.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "live-run.jsonl").stat().st_size > 0


def test_a_fallback_plan_of_demo_live_is_reported_in_its_json_and_its_log(tmp_path, capsys, monkeypatch):
    from trajgen.methods.optimal import class_solve as optimal_method

    monkeypatch.setattr(optimal_method, "solve", _failing_solve)
    fast = ["--time-scale", "25", "--state-rate", "1"]
    status = main(["demo", "--live", "--json", *fast, "--output", str(tmp_path)])
    captured = capsys.readouterr()
    summary = json.loads(captured.out)  # stdout is the summary alone
    assert status == 0
    assert summary["outcome"] == "goals-reached"
    assert (summary["method"], summary["computed_by"], summary["fallback_reason"]) == (
        "optimal",
        "exact",
        "solver-failed",
    )
    assert summary["planned_s"] == pytest.approx(67.5)
    assert "fell back to the exact schedule (solver-failed): no solver converged" in captured.err
    plan = next(
        json.loads(line)
        for line in (tmp_path / "live-run.jsonl").read_text().splitlines()
        if json.loads(line)["event"] == "plan"
    )
    assert (plan["method"], plan["computed_by"], plan["fallback_reason"]) == (
        "optimal",
        "exact",
        "solver-failed",
    )


def _failing_solve(*_arguments, **_options):
    """The optimal method's solver chain, made to fail: every class falls back to ``exact``."""
    from trajgen.methods.optimal import Outcome, Solver, SolverAttempt
    from trajgen.methods.optimal.solve import SolveResult

    return SolveResult(None, (SolverAttempt(Solver.FATROP, Outcome.NOT_CONVERGED, 1, "made to fail"),))


def test_serve_with_no_broker_retries_says_so_once_and_commits_its_log_and_picture(tmp_path, capsys):
    # issue 35, items 1 and 5: the first connection is retried until --timeout, said once (on the
    # timeline, issue 48 item 4); the log and the summary are committed, and a picture saying no
    # vehicle sent a state (issue 48 item 6); exit 1
    status = main(
        [
            "serve",
            str(REPO / "examples" / "swap.toml"),
            "--broker",
            "mqtt://127.0.0.1:1",
            "--method",
            "exact",
            "--timeout",
            "3",
            "--log",
            str(tmp_path / "run.jsonl"),
            "--plot",
            str(tmp_path / "run.png"),
        ]
    )
    captured = capsys.readouterr()
    assert status == 1
    said = "broker: cannot reach mqtt://127.0.0.1:1: connection refused; retrying"
    assert captured.out.count(said) == 1
    assert "cannot reach" not in captured.err  # said once: on the timeline, not again on stderr
    assert "trajgen: error: master: the broker mqtt://127.0.0.1:1 was never reached" in captured.err
    assert "internal failure" not in captured.err
    assert "live run: timed-out before any order was sent" in captured.out
    records = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert records[-1]["event"] == "end"
    assert "never reached" in records[-1]["error"]
    assert (tmp_path / "run.png").read_bytes().startswith(b"\x89PNG")
    assert not (tmp_path / "run.jsonl.partial").exists()  # committed: the partial log is gone


def test_serve_timeout_counts_from_its_start_and_names_vehicles_never_heard(tmp_path, capsys, monkeypatch):
    # issue 48, item 4: serve connects while it plans (here 1.5 s), so --timeout counts from its
    # start; a broker with no vehicle on it is said (issue 35, item 9)
    import trajgen.live.coordinator as coordinator

    planned = coordinator.schedule_for_execution

    def slow_plan(scenario, *, method=None):
        time.sleep(1.5)
        return planned(scenario, method=method)

    monkeypatch.setattr(coordinator, "schedule_for_execution", slow_plan)
    with new_broker() as broker:
        began = time.monotonic()
        scenario, log = str(REPO / "examples" / "swap.toml"), str(tmp_path / "run.jsonl")
        options = ["--broker", broker.url, "--method", "exact", "--timeout", "2", "--log", log, "--json"]
        status = main(["serve", scenario, *options])
        seconds = time.monotonic() - began
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert status == 1
    assert 2.0 <= seconds < 1.5 + 2.0  # --timeout from the start: planning is part of it
    assert summary["planning_s"] >= 1.5
    assert summary["outcome"] == "timed-out"
    assert summary["orders"] == 0
    assert summary["broker_wait_s"] >= 0.0
    assert summary["vehicle_wait_s"] is None
    assert summary["error"].startswith("master: no order was sent: agv1 and agv2 never came online")
    assert "uagv/v2/unspecified/agv1/connection" in summary["error"]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        pytest.param(lambda: BrokerSettings.from_url("http://host:1883"), "scheme 'http'", id="scheme"),
        pytest.param(lambda: BrokerSettings.from_url("mqtt://host:99999"), "bad port", id="port"),
        pytest.param(lambda: BrokerSettings.from_url("mqtt://:1883"), "names no host", id="no-host"),
        pytest.param(
            lambda: BrokerSettings.from_url("mqtt://h:1", username="u", password_file="/nonexistent/pw"),
            "password file '/nonexistent/pw' cannot be read",
            id="password-file",
        ),
        pytest.param(lambda: RunClock(1000.0), "time scale 1000.0 is out of range", id="time-scale"),
        pytest.param(lambda: StopFault.parse("halt@3"), "vehicle fault 'halt@3' cannot be read", id="fault"),
        pytest.param(lambda: identities(("agv1", "agv1")), "expected 2 different ones", id="same-serials"),
        pytest.param(lambda: VehicleIdentity("a/b", "agv1"), "not an MQTT topic level", id="slash-in-level"),
    ],
)
def test_bad_live_input_is_refused_naming_the_value(call, match):
    with pytest.raises(InputError, match=match):
        call()


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        pytest.param(["--goal-at", "soon=A:3,B:3"], "--goal-at 'soon=A:3,B:3' cannot be read", id="goal-at"),
        pytest.param(["--time-scale", "0"], "time scale 0.0 is out of range", id="time-scale"),
        pytest.param(["--broker", "ftp://x"], "scheme 'ftp'", id="broker"),
    ],
)
def test_bad_serve_arguments_exit_2_before_connecting(arguments, match, capsys, tmp_path):
    argv = [
        "serve",
        str(REPO / "examples" / "swap.toml"),
        "--broker",
        "mqtt://127.0.0.1:1",
        "--log",
        str(tmp_path / "l"),
    ]
    assert main([*argv, *arguments]) == 2
    assert match in capsys.readouterr().err


def test_the_live_error_is_a_runtime_error():
    assert issubclass(LiveError, RuntimeError)


def test_a_clock_waits_for_the_slowest_vehicle_it_follows_and_the_time_waited_is_not_the_runs():
    clock = RunClock(50.0)
    stuck = [0.0]
    clock.follow(lambda: stuck[0])
    time.sleep(0.05)  # 2.5 s of the run at 50x, but the vehicle stands at 0
    assert clock.now() == pytest.approx(LEAD)
    stuck[0] = float("inf")  # it stopped: followed no more
    before = clock.now()
    time.sleep(0.02)
    assert clock.now() - before == pytest.approx(1.0, abs=0.5)  # 20 ms at 50x, from where it waited


def test_the_closest_approach_compares_the_vehicles_at_the_same_cycle_and_keeps_few_snapshots():
    scenario = execution_plan("swap", "exact")[0]
    approach = ClosestApproach(scenario.track)
    first, second = approach.observer(0), approach.observer(1)
    a_leg = position_xy(scenario.track, Position("A", 1.0))
    for k in range(5000):  # vehicle 1 stands 1 m into A; vehicle 2 drives in from B:10 to the junction
        t = 0.02 * k
        s = max(10.0 - 0.004 * k, 0.0)
        b_leg = position_xy(scenario.track, Position("B", s)) if s > 0 else (0.0, 0.0)
        first(VehicleSnapshot(t, *a_leg, 0.0, 0, False))
        if k % 7 != 3:  # some cycles of vehicle 2 missing: those moments are never compared
            second(VehicleSnapshot(t, *b_leg, 1.0, 0, False))
    assert approach.closest == pytest.approx(1.0)  # at the junction: 1 m + 0 m
    assert approach.compared == 5000 - len(range(3, 5000, 7))
    assert approach.waiting <= 2  # bounded, not the whole run


# -- orders refused, not taken, or known from an earlier run (issue 35, items 3 and 10) ----------------

REFUSAL = "first node 'A:0.228571' is not trivially reachable"


def _orders_of(fake: FakeVehicles, serial: str) -> list[dict]:
    return [order for order in fake.orders if order["serialNumber"] == serial]


def test_a_refused_order_is_reported_at_once_and_its_resends_back_off_with_new_header_ids(caplog):
    caplog.set_level(logging.WARNING, logger="trajgen.live.master")
    scenario, verified = execution_plan("swap", "exact")
    name = scenario.names[0]
    with _master_and_fakes(scenario, verified) as (master, fake):
        assert _until(lambda: len(_orders_of(fake, name)) >= 1, 5.0)
        first = _orders_of(fake, name)[0]
        error = {"errorType": "orderError", "errorLevel": "WARNING", "errorDescription": REFUSAL}

        def refusing() -> bytes:  # the vehicle holds no order and says why
            return fake.state(0, first, 0, orderId="", orderUpdateId=0, lastNodeId="", errors=[error])

        began = time.monotonic()
        fake.publish(0, refusing())
        assert _until(lambda: any(r["event"] == "vehicle-error" for r in master.log.records()), 5.0)
        assert time.monotonic() - began < 5.0  # the issue: within 5 s
        for _ in range(30):  # the refusal stands for 3 s, a state every 0.1 s
            fake.publish(0, refusing())
            time.sleep(0.1)
        time.sleep(0.2)
        sent = _orders_of(fake, name)
    records = [r for r in master.log.records() if r["event"] == "vehicle-error"]
    assert len(records) == 1
    assert records[0]["vehicle"] == name
    assert records[0]["type"] == "orderError"
    assert records[0]["description"] == REFUSAL
    warnings = [r.getMessage() for r in caplog.records if REFUSAL in r.getMessage()]
    assert warnings == [f"master: {name} reports orderError: {REFUSAL}"]
    # 0.25, 0.5, 1, 2 s apart (not 12 re-sends at 0.25 s): the first order and at most 5 more
    assert 2 <= len(sent) <= 6, len(sent)
    headers = [order["headerId"] for order in sent]
    assert headers == sorted(set(headers)), headers  # one headerId per message, increasing


def test_a_refusal_that_stands_ends_the_run_as_order_not_taken_naming_the_vehicle_and_its_reason():
    scenario, verified = execution_plan("swap", "exact")
    name = scenario.names[0]
    with _master_and_fakes(scenario, verified, give_up_after=1.5) as (master, fake):
        assert _until(lambda: len(_orders_of(fake, name)) >= 1, 5.0)
        first = _orders_of(fake, name)[0]
        error = {"errorType": "orderError", "errorLevel": "WARNING", "errorDescription": REFUSAL}
        began = time.monotonic()
        while not master.wait(timeout=0.1) and time.monotonic() - began < 10.0:
            fake.publish(
                0, fake.state(0, first, 0, orderId="", orderUpdateId=0, lastNodeId="", errors=[error])
            )
        ended = time.monotonic() - began
        run = master.result()
    assert run.outcome is LiveOutcome.ORDER_NOT_TAKEN
    assert 1.5 <= ended < 4.0  # after the time given, not at the run's time limit
    assert run.error.startswith(f"master: {name} has not taken its order in 1.5 s of re-sends")
    assert f"it reports no order): it says orderError: {REFUSAL}" in run.error
    assert "ACL" not in run.error  # the vehicle gave its reason: no guess besides it
    end = list(master.log.records())[-1]
    assert (end["event"], end["outcome"], end["error"]) == ("end", "order-not-taken", run.error)


def test_a_vehicle_that_takes_its_order_late_is_not_given_up():
    scenario, verified = execution_plan("swap", "exact")
    with _master_and_fakes(scenario, verified, give_up_after=1.0) as (master, fake):
        assert _until(lambda: len(_orders_of(fake, scenario.names[0])) >= 1, 5.0)
        first = _orders_of(fake, scenario.names[0])[0]
        for _ in range(8):  # 0.8 s without the order, then it has it: the wait starts again
            fake.publish(0, fake.state(0, first, 0, orderId="", orderUpdateId=0, lastNodeId=""))
            time.sleep(0.1)
        for _ in range(8):
            fake.publish(0, fake.state(0, first, 0))
            time.sleep(0.1)
        for _ in range(8):
            fake.publish(0, fake.state(0, first, 0, orderId="", orderUpdateId=0, lastNodeId=""))
            time.sleep(0.1)
        assert not master.wait(timeout=0.1)
        assert master.result().outcome is LiveOutcome.TIMED_OUT


def test_a_retained_online_of_an_earlier_run_sends_no_second_order():
    scenario, verified = execution_plan("swap", "exact")
    ids = identities(scenario.names)
    with new_broker() as broker:
        settings = BrokerSettings.from_url(broker.url)
        earlier = make_client(settings, "an-earlier-vehicle")
        earlier.connect(settings.host, settings.port)
        earlier.loop_start()
        for identity in ids:
            online = connection_message(identity, "ONLINE")
            topic = identity.topic(Topic.CONNECTION)
            earlier.publish(topic, online, qos=1, retain=True).wait_for_publish(2.0)
        earlier.disconnect()
        earlier.loop_stop()
        fake = FakeVehicles(broker.url, ids)
        master = LiveMaster(scenario, plan=verified, identities=ids, broker=settings).start()
        fake.stand(scenario, master)
        try:
            assert _until(lambda: len(fake.orders) >= 2, 5.0)
            time.sleep(1.0)  # time for a redundant order, if one were sent
        finally:
            master.stop()
            fake.close()
    assert sorted(order["serialNumber"] for order in fake.orders) == sorted(scenario.names)


def test_nothing_is_released_to_a_vehicle_back_online_before_its_first_state_says_it_kept_its_order():
    """A release to or for a vehicle back online waits for its first state.

    A restarted vehicle takes any order before its first state (it cannot yet say where it is): a
    release sent then would start where it no longer stands.
    """
    scenario, verified = execution_plan("swap", "exact")
    with _master_and_fakes(scenario, verified) as (master, fake):
        _until(lambda: len(fake.orders) >= 2, 5.0)
        v = _releasing_vehicle(verified, master.spacing)
        other = 1 - v
        orders = {o["serialNumber"]: o for o in fake.orders}
        first, theirs = orders[scenario.names[v]], orders[scenario.names[other]]
        fake.publish(other, fake.state(other, theirs, 0))
        for state in ("OFFLINE", "ONLINE"):  # the other drops off and comes back
            fake.publish(
                other,
                connection_message(fake.ids[other], state),
                topic=fake.ids[other].topic(Topic.CONNECTION),
            )
        time.sleep(0.2)
        sent = len(fake.orders)
        fake.publish(v, fake.state(v, first, _last_base(first)))  # at its decision point: a release is due
        time.sleep(0.5)
        assert len(fake.orders) == sent  # held: the other has not said yet whether it kept its order
        fake.publish(other, fake.state(other, theirs, 0, headerId=1))  # it did (its headers count afresh)
        assert _until(lambda: len(fake.orders) > sent, 5.0)
    assert master.result().ignored == 0


def test_a_vehicle_that_loses_its_order_without_going_offline_is_re_planned_from_where_it_stands():
    """A vehicle that suddenly holds no order is planned again from where it says it stands.

    Issue 48, item 1: what a vehicle reports is the truth; a restart faster than the broker saw it go
    leaves no OFFLINE to go by, only a state without the order; the other vehicle is held meanwhile.
    """
    scenario, verified = execution_plan("swap", "exact")
    with _master_and_fakes(scenario, verified) as (master, fake):
        assert _until(lambda: {o["serialNumber"] for o in fake.orders} == set(scenario.names), 5.0)
        orders = {o["serialNumber"]: o for o in fake.orders}
        mine, theirs = orders[scenario.names[0]], orders[scenario.names[1]]
        fake.publish(1, fake.state(1, theirs, _last_base(theirs)))  # at its decision point, at rest
        fake.publish(0, fake.state(0, mine, 0))  # agv1 took its order
        x, y = position_xy(scenario.track, scenario.start.first)
        position = {"positionInitialized": True, "x": x, "y": y, "theta": 0.0, "mapId": "trajgen"}
        nothing = {"orderId": "", "orderUpdateId": 0, "nodes": [{"nodeId": "", "sequenceId": 0}]}
        fake.publish(0, fake.state(0, nothing, 0, agvPosition=position))  # and then holds none
        assert _until(lambda: any(r["event"] == "restart" for r in master.log.records()), 5.0)
        sent = len(fake.orders)
        latest = _orders_of(fake, scenario.names[1])[-1]  # agv1's order may have released more to agv2
        fake.publish(1, fake.state(1, latest, _last_base(latest)))  # agv2 stands at its decision point
        assert _until(lambda: any(r["event"] == "replan" for r in master.log.records()), 10.0)
        # each vehicle's new order (on a loaded machine more than two messages may come first)
        assert _until(lambda: {o["serialNumber"] for o in fake.orders[sent:]} == set(scenario.names), 5.0)
        theirs = latest
    events = [r["event"] for r in master.log.records()]
    assert events.index("restart") < events.index("replan")
    restart = next(r for r in master.log.records() if r["event"] == "restart")
    assert (restart["vehicle"], restart["at"]) == (scenario.names[0], str(scenario.start.first))
    new = {o["serialNumber"]: o for o in fake.orders[sent:]}
    assert new[scenario.names[0]]["nodes"][0]["sequenceId"] == 0  # a new order, numbered afresh
    assert new[scenario.names[1]]["nodes"][0]["nodeId"] == theirs["nodes"][_last_base(theirs)]["nodeId"]
