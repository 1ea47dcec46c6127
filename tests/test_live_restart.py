"""A vehicle process killed mid-run and restarted where it stood: the run completes (issue 35, item 4).

The master, the two vehicles and the broker run as separate processes, as in a plant; agv1 is
killed with SIGKILL (no OFFLINE: the broker sends its last will) while it drives, and started again
a second later with ``--start`` at the place it last reported. The master takes its new session
(its ``headerId`` counting from 1 again), holds agv2 at its released base, re-plans from where
both stand and completes the run; no two states of the vehicles were closer than the separation.

On a junction a vehicle reports its map x/y; on a track graph (issue 37) its last node and the
distance past it, a place on the track; restarted there it reports that place as its node, and its
new order numbers its nodes from 0, as a new order does.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable

import pytest

from tests.conftest import REPO
from tests.support.live import new_broker
from trajgen.export.vda5050.graph_path import point_id
from trajgen.live.geometry import track_position
from trajgen.live.mqtt import BrokerSettings, make_client
from trajgen.live.places import snapshot_point
from trajgen.scenario import GraphScenario, load_scenario

SWAP = str(REPO / "examples" / "swap.toml")
H = str(REPO / "examples" / "graphs" / "h.toml")
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
    """Every state the vehicles publish, as a third client sees them: ``(serial, place, driving)``.

    ``place_of``: where a state puts its vehicle on the track (from its x/y, or its nodes).
    """

    def __init__(self, url: str, place_of: Callable[[dict], object]) -> None:
        self.seen: list[tuple[str, object, bool]] = []
        self._place_of = place_of
        self._lock = threading.Lock()
        settings = BrokerSettings.from_url(url)
        self._client = make_client(settings, f"states-{id(self):x}")
        self._client.on_connect = lambda client, *_: client.subscribe("uagv/v2/+/+/state")
        self._client.on_message = self._take
        self._client.connect(settings.host, settings.port)
        self._client.loop_start()

    def _take(self, client, userdata, message) -> None:
        state = json.loads(message.payload)
        place = self._place_of(state)
        with self._lock:
            self.seen.append((state["serialNumber"], place, state["driving"]))

    def last(self, serial: str):
        with self._lock:
            return next((s for s in reversed(self.seen) if s[0] == serial), None)

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


def _place_reader(scenario) -> tuple[Callable[[dict], object], Callable[[object], str]]:
    """How a state places its vehicle on ``scenario``'s track, and how ``--start`` writes a place."""
    track = scenario.track
    if isinstance(scenario, GraphScenario):

        def on_graph(state: dict):
            upcoming = state.get("nodeStates") or []
            following = upcoming[0]["nodeId"] if upcoming else ""
            return snapshot_point(
                track, state["lastNodeId"], following, state.get("distanceSinceLastNode") or 0.0
            )

        return on_graph, lambda place: point_id(track, place)

    def on_junction(state: dict):
        position = state.get("agvPosition")
        return None if position is None else track_position(track, position["x"], position["y"])

    return on_junction, lambda place: f"{place.leg}:{place.s:.6f}"


def _run_with_a_restart(path: str, method: str, log) -> tuple[dict, list[dict], States, object]:
    """Serve ``path`` to two vehicle processes, kill agv1 while it drives and restart it where it stood.

    Returns serve's JSON summary, the run log's records, every state seen and where agv1 restarted.
    """
    scenario = load_scenario(path)
    place_of, start_text = _place_reader(scenario)
    broker = new_broker().start()
    states = States(broker.url, place_of)
    common = ["--broker", broker.url, "--time-scale", f"{SCALE:g}"]
    vehicle = ["--exit-at-goal", "--timeout", "600"]
    processes = {name: _trajgen("vehicle", path, name, *common, *vehicle) for name in scenario.names}
    serve = _trajgen(
        "serve", path, *common, "--method", method, "--json", "--log", str(log), "--timeout", "600"
    )
    try:
        deadline = time.monotonic() + 60.0
        while not (states.last("agv1") and states.last("agv1")[2]):  # agv1 drives
            assert time.monotonic() < deadline, "agv1 never drove"
            time.sleep(0.05)
        time.sleep(1.0)
        os.kill(processes["agv1"].pid, signal.SIGKILL)
        processes["agv1"].wait(10)
        time.sleep(0.3)
        here = states.last("agv1")[1]
        time.sleep(0.7)  # a second after the kill
        processes["agv1"] = _trajgen("vehicle", path, "agv1", *common, "--start", start_text(here), *vehicle)
        out, err = serve.communicate(timeout=240)
    finally:
        for process in [serve, *processes.values()]:
            if process.poll() is None:
                process.kill()
        states.close()
        broker.stop()
    assert serve.returncode == 0, err
    records = [json.loads(line) for line in log.read_text().splitlines()]
    return json.loads(out), records, states, here


def _closest_states(scenario, states: States) -> float:
    """The least track distance between each vehicle's latest reported place, at every state."""
    latest: dict[str, object] = {}
    closest = float("inf")
    for serial, place, _ in states.seen:
        if place is None:
            continue
        latest[serial] = place
        if len(latest) == 2:
            closest = min(closest, scenario.track.distance(*(latest[name] for name in scenario.names)))
    return closest


@pytest.mark.parametrize(
    ("path", "method"),
    [(SWAP, "exact"), (SWAP, "optimal"), (H, "exact")],
    ids=["swap-exact", "swap-optimal", "h-exact"],
)
def test_a_vehicle_killed_and_restarted_where_it_stood_completes_the_run_safely(path, method, tmp_path):
    scenario = load_scenario(path)
    summary, records, states, here = _run_with_a_restart(path, method, tmp_path / "run.jsonl")
    assert summary["outcome"] == "goals-reached"
    assert summary["replans"] == 1
    restarts = [r for r in records if r["event"] == "restart"]
    assert [r["vehicle"] for r in restarts] == ["agv1"]
    assert not [r for r in records if r["event"] == "ignored"], "the new session's states were all taken"
    if isinstance(scenario, GraphScenario):  # placed by the node it reports: the place it restarted at
        assert restarts[0]["at"] == point_id(scenario.track, here)
        for serial, goal in zip(scenario.names, scenario.goal, strict=True):
            assert states.last(serial)[1] == goal
    closest = _closest_states(scenario, states)
    assert closest >= scenario.limits.min_separation - STATE_SKEW_M
    print(
        f"restart ({method}): makespan {summary['makespan_s']:.2f} s of the run against a plan of "
        f"{summary['planned_s']:.2f} s; closest states {closest:.3f} m"
    )
