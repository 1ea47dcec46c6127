"""A vehicle process killed mid-run and restarted where it stood: the run completes (issue 35, item 4).

The master, the two vehicles and the broker run as separate processes, as in a plant; agv1 is
killed with SIGKILL (no OFFLINE: the broker sends its last will) while it drives, and started again
a second later with ``--start`` at the position it last reported. The master takes its new session
(its ``headerId`` counting from 1 again), holds agv2 at its released base, re-plans from where
both stand and completes the run; no two states of the vehicles were closer than the separation.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from tests.conftest import REPO
from trajgen.live.broker import EmbeddedBroker, MosquittoBroker, mosquitto_available
from trajgen.live.geometry import track_position
from trajgen.live.mqtt import BrokerSettings, make_client
from trajgen.scenario import load_scenario

SWAP = str(REPO / "examples" / "swap.toml")
SCALE = 5.0
#: Metres two states may lag each other by (a state per 0.1 s of the run, 2 m/s between them).
STATE_SKEW_M = 0.25


def _trajgen(*arguments: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "trajgen", *arguments],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


class States:
    """Every state the vehicles publish, as a third client sees them: ``(serial, x, y, driving)``."""

    def __init__(self, url: str) -> None:
        self.seen: list[tuple[str, float, float, bool]] = []
        self._lock = threading.Lock()
        settings = BrokerSettings.from_url(url)
        self._client = make_client(settings, f"states-{id(self):x}")
        self._client.on_connect = lambda client, *_: client.subscribe("uagv/v2/+/+/state")
        self._client.on_message = self._take
        self._client.connect(settings.host, settings.port)
        self._client.loop_start()

    def _take(self, client, userdata, message) -> None:
        state = json.loads(message.payload)
        position = state.get("agvPosition") or {}
        with self._lock:
            self.seen.append((state["serialNumber"], position.get("x"), position.get("y"), state["driving"]))

    def last(self, serial: str):
        with self._lock:
            return next((s for s in reversed(self.seen) if s[0] == serial), None)

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


@pytest.mark.parametrize("method", ["exact", "optimal"])
def test_a_vehicle_killed_and_restarted_where_it_stood_completes_the_run_safely(method, tmp_path):
    scenario = load_scenario(SWAP)
    graph = scenario.track
    broker = (MosquittoBroker() if mosquitto_available() else EmbeddedBroker()).start()
    states = States(broker.url)
    common = ["--broker", broker.url, "--time-scale", f"{SCALE:g}"]
    processes = {
        name: _trajgen("vehicle", SWAP, name, *common, "--exit-at-goal", "--timeout", "600")
        for name in scenario.names
    }
    log = tmp_path / "run.jsonl"
    serve = _trajgen(
        "serve", SWAP, *common, "--method", method, "--json", "--log", str(log), "--timeout", "600"
    )
    try:
        deadline = time.monotonic() + 60.0
        while not (states.last("agv1") and states.last("agv1")[3]):  # agv1 drives
            assert time.monotonic() < deadline, "agv1 never drove"
            time.sleep(0.05)
        time.sleep(1.0)
        os.kill(processes["agv1"].pid, signal.SIGKILL)
        processes["agv1"].wait(10)
        time.sleep(0.3)
        _, x, y, _ = states.last("agv1")
        here = track_position(graph, x, y)
        time.sleep(0.7)  # a second after the kill
        processes["agv1"] = _trajgen(
            "vehicle",
            SWAP,
            "agv1",
            *common,
            "--start",
            f"{here.leg}:{here.s:.6f}",
            "--exit-at-goal",
            "--timeout",
            "600",
        )
        out, err = serve.communicate(timeout=240)
    finally:
        for process in [serve, *processes.values()]:
            if process.poll() is None:
                process.kill()
        states.close()
        broker.stop()
    assert serve.returncode == 0, err
    summary = json.loads(out)
    assert summary["outcome"] == "goals-reached"
    assert summary["replans"] == 1
    records = [json.loads(line) for line in log.read_text().splitlines()]
    restarts = [r for r in records if r["event"] == "restart"]
    assert [r["vehicle"] for r in restarts] == ["agv1"]
    assert not [r for r in records if r["event"] == "ignored"], "the new session's states were all taken"
    # no two states (each vehicle's latest at every state) closer than the separation
    latest: dict[str, tuple[float, float]] = {}
    closest = float("inf")
    for serial, x, y, _ in states.seen:
        if x is None:
            continue
        latest[serial] = (x, y)
        if len(latest) == 2:
            a, b = (track_position(graph, *latest[name]) for name in scenario.names)
            closest = min(closest, graph.distance(a, b))
    assert closest >= scenario.limits.min_separation - STATE_SKEW_M
    print(
        f"restart: makespan {summary['makespan_s']:.2f} s of the run against a plan of "
        f"{summary['planned_s']:.2f} s; closest states {closest:.3f} m"
    )


def test_a_vehicle_killed_on_the_h_and_restarted_where_it_stood_completes_the_run_safely(tmp_path):
    """A vehicle on a track graph killed mid-run and restarted where it stood: the run completes.

    It says where it is by its last node and the distance past it; restarted there (``--start
    EDGE:s``), it reports that place as its node, and the master re-plans from it (its new order
    numbered from 0, as a new order is).
    """
    from trajgen.export.vda5050.graph_path import point_id
    from trajgen.live.places import snapshot_point

    h = str(REPO / "examples" / "graphs" / "h.toml")
    scenario = load_scenario(h)
    track = scenario.track
    broker = (MosquittoBroker() if mosquitto_available() else EmbeddedBroker()).start()
    places: dict[str, list] = {"agv1": [], "agv2": []}
    seen: list = []  # (serial, place) in the order heard
    settings = BrokerSettings.from_url(broker.url)
    watcher = make_client(settings, "graph-states")
    watcher.on_connect = lambda client, *_: client.subscribe("uagv/v2/+/+/state")

    def take(client, userdata, message):
        state = json.loads(message.payload)
        upcoming = state.get("nodeStates") or []
        place = snapshot_point(
            track,
            state["lastNodeId"],
            upcoming[0]["nodeId"] if upcoming else "",
            state.get("distanceSinceLastNode") or 0.0,
        )
        places[state["serialNumber"]].append((place, state["driving"]))
        seen.append((state["serialNumber"], place))

    watcher.on_message = take
    watcher.connect(settings.host, settings.port)
    watcher.loop_start()
    common = ["--broker", broker.url, "--time-scale", f"{SCALE:g}"]
    processes = {
        name: _trajgen("vehicle", h, name, *common, "--exit-at-goal", "--timeout", "600")
        for name in scenario.names
    }
    log = tmp_path / "run.jsonl"
    serve = _trajgen(
        "serve", h, *common, "--method", "exact", "--json", "--log", str(log), "--timeout", "600"
    )
    try:
        deadline = time.monotonic() + 60.0
        while not (places["agv1"] and places["agv1"][-1][1]):  # agv1 drives
            assert time.monotonic() < deadline, "agv1 never drove"
            time.sleep(0.05)
        time.sleep(1.0)
        os.kill(processes["agv1"].pid, signal.SIGKILL)
        processes["agv1"].wait(10)
        time.sleep(0.3)
        here = places["agv1"][-1][0]
        time.sleep(0.7)
        processes["agv1"] = _trajgen(
            "vehicle",
            h,
            "agv1",
            *common,
            "--start",
            point_id(track, here),
            "--exit-at-goal",
            "--timeout",
            "600",
        )
        out, err = serve.communicate(timeout=240)
    finally:
        for process in [serve, *processes.values()]:
            if process.poll() is None:
                process.kill()
        watcher.disconnect()
        watcher.loop_stop()
        broker.stop()
    assert serve.returncode == 0, err
    summary = json.loads(out)
    assert summary["outcome"] == "goals-reached"
    assert summary["replans"] == 1
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert [(r["vehicle"], r["at"]) for r in records if r["event"] == "restart"] == [
        ("agv1", point_id(track, here))
    ]
    assert not [r for r in records if r["event"] == "ignored"], "the new session's states were all taken"
    assert places["agv1"][-1][0] == track.point("D")
    assert places["agv2"][-1][0] == track.point("A")
    # each vehicle's latest reported place at every state: never closer than the separation
    latest: dict[str, object] = {}
    closest = float("inf")
    for serial, place in seen:
        latest[serial] = place
        if len(latest) == 2:
            closest = min(closest, track.distance(latest["agv1"], latest["agv2"]))
    assert closest >= scenario.limits.min_separation - STATE_SKEW_M
    print(
        f"restart on the H: makespan {summary['makespan_s']:.2f} s of the run; closest states {closest:.3f} m"
    )
