"""What the live tests share: a broker, a tap on every message, run settings, serve with vehicle processes."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from collections.abc import Callable

from trajgen.cli import main
from trajgen.export.vda5050.graph_path import point_id
from trajgen.live.broker import EmbeddedBroker, MosquittoBroker, mosquitto_available
from trajgen.live.geometry import track_position
from trajgen.live.mqtt import BrokerSettings, make_client
from trajgen.live.places import snapshot_point
from trajgen.scenario import GraphScenario

#: Time scale, state rate (Hz of the run), control period (s) and node spacing (m) of the runs
#: that check behaviour under faults: ~100 messages/s through amqtt (a node every metre).
FAST = {"time_scale": 25.0, "state_rate": 1.0, "period": 0.02, "spacing": 1.0}
#: Wall seconds a message may take through the broker here (a state, then the update it allows).
HOP_S = 0.02


def trajgen_process(*arguments: str) -> subprocess.Popen:
    """``python -m trajgen ARGUMENTS`` as a process of its own, its output captured as text."""
    return subprocess.Popen(
        [sys.executable, "-m", "trajgen", *arguments],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def new_broker():
    """The broker of a test: mosquitto when it is installed, else amqtt in this process."""
    return MosquittoBroker() if mosquitto_available() else EmbeddedBroker()


class Tap:
    """Every message on the broker, as a third client sees it: ``(wall time, topic, payload)``."""

    def __init__(self, url: str) -> None:
        self.messages: list[tuple[float, str, bytes]] = []
        self._ready = threading.Event()
        self._client = make_client(BrokerSettings.from_url(url), f"tap-{id(self):x}")
        self._client.on_connect = lambda client, *_: (client.subscribe("uagv/#", qos=0), self._ready.set())
        self._client.on_message = lambda client, userdata, m: self.messages.append(
            (time.monotonic(), m.topic, bytes(m.payload))
        )
        settings = BrokerSettings.from_url(url)
        self._client.connect(settings.host, settings.port)
        self._client.loop_start()
        assert self._ready.wait(5.0)
        time.sleep(0.1)  # the subscription is in place

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()

    def of(self, kind: str) -> list[dict]:
        return [json.loads(p) for _, topic, p in self.messages if topic.endswith("/" + kind)]


def serve_with_vehicle_processes(
    scenario: str, common: list[str], *, vehicle: list[str], serve: list[str]
) -> tuple[int, list[tuple[str, str]], list[subprocess.Popen]]:
    """``trajgen serve`` in this process driving a ``trajgen vehicle`` process per vehicle.

    ``common``: the broker options of all three; ``vehicle``, ``serve``: each command's own. The
    vehicles start 2 s before the master. Returns serve's exit status, each vehicle's
    ``(stdout, stderr)`` and the vehicle processes (ended).
    """
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "trajgen", "vehicle", scenario, name, *common, *vehicle],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for name in ("agv1", "agv2")
    ]
    time.sleep(2.0)
    try:
        status = main(["serve", scenario, *common, *serve])
    finally:
        outputs = [p.communicate(timeout=30) for p in processes]
    return status, outputs, processes


def logged_serve(folder, *, method: str = "exact") -> list[str]:
    """``trajgen serve`` options of a test run: its plan's method, a run log and picture in ``folder``."""
    log, picture = str(folder / "run.jsonl"), str(folder / "run.png")
    return ["--method", method, "--log", log, "--plot", picture, "--timeout", "300", "--json"]


class States:
    """Every state the vehicles publish, as a third client sees them: ``(serial, place, driving)``.

    Also every state as it came (:attr:`documents`), for what else it says (its action states).

    ``place_of``: where a state puts its vehicle on the track (from its x/y, or its nodes).
    """

    def __init__(self, url: str, place_of: Callable[[dict], object]) -> None:
        self.seen: list[tuple[str, object, bool]] = []
        self.documents: list[dict] = []
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
            self.documents.append(state)

    def last(self, serial: str):
        with self._lock:
            return next((s for s in reversed(self.seen) if s[0] == serial), None)

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


def place_reader(scenario) -> tuple[Callable[[dict], object], Callable[[object], str]]:
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


def closest_states(scenario, states: States) -> float:
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
