"""The MQTT brokers of the live demonstration: amqtt in a thread, or mosquitto, behind one interface.

Each test runs against both kinds (``amqtt``, ``mosquitto``; the latter skipped where it is not
installed, unless ``TRAJGEN_TEST_REQUIRE_MOSQUITTO=1``, as in CI), with paho-mqtt 2.x clients on
their own network threads, as the vehicles and the master use them: a round trip, a last will on a
broken connection, clients that reconnect by themselves after a restart, a restart on the same
port, and a port of its own for each broker.
"""

from __future__ import annotations

import json
import os
import queue
import socket
import subprocess
import sys
import threading
import time
from logging import WARNING

import paho.mqtt.client as mqtt
import pytest

import trajgen.live.broker_base as broker_base
import trajgen.live.mosquitto as mosquitto_module
from tests.conftest import REPO
from trajgen.errors import InputError, LiveError
from trajgen.live.broker import (
    THREAD_NAME,
    EmbeddedBroker,
    MosquittoBroker,
    mosquitto_available,
)

pytestmark = pytest.mark.slow

KINDS = [
    pytest.param(EmbeddedBroker, id="amqtt"),
    pytest.param(
        MosquittoBroker,
        id="mosquitto",
        marks=pytest.mark.skipif(
            not mosquitto_available() and os.environ.get("TRAJGEN_TEST_REQUIRE_MOSQUITTO") != "1",
            reason="mosquitto is not installed",
        ),
    ),
]
#: Seconds a test waits for something the broker should do at once.
PATIENCE_S = 5.0


def wait_until(condition, what: str, timeout: float = PATIENCE_S) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"no {what} within {timeout:g} s"
        time.sleep(0.01)


