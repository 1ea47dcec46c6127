"""The broker section of docs/live.md runs as written: amqtt, mosquitto with logins and an ACL, TLS.

Its ``sh`` blocks (between the ``broker-commands`` markers) run in order in a temporary folder
beside a copy of ``examples/``, with ``PORT`` and ``TLS_PORT`` set to free ports: amqtt starts
and answers; mosquitto with passwords and the ACL carries a whole ``serve`` run of two logged-in
vehicles; a vehicle connects over TLS to a listener whose certificate a CA made by the commands
signed. Run as root, mosquitto would switch to the user ``mosquitto``, who cannot read the test's
files: a shim on the ``PATH`` adds ``user root`` to its configuration then.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import REPO
from trajgen.live.broker import MosquittoBroker, mosquitto_available

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        not mosquitto_available() and os.environ.get("TRAJGEN_TEST_REQUIRE_MOSQUITTO") != "1",
        reason="mosquitto is not installed",
    ),
]

PAGE = REPO / "docs" / "live.md"


def _blocks() -> list[str]:
    text = PAGE.read_text(encoding="utf-8")
    region = re.search(r"<!-- broker-commands -->(.*?)<!-- /broker-commands -->", text, flags=re.S)
    assert region, "docs/live.md has no broker-commands region"
    return re.findall(r"^```sh\n(.*?)^```", region.group(1), flags=re.S | re.M)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _answers(port: int, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return True
        except OSError:
            time.sleep(0.05)
    return False


def _stop(folder: Path) -> None:
    for pid_file in folder.rglob("*.pid"):
        with contextlib.suppress(ProcessLookupError, ValueError):
            os.kill(int(pid_file.read_text().split()[0]), signal.SIGTERM)


@pytest.fixture
def workspace(tmp_path):
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shims = tmp_path / "shims"
    shims.mkdir()
    real = MosquittoBroker.executable()
    shim = shims / "mosquitto"
    shim.write_text(
        "#!/bin/sh\n"
        '[ "$(id -u)" = 0 ] && [ "$1" = -c ] && printf "user root\\n" >> "$2"\n'
        f'exec {real} "$@"\n',
        encoding="utf-8",
    )
    shim.chmod(0o755)
    sbin = os.pathsep.join(folder for folder in ("/usr/sbin", "/usr/local/sbin") if Path(folder).is_dir())
    environment = dict(
        os.environ,
        PATH=os.pathsep.join([str(shims), str(Path(sys.executable).parent), os.environ["PATH"], sbin]),
        PORT=str(_free_port()),
        TLS_PORT=str(_free_port()),
    )
    yield tmp_path, environment
    _stop(tmp_path)


def _sh(block: str, folder: Path, environment: dict, seconds: float) -> subprocess.CompletedProcess:
    return subprocess.run(
        ["bash", "-e", "-c", block],
        cwd=folder,
        env=environment,
        capture_output=True,
        text=True,
        timeout=seconds,
        check=False,
    )


def test_the_broker_section_has_its_four_blocks():
    blocks = _blocks()
    assert len(blocks) == 4
    assert "amqtt -c" in blocks[0]
    assert "acl_file" in blocks[1]
    assert "trajgen serve" in blocks[2]
    assert "mqtts://" in blocks[3]


def test_the_amqtt_quick_try_starts_a_broker(workspace):
    folder, environment = workspace
    done = _sh(_blocks()[0], folder, environment, 30)
    assert done.returncode == 0, done.stderr
    assert _answers(int(environment["PORT"])), (folder / "amqtt.log").read_text()


def test_the_mosquitto_commands_carry_a_logged_in_run_and_a_tls_connection(workspace):
    folder, environment = workspace
    setup, run, tls = _blocks()[1:]
    done = _sh(setup, folder, environment, 30)
    assert done.returncode == 0, done.stderr
    assert _answers(int(environment["PORT"])), (folder / "broker" / "mosquitto.log").read_text()
    done = _sh(run, folder, environment, 240)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "live run: goals-reached" in done.stdout
    assert done.stdout.count("at its goal") == 2
    assert "trajgen: error" not in done.stderr
    done = _sh(tls, folder, environment, 60)
    assert done.returncode == 0, done.stdout + done.stderr + (folder / "broker" / "tls.log").read_text()
    assert "vehicle agv1: stopped" in done.stdout
