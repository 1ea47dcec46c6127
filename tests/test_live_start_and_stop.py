"""Live over mosquitto: no order before the vehicles stand at the plan's start; a stopped master tells.

Issue 48, items 1, 2 and 4: a vehicle off its plan's start gets the run re-planned (or refused)
before any order leaves; a master stopped by SIGINT, SIGTERM or SIGKILL keeps its log and its
vehicles know; serve says what happens, one line each, and the closest approach.

Every run drives ``trajgen vehicle`` processes; a third client taps every message. Where a vehicle
stands is read from its reported states, as the master reads them.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time

import pytest

from tests.conftest import REPO
from tests.support.live import States, Tap, closest_states, new_broker, place_reader, trajgen_process
from topology import Position
from trajgen.cli import main
from trajgen.export.vda5050.graph_path import point_id
from trajgen.live.geometry import position_xy
from trajgen.scenario import GraphScenario, load_scenario

pytestmark = pytest.mark.slow

SWAP = str(REPO / "examples" / "swap.toml")
H = str(REPO / "examples" / "graphs" / "h.toml")
SCALE = 10.0


def _vehicles(path: str, url: str, starts: dict[str, str], *, timeout: float = 600.0) -> dict:
    """A ``trajgen vehicle`` process per vehicle of ``path``, each at its ``--start`` in ``starts``."""
    processes = {}
    for name in load_scenario(path).names:
        start = ["--start", starts[name]] if name in starts else []
        common = ["--broker", url, "--time-scale", f"{SCALE:g}", "--exit-at-goal"]
        common += ["--timeout", f"{timeout:g}"]
        processes[name] = trajgen_process("vehicle", path, name, *common, *start)
    return processes


def _ended(processes) -> dict[str, tuple[int, str, str]]:
    """Each process's exit status, stdout and stderr (killed after 30 s)."""
    ended = {}
    for name, process in processes.items():
        try:
            out, err = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            out, err = process.communicate()
        ended[name] = (process.returncode, out, err)
    return ended


def _place_name(scenario, place_text: str) -> str:
    """How the master names the place ``--start place_text`` (its node id on a graph)."""
    track = scenario.track
    if isinstance(scenario, GraphScenario):
        return point_id(track, track.point(place_text))
    return str(track.check(Position.parse(place_text)))


# -- item 1: a vehicle that is not where the plan starts it ------------------------------------------------

#: scenario, where the vehicles stand (``--start``), and how the run must end
OFF_START = {
    # the issue's case: agv1 stands on agv2's way, 3 m down e, where agv2 drives first
    "h-on-the-others-path": (H, {"agv1": "e:3"}, "goals-reached"),
    # agv1 already 3 m along its own way out of A
    "h-on-its-own-path": (H, {"agv1": "a:3"}, "goals-reached"),
    # agv2 in the side leg c, an edge the plan sends neither vehicle along
    "h-on-another-edge": (H, {"agv2": "c:3"}, "goals-reached"),
    # the swap: agv1 on leg B, 3 m in front of agv2
    "swap-on-the-others-path": (SWAP, {"agv1": "B:7"}, "goals-reached"),
    # 1 m from agv2 at D, with a separation of 1.5 m: no plan starts there
    "h-too-close": (H, {"agv1": "e:5.5"}, "refused"),
}