def refuses_connections(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
    except ConnectionRefusedError:
        return True
    return False


class Peer:
    """A paho-mqtt 2.x client on its own network thread (``loop_start``), reconnecting by itself."""

    def __init__(self, broker, client_id: str, *, subscribe: str | None = None, will=None) -> None:
        self.topic = subscribe
        self.messages: queue.Queue[tuple[str, bytes]] = queue.Queue()
        self.sessions_present: list[bool] = []  # one per accepted connection
        self.subscriptions = 0
        self.drops = 0
        self.crashed = False
        self.client = mqtt.Client(
            mqtt.CallbackAPIVersion.VERSION2, client_id=client_id, protocol=mqtt.MQTTv311, clean_session=False
        )
        self.client.reconnect_delay_set(min_delay=0.05, max_delay=0.2)  # seconds; paho takes floats
        self.client.on_connect = self.on_connect
        self.client.on_subscribe = self.on_subscribe
        self.client.on_disconnect = self.on_disconnect
        self.client.on_message = self.on_message
        if will is not None:
            self.client.will_set(will[0], will[1], qos=1, retain=True)
        self.client.connect(broker.host, broker.port, keepalive=10)
        self.client.loop_start()
        wait_until(lambda: self.sessions_present, f"connection of {client_id}")
        if subscribe is not None:
            wait_until(lambda: self.subscriptions, f"subscription of {client_id}")

    def on_connect(self, client, userdata, flags, reason_code, properties) -> None:
        if not reason_code.is_failure:
            if self.topic is not None:  # again after every reconnection: the broker forgot
                client.subscribe(self.topic, qos=1)
            self.sessions_present.append(flags.session_present)

    def on_subscribe(self, client, userdata, mid, reason_codes, properties) -> None:
        self.subscriptions += 1

    def on_disconnect(self, client, userdata, flags, reason_code, properties) -> None:
        self.drops += 1

    def on_message(self, client, userdata, message) -> None:
        self.messages.put((message.topic, message.payload))

    def publish(self, topic: str, payload: bytes) -> None:
        self.client.publish(topic, payload, qos=1).wait_for_publish(PATIENCE_S)

    def receive(self) -> tuple[str, bytes]:
        return self.messages.get(timeout=PATIENCE_S)

    def crash(self) -> None:
        """End the network thread and close the socket without an MQTT DISCONNECT."""
        self.crashed = True
        self.client.loop_stop()
        self.client.socket().close()

    def close(self) -> None:
        if not self.crashed and self.client.is_connected():
            self.client.disconnect()
        self.client.loop_stop()
        sock = self.client.socket()
        if sock is not None:
            sock.close()
        # no reference cycle through the callbacks: the client is freed at once, and closes its
        # internal socket pair itself (freed by the garbage collector, the pair might go first)
        self.client.on_connect = self.client.on_subscribe = None
        self.client.on_disconnect = self.client.on_message = None


@pytest.fixture(params=KINDS)
def broker_class(request):
    return request.param


def complaints(caplog) -> list[str]:
    """Warnings and errors logged so far in this test (by amqtt, asyncio, ...): a stop must log none."""
    records = [*caplog.get_records("setup"), *caplog.get_records("call"), *caplog.records]
    return [f"{record.name}: {record.getMessage()}" for record in records if record.levelno >= WARNING]


@pytest.fixture
def broker(broker_class, caplog):
    broker = broker_class()
    with broker:
        yield broker
    assert not broker.running
    assert refuses_connections(broker.port)
    assert not [thread for thread in threading.enumerate() if thread.name == THREAD_NAME]
    assert complaints(caplog) == []


@pytest.fixture
def peers():
    """Make a :class:`Peer` with ``peers(broker, client_id, ...)``; all are closed at the end."""
    made: list[Peer] = []

    def make(*args, **kwargs) -> Peer:
        made.append(Peer(*args, **kwargs))
        return made[-1]

    yield make
    for peer in made:
        peer.close()


def test_a_message_goes_round(broker, peers):
    assert broker.running
    assert broker.host == "127.0.0.1"
    assert broker.url == f"mqtt://127.0.0.1:{broker.port}"
    listener = peers(broker, "listener", subscribe="trajgen/test/#")
    talker = peers(broker, "talker")
    talker.publish("trajgen/test/order", b'{"orderId": "o1"}')
    assert listener.receive() == ("trajgen/test/order", b'{"orderId": "o1"}')


def test_the_will_is_published_when_a_connection_breaks_without_disconnect(broker, peers):
    listener = peers(broker, "listener", subscribe="trajgen/test/+/connection")
    polite = peers(broker, "polite", will=("trajgen/test/polite/connection", b"BROKEN"))
    vehicle = peers(broker, "vehicle", will=("trajgen/test/vehicle/connection", b"CONNECTIONBROKEN"))
    polite.close()  # an MQTT DISCONNECT: no will
    vehicle.crash()
    assert listener.receive() == ("trajgen/test/vehicle/connection", b"CONNECTIONBROKEN")
    time.sleep(0.2)
    assert listener.messages.empty()


def test_clients_reconnect_by_themselves_after_a_restart(broker, peers):
    listener = peers(broker, "listener", subscribe="trajgen/test/#")
    talker = peers(broker, "talker")
    talker.publish("trajgen/test/state", b"before")
    assert listener.receive() == ("trajgen/test/state", b"before")
    port = broker.port
    broker.restart(down_for=0.3)
    assert broker.running
    assert broker.port == port
    wait_until(lambda: listener.drops == 1 and talker.drops == 1, "dropped connections")
    wait_until(lambda: len(listener.sessions_present) == 2 and listener.subscriptions == 2, "resubscription")
    wait_until(lambda: len(talker.sessions_present) == 2, "reconnection")
    # the restart forgot every session, though the clients asked to keep theirs
    assert listener.sessions_present == talker.sessions_present == [False, False]
    talker.publish("trajgen/test/state", b"after")
    assert listener.receive() == ("trajgen/test/state", b"after")


def test_a_broker_starts_again_on_its_port_after_a_stop(broker, peers):
    port = broker.port
    assert broker.start() is broker  # started already: nothing happens
    broker.stop()
    broker.stop()  # stopped already: nothing happens
    assert not broker.running
    assert refuses_connections(port)
    assert broker.start() is broker
    assert broker.running
    assert broker.port == port
    listener = peers(broker, "listener", subscribe="trajgen/test/#")
    peers(broker, "talker").publish("trajgen/test/again", b"1")
    assert listener.receive() == ("trajgen/test/again", b"1")


def test_a_stop_closes_every_connection_also_one_that_never_said_connect(broker, peers):
    peer = peers(broker, "vehicle")
    silent = socket.create_connection((broker.host, broker.port), timeout=PATIENCE_S)
    with silent:
        time.sleep(0.1)  # the broker has accepted it and waits for its CONNECT
        broker.stop()
        assert silent.recv(1) == b""  # closed by the broker
    wait_until(lambda: peer.drops == 1, "dropped connection")
    assert not peer.client.is_connected()


def test_two_brokers_get_ports_of_their_own(broker, broker_class, peers):
    with broker_class() as other:
        assert other.port != broker.port
        listener = peers(broker, "listener", subscribe="trajgen/test/#")
        other_listener = peers(other, "listener", subscribe="trajgen/test/#")
        peers(other, "talker").publish("trajgen/test/which", b"other")
        assert other_listener.receive() == ("trajgen/test/which", b"other")
        time.sleep(0.1)
        assert listener.messages.empty()
    assert not other.running


def test_a_taken_port_is_a_live_error_naming_it(broker_class, monkeypatch):
    monkeypatch.setattr(broker_base, "REBIND_TIMEOUT_S", 0.2)  # how long it waits is not the point here
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        broker = broker_class(port=port)
        with pytest.raises(
            LiveError, match=rf"cannot listen on 127.0.0.1:{port}: .* \(still so after 0.2 s\)"
        ):
            broker.start()
    assert not broker.running
    assert not [thread for thread in threading.enumerate() if thread.name == THREAD_NAME]


def test_a_missing_mosquitto_is_a_live_error_saying_so(monkeypatch):
    monkeypatch.setattr(MosquittoBroker, "executable", staticmethod(lambda: None))
    with pytest.raises(LiveError, match=r"mosquitto is not installed .*expected the mosquitto broker"):
        MosquittoBroker().start()


def test_mosquitto_is_found_in_sbin_when_the_path_lacks_it(monkeypatch, tmp_path):
    fake = tmp_path / "mosquitto"
    fake.write_text("#!/bin/sh\n", encoding="utf-8")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.setattr(mosquitto_module, "MOSQUITTO_FOLDERS", (str(tmp_path),))
    assert MosquittoBroker.executable() == str(fake)
    assert mosquitto_available()
    monkeypatch.setattr(mosquitto_module, "MOSQUITTO_FOLDERS", ())
    assert MosquittoBroker.executable() is None
    assert not mosquitto_available()


@pytest.mark.parametrize("port", [0, 65536, -1, 1883.0, "1883", True])
def test_a_bad_port_is_an_input_error(port):
    with pytest.raises(InputError, match="broker port"):
        EmbeddedBroker(port=port)


@pytest.mark.parametrize("down_for", [-0.1, float("nan"), "1"])
def test_a_bad_down_time_is_an_input_error(down_for):
    broker = EmbeddedBroker()
    with pytest.raises(InputError, match="down_for"):
        broker.restart(down_for=down_for)
    assert not broker.running


def test_importing_the_module_loads_neither_amqtt_nor_paho():
    code = "import json, sys, trajgen.live.broker\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True, timeout=60
    )
    loaded = {name.split(".")[0] for name in json.loads(done.stdout)}
    assert not loaded & {"amqtt", "paho", "transitions", "websockets"}
