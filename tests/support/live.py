"""What the live tests share: a broker, a tap on every message, run settings, serve with vehicle processes."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time

from trajgen.cli import main
from trajgen.live.broker import EmbeddedBroker, MosquittoBroker, mosquitto_available
from trajgen.live.mqtt import BrokerSettings, make_client

#: Time scale, state rate (Hz of the run), control period (s) and node spacing (m) of the runs
#: that check behaviour under faults: ~100 messages/s through amqtt (a node every metre).
FAST = {"time_scale": 25.0, "state_rate": 1.0, "period": 0.02, "spacing": 1.0}
#: Wall seconds a message may take through the broker here (a state, then the update it allows).
HOP_S = 0.02


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