@pytest.mark.parametrize("case", list(OFF_START))
def test_no_order_leaves_before_every_vehicle_stands_where_the_plan_starts_it(case, tmp_path, capsys):
    path, starts, outcome = OFF_START[case]
    scenario = load_scenario(path)
    place_of, _ = place_reader(scenario)
    log, picture = tmp_path / "run.jsonl", tmp_path / "run.png"
    with new_broker() as broker:
        tap = Tap(broker.url)
        states = States(broker.url, place_of)
        processes = _vehicles(path, broker.url, starts)
        try:
            time.sleep(1.5)  # the vehicles say where they stand before the master comes
            options = ["--broker", broker.url, "--time-scale", f"{SCALE:g}", "--timeout", "600"]
            status = main(["serve", path, *options, "--log", str(log), "--plot", str(picture)])
        finally:
            vehicles = _ended(processes)
            tap.close()
            states.close()
    out, err = capsys.readouterr()
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert picture.read_bytes().startswith(b"\x89PNG")
    moved = [r for r in records if r["event"] == "off-start"]
    assert {r["vehicle"] for r in moved} == set(starts)
    assert all(r["at"] == _place_name(scenario, starts[r["vehicle"]]) for r in moved)
    orders = tap.of("order")
    if outcome == "refused":
        assert status == 1
        assert orders == []  # nothing left for anyone
        assert "closer than the separation 1.5 m: no plan starts there" in err
        assert "no order was sent" in err
        assert records[-1]["outcome"] == "refused"
        for code, _, said in vehicles.values():  # told by the master's going: they end, not at a goal
            assert code == 1
            assert "the master is gone (OFFLINE) before any order" in said
        return
    assert status == 0, err
    assert records[-1]["outcome"] == outcome
    # every vehicle's first order starts where it stood: none was sent for the plan from the scenario
    for name in scenario.names:
        first = next(order for order in orders if order["serialNumber"] == name)
        v = scenario.names.index(name)
        if isinstance(scenario, GraphScenario):
            start = starts.get(name, scenario.track.name(scenario.start[v]))
            assert first["nodes"][0]["nodeId"] == _place_name(scenario, start)
        else:
            given = (scenario.start.first, scenario.start.second)[v]
            here = Position.parse(starts[name]) if name in starts else given
            x, y = position_xy(scenario.track, here)
            node = first["nodes"][0]["nodePosition"]
            assert abs(node["x"] - x) < 1e-6
            assert abs(node["y"] - y) < 1e-6
        assert vehicles[name][0] == 0, vehicles[name][2]
    first_order = next(k for k, r in enumerate(records) if r["event"] == "order")
    replanned = next(k for k, r in enumerate(records) if r["event"] == "planned" and "stand" in r["what"])
    assert replanned < first_order
    closest = closest_states(scenario, states)
    separation = scenario.limits.min_separation
    assert closest >= separation - 1e-6, closest  # the reported places, every state both sent
    assert "closest approach" in out
    summary_closest = float(out.split("closest approach ")[1].split(" m")[0])
    assert summary_closest >= separation - 1e-4
    print(f"{case}: closest reported {closest:.3f} m; timeline:\n{out}")


def test_serve_says_planning_connection_first_orders_and_the_end_one_line_each(tmp_path, capsys):
    """Item 4: the timeline of a run on the H, and the closest approach in the summary.

    Item 6: the vehicles started 30 s of the run before the master, with ``--timeout 60``, while the
    run takes about 45 s: their time out counts from their first order, and they reach their goals.
    """
    log = tmp_path / "run.jsonl"
    with new_broker() as broker:
        processes = _vehicles(H, broker.url, {}, timeout=60.0)
        try:
            time.sleep(3.0)
            options = ["--broker", broker.url, "--time-scale", f"{SCALE:g}", "--timeout", "600"]
            assert main(["serve", H, *options, "--log", str(log)]) == 0
        finally:
            vehicles = _ended(processes)
    for code, said, err in vehicles.values():
        assert code == 0, err
        assert "(at its goal)" in said
    out = capsys.readouterr().out
    lines = out.splitlines()
    said = [line.split(" s  ", 1)[1] for line in lines if " s  " in line]
    assert said[0] == "planning the scenario's start (exact)"  # one default on a graph, said once
    for expected in (
        "broker: connected to mqtt://",
        "agv1 stands at A",
        "agv2 stands at D",
        "planned the scenario's start in",
        "agv1: order, base to",
        "agv2: order, base to",
        "end: goals-reached",
    ):
        assert sum(line.startswith(expected) for line in said) == 1, (expected, said)
    assert not any("update" in line for line in said)  # updates are the log's, not the timeline's
    times = [float(line.split(" s  ", 1)[0]) for line in lines if " s  " in line]
    assert times == sorted(times)
    assert "closest approach" in lines[-1]
    print("the timeline of serve on the H:\n" + out)


# -- item 2: stopping the master ---------------------------------------------------------------------------


