"""Live runs against mosquitto with a login and with TLS (a CA made in the test): issue 35.

A failure that retrying cannot mend (a wrong password, no username, an untrusted certificate, TLS
spoken to a plain listener, a plain client on a TLS listener) ends ``serve`` and ``vehicle`` within
seconds with exit 1 and one plain ``trajgen: error:`` line, never as an "internal failure"; the
right login and the right CA connect.
"""

from __future__ import annotations

import getpass
import os
import re
import socket
import subprocess
import time

import pytest

from tests.conftest import REPO
from trajgen.cli import main
from trajgen.live.broker import MosquittoBroker, mosquitto_available
from trajgen.live.clock import RunClock
from trajgen.live.mqtt import BrokerSettings, VehicleIdentity
from trajgen.live.outcome import LiveOutcome
from trajgen.live.vehicle import SimulatedVehicle
from trajgen.scenario import load_scenario

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        not mosquitto_available() and os.environ.get("TRAJGEN_TEST_REQUIRE_MOSQUITTO") != "1",
        reason="mosquitto is not installed",
    ),
]

SWAP = str(REPO / "examples" / "swap.toml")
#: The issue's bound: a plain message within 10 s.
PLAIN_WITHIN_S = 10.0


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class ConfiguredMosquitto:
    """mosquitto with the given configuration lines after ``listener PORT 127.0.0.1``."""

    def __init__(self, folder, lines: list[str]) -> None:
        self.port = _free_port()
        self.folder = folder
        config = folder / "mosquitto.conf"
        # run as root, mosquitto would become user "mosquitto", who cannot read the test's files
        head = [f"user {getpass.getuser()}", f"listener {self.port} 127.0.0.1"]
        config.write_text("\n".join([*head, *lines]) + "\n", encoding="utf-8")
        self._log = open(folder / "mosquitto.log", "wb")  # noqa: SIM115 - closed in stop
        self.process = subprocess.Popen(
            [MosquittoBroker.executable(), "-c", str(config)], stdout=self._log, stderr=self._log
        )
        deadline = time.monotonic() + 10.0
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=0.2).close()
                return
            except OSError:
                if time.monotonic() > deadline or self.process.poll() is not None:
                    self.stop()
                    raise RuntimeError((folder / "mosquitto.log").read_text()) from None
                time.sleep(0.05)

    def stop(self) -> None:
        self.process.terminate()
        self.process.wait(5)
        self._log.close()


@pytest.fixture
def login_broker(tmp_path):
    """Mosquitto that lets in user ``agv`` with password ``right`` only."""
    passwords = tmp_path / "passwords"
    subprocess.run(["mosquitto_passwd", "-c", "-b", str(passwords), "agv", "right"], check=True)
    passwords.chmod(0o600)
    broker = ConfiguredMosquitto(tmp_path, ["allow_anonymous false", f"password_file {passwords}"])
    yield broker
    broker.stop()


@pytest.fixture
def certificates(tmp_path):
    """A CA made here, a server certificate it signed for 127.0.0.1, and another CA's file."""
    trustme = pytest.importorskip("trustme")
    authority = trustme.CA()
    server = authority.issue_cert("127.0.0.1")
    files = {name: tmp_path / f"{name}.pem" for name in ("ca", "cert", "key", "other-ca")}
    authority.cert_pem.write_to_path(str(files["ca"]))
    server.private_key_pem.write_to_path(str(files["key"]))
    for blob in server.cert_chain_pems:
        blob.write_to_path(str(files["cert"]), append=True)
    trustme.CA().cert_pem.write_to_path(str(files["other-ca"]))
    return files


@pytest.fixture
def tls_broker(tmp_path, certificates):
    broker = ConfiguredMosquitto(
        tmp_path,
        [
            "allow_anonymous true",
            f"cafile {certificates['ca']}",
            f"certfile {certificates['cert']}",
            f"keyfile {certificates['key']}",
        ],
    )
    yield broker
    broker.stop()