def _serve_process(path: str, url: str, folder) -> subprocess.Popen:
    options = ["--broker", url, "--time-scale", f"{SCALE / 2:g}", "--timeout", "200"]
    files = ["--log", str(folder / "run.jsonl"), "--plot", str(folder / "run.png")]
    return trajgen_process("serve", path, *options, *files)


@pytest.mark.parametrize(
    ("how", "status"),
    [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGKILL, -signal.SIGKILL)],
    ids=["sigint", "sigterm", "kill-9"],
)
def test_a_master_stopped_mid_run_keeps_its_log_and_its_vehicles_know(how, status, tmp_path):
    scenario = load_scenario(H)
    place_of, _ = place_reader(scenario)
    with new_broker() as broker:
        tap = Tap(broker.url)
        states = States(broker.url, place_of)
        processes = {}
        for name in scenario.names:
            common = ["--broker", broker.url, "--time-scale", f"{SCALE / 2:g}", "--exit-at-goal"]
            processes[name] = trajgen_process("vehicle", H, name, *common, "--timeout", "120")
        serve = _serve_process(H, broker.url, tmp_path)
        try:
            deadline = time.monotonic() + 60.0
            while not any(driving for _, _, driving in states.seen):  # stopped while the vehicles drive
                assert time.monotonic() < deadline, "no vehicle drove"
                time.sleep(0.05)
            time.sleep(1.0)
            os.kill(serve.pid, how)
            out, err = serve.communicate(timeout=30)
            vehicles = _ended(processes)
        finally:
            for process in [serve, *processes.values()]:
                if process.poll() is None:
                    process.kill()
            tap.close()
            states.close()
    assert serve.returncode == status, err
    if how == signal.SIGKILL:
        # the log so far is on disk, streamed as the run went; nothing committed, no end record
        assert not (tmp_path / "run.jsonl").exists()
        partial = [json.loads(line) for line in (tmp_path / "run.jsonl.partial").read_text().splitlines()]
        assert [r["event"] for r in partial[:1]] == ["planning"]
        assert sum(r["event"] == "state" for r in partial) > 10
        assert all(r["event"] != "end" for r in partial)
        # the vehicles see the master's last will, drive on to the end of their base, and end
        gone = [json.loads(p) for _, topic, p in tap.messages if topic.endswith("/master/connection")]
        assert gone[-1]["connectionState"] == "CONNECTIONBROKEN"
        for code, _, said in vehicles.values():
            assert code == 1
            assert "the master is gone (CONNECTIONBROKEN)" in said
        return
    name = signal.Signals(how).name
    records = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert (tmp_path / "run.png").read_bytes().startswith(b"\x89PNG")
    assert not (tmp_path / "run.jsonl.partial").exists()
    assert records[-1]["outcome"] == "interrupted"
    stop = next(r for r in records if r["event"] == "stop")
    assert stop["reason"] == name
    assert sorted(stop["cancelled"]) == sorted(scenario.names)
    # nothing released after the stop: no order after it in the log, none on the broker after the cancels
    assert all(r["event"] != "order" for r in records[records.index(stop) :])
    cancels = [(t, json.loads(p)) for t, topic, p in tap.messages if topic.endswith("/instantActions")]
    assert {c["serialNumber"] for _, c in cancels} == set(scenario.names)
    assert all(a["actionType"] == "cancelOrder" for _, c in cancels for a in c["actions"])
    last_cancel = max(t for t, _ in cancels)
    assert not [t for t, topic, _ in tap.messages if topic.endswith("/order") and t > last_cancel]
    # each vehicle showed the cancel and stopped; its process ended saying so
    for serial in scenario.names:
        shown = [
            action["actionStatus"]
            for state in states.documents
            if state["serialNumber"] == serial
            for action in state["actionStates"]
            if action["actionType"] == "cancelOrder"
        ]
        assert shown[-1] == "FINISHED", shown
        assert states.last(serial)[2] is False  # at rest
        code, _, said = vehicles[serial]
        assert code == 1
        assert "its order was cancelled by the master" in said
    assert f"trajgen: master: stopped by {name}: nothing more released; cancelOrder sent to" in err
    assert "shown by agv1, agv2" in err
    assert "live run: interrupted" in out
    assert "Traceback" not in err
    assert closest_states(scenario, states) >= scenario.limits.min_separation - 1e-6