def _password_file(tmp_path, password: str) -> str:
    path = tmp_path / f"password-{password}"
    path.write_text(password + "\n", encoding="utf-8")
    return str(path)


def _run(command: str, broker_arguments: list[str], tmp_path) -> tuple[int, float]:
    if command == "serve":
        argv = ["serve", SWAP, "--method", "exact", "--timeout", "30", "--log", str(tmp_path / "run.jsonl")]
    else:
        argv = ["vehicle", SWAP, "agv1", "--timeout", "30"]
    began = time.monotonic()
    status = main([*argv, *broker_arguments])
    return status, time.monotonic() - began


CASES = {
    "wrong-password": ("login", ["--username", "agv", "--password", "wrong"], "refused the login"),
    "no-username": ("login", [], "refused the login"),
    "wrong-ca": ("tls", ["--tls", "--cafile", "other-ca"], "is not trusted"),
    "plain-on-tls": ("tls", [], "closed the connection without answering"),
    "tls-on-plain": ("plain", ["--tls", "--cafile", "ca"], "during the TLS handshake"),
}


@pytest.mark.parametrize("command", ["serve", "vehicle"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_a_connection_that_cannot_work_ends_in_seconds_with_a_plain_error(
    case, command, request, tmp_path, capsys, certificates
):
    kind, options, expected = CASES[case]
    if kind == "plain":
        broker = MosquittoBroker().start()
        request.addfinalizer(broker.stop)
        port = broker.port
    else:
        broker = request.getfixturevalue("login_broker" if kind == "login" else "tls_broker")
        port = broker.port
    arguments = ["--broker", f"mqtt://127.0.0.1:{port}"]
    for option in options:
        if option in certificates:
            arguments.append(str(certificates[option]))
        elif option == "--password":
            arguments.append("--password-file")
        elif arguments[-1] == "--password-file":
            arguments.append(_password_file(tmp_path, option))
        else:
            arguments.append(option)
    status, seconds = _run(command, arguments, tmp_path)
    err = capsys.readouterr().err
    assert status == 1, err
    assert seconds < PLAIN_WITHIN_S, f"{seconds:.1f} s"
    print(f"{case}, {command}: exit 1 in {seconds:.2f} s: {err.strip().splitlines()[-1]}")
    assert expected in err, err
    assert "trajgen: error: " in err
    assert "internal failure" not in err
    assert "Traceback" not in err
    if command == "serve":  # the run's log is committed, saying why it ended
        assert (tmp_path / "run.jsonl").exists()


def _vehicle(settings: BrokerSettings) -> SimulatedVehicle:
    scenario = load_scenario(SWAP)
    return SimulatedVehicle(
        VehicleIdentity("unspecified", "agv1"),
        scenario.limits.vehicles[0],
        (0.0, 0.0),
        broker=settings,
        clock=RunClock(1.0),
    )


def _connects(vehicle: SimulatedVehicle) -> bool:
    vehicle.start()
    try:
        deadline = time.monotonic() + PLAIN_WITHIN_S
        while time.monotonic() < deadline and not vehicle.link.connected:
            time.sleep(0.05)
        return vehicle.link.connected
    finally:
        vehicle.stop()


def test_the_right_login_connects(login_broker, tmp_path):
    settings = BrokerSettings.from_url(
        f"mqtt://127.0.0.1:{login_broker.port}",
        username="agv",
        password_file=_password_file(tmp_path, "right"),
    )
    assert _connects(_vehicle(settings))


def test_tls_with_the_right_ca_connects(tls_broker, certificates):
    settings = BrokerSettings.from_url(f"mqtts://127.0.0.1:{tls_broker.port}", cafile=certificates["ca"])
    assert _connects(_vehicle(settings))


#: Seconds within which an order the broker drops is reported for every vehicle (a vehicle's 4 sends
#: take about 4 s; the rest is room for a loaded machine, where a CI run saw 5 s not enough).
REPORTED_WITHIN_S = 15.0


def test_an_acl_that_forbids_the_masters_orders_is_reported_within_seconds_naming_each_vehicle(tmp_path):
    from tests.support.helpers import execution_plan, scenario_vehicle
    from trajgen.live.master import LiveMaster
    from trajgen.live.session import identities

    passwords = tmp_path / "passwords"
    for number, user in enumerate(("master", "agv1", "agv2")):
        flags = ["-c"] if number == 0 else []
        subprocess.run(["mosquitto_passwd", *flags, "-b", str(passwords), user, "right"], check=True)
    acl = tmp_path / "acl"
    acl.write_text(  # the master may read, not order: its publishes are dropped by the broker
        "user master\ntopic read uagv/#\npattern readwrite uagv/v2/+/%u/#\n", encoding="utf-8"
    )
    broker = ConfiguredMosquitto(
        tmp_path, ["allow_anonymous false", f"password_file {passwords}", f"acl_file {acl}"]
    )
    scenario, verified = execution_plan("swap", "exact")
    ids = identities(scenario.names)
    password = _password_file(tmp_path, "right")
    url = f"mqtt://127.0.0.1:{broker.port}"

    def login(user: str) -> BrokerSettings:
        return BrokerSettings.from_url(url, username=user, password_file=password)

    clock = RunClock(1.0)
    vehicles = [
        scenario_vehicle(scenario, v, ids[v], broker=login(ids[v].serial_number), clock=clock).start()
        for v in (0, 1)
    ]
    master = LiveMaster(
        scenario, plan=verified, identities=ids, broker=login("master"), clock=clock, give_up_after=6.0
    )
    began = time.monotonic()
    master.start()
    try:
        # 4 sends on a back-off driven by the states: about 4 s each, later on a loaded machine
        while time.monotonic() - began < REPORTED_WITHIN_S:
            reported = {r["vehicle"] for r in master.log.records() if r["event"] == "order-not-taken"}
            if reported == set(scenario.names):
                break
            time.sleep(0.05)
        seconds = time.monotonic() - began
        ended = master.wait(timeout=30.0)  # nothing changes: the run ends with its status
        run = master.result()
    finally:
        master.stop()
        for vehicle in vehicles:
            vehicle.stop()
        broker.stop()
    assert reported == set(scenario.names)
    assert seconds < REPORTED_WITHIN_S
    records = [r for r in master.log.records() if r["event"] == "order-not-taken"]
    assert all(r["reports"] == "no order" for r in records)
    assert ended
    assert run.outcome is LiveOutcome.ORDER_NOT_TAKEN
    assert re.match(
        r"master: agv[12] has not taken its order in 6 s of re-sends \(it reports no order\)", run.error
    )


def test_a_refused_login_is_said_while_the_plan_is_still_being_made(
    login_broker, tmp_path, capsys, monkeypatch
):
    """Issue 48, item 4: serve connects and plans at once; a wrong password does not wait for the plan."""
    import trajgen.live.coordinator as coordinator

    planned = coordinator.schedule_for_execution

    def slow_plan(scenario, *, method=None):
        time.sleep(20.0)  # far longer than a connection takes
        return planned(scenario, method=method)

    monkeypatch.setattr(coordinator, "schedule_for_execution", slow_plan)
    password = _password_file(tmp_path, "wrong")
    arguments = ["--broker", f"mqtt://127.0.0.1:{login_broker.port}", "--username", "agv"]
    status, seconds = _run("serve", [*arguments, "--password-file", password], tmp_path)
    captured = capsys.readouterr()
    assert status == 1
    assert seconds < 5.0, f"{seconds:.1f} s"  # not after the 20 s of planning
    assert "refused the login" in captured.err
    assert "no plan made yet" in captured.out
    assert captured.err.count("trajgen: error:") == 1  # said once
