"""What an install brings: a light base, the live parts behind ``trajgen[live]``, every import declared.

The resolver's own answer (``pip install --dry-run --report``, in a new virtual environment, nothing
installed) says what ``pip install .`` and ``pip install '.[live]'`` would bring; the live commands
are run with the live extra's modules made unimportable, as in a base install.
"""

from __future__ import annotations

import ast
import concurrent.futures
import importlib.metadata
import json
import re
import subprocess
import sys
import tomllib

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

LIVE_ONLY = {"amqtt", "paho-mqtt"}
#: Modules of the standard library or of this repository (never a distribution to declare).
OWN = {"trajgen", "topology", "limits"}


def _resolved(tmp_path, target: str) -> set[str]:
    """The distributions ``pip install TARGET`` would install into a new virtual environment."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    report = tmp_path / "report.json"
    pip = [sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python")]
    subprocess.run(
        [*pip, "install", "--dry-run", "--quiet", "--report", str(report), target],
        check=True,
        cwd=REPO,
        capture_output=True,
    )
    return {item["metadata"]["name"].lower() for item in json.loads(report.read_text())["install"]}


@pytest.mark.slow
def test_the_base_install_brings_no_mqtt_and_the_live_extra_does(tmp_path):
    with concurrent.futures.ThreadPoolExecutor(2) as pool:  # two resolvers at once
        base, live = pool.map(
            lambda pair: _resolved(tmp_path / pair[0], pair[1]), [("base", "."), ("live", ".[live]")]
        )
    assert not base & LIVE_ONLY, base & LIVE_ONLY
    assert live >= LIVE_ONLY | {"vda5050-sdk", "casadi", "trajgen"}
    assert {"scipy", "pillow", "vda5050-sdk"} <= base


def _without_live(arguments: list[str]) -> subprocess.CompletedProcess:
    """``trajgen ARGUMENTS`` with paho and amqtt unimportable, as after ``pip install trajgen``."""
    code = (
        "import sys; sys.modules['paho'] = sys.modules['amqtt'] = None\n"
        "from trajgen.cli import main\n"
        f"sys.exit(main({arguments!r}))"
    )
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=120)


@pytest.mark.parametrize(
    ("arguments", "command"),
    [
        (["serve", "examples/swap.toml", "--broker", "mqtt://127.0.0.1:1"], "trajgen serve"),
        (["vehicle", "examples/swap.toml", "agv1", "--broker", "mqtt://127.0.0.1:1"], "trajgen vehicle"),
        (["demo", "--live", "--output", "never-written"], "trajgen demo --live"),
    ],
    ids=["serve", "vehicle", "demo-live"],
)
def test_a_live_command_without_the_live_extra_exits_2_naming_it(arguments, command):
    done = _without_live(arguments)
    assert done.returncode == 2, done.stderr
    expected = f"{command} needs 'paho', which is not installed: expected pip install 'trajgen[live]'"
    assert done.stderr.strip() == f"trajgen: error: {expected}"
    assert not (REPO / "never-written").exists()


def test_the_embedded_broker_without_amqtt_is_refused_naming_the_extra():
    code = (
        "import sys; sys.modules['amqtt'] = None\n"
        "from trajgen.errors import MissingExtraError\n"
        "from trajgen.live.broker import EmbeddedBroker\n"
        "try:\n    EmbeddedBroker().start()\n"
        "except MissingExtraError as error:\n    print(error)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert re.fullmatch(r"the MQTT broker of this process .* needs 'amqtt'.*'trajgen\[live\]'\n", done.stdout)


def test_the_package_imports_and_refuses_to_commit_where_folders_cannot_be_locked(tmp_path):
    code = (
        "import sys; sys.modules['fcntl'] = None\n"  # as on Windows
        "import trajgen, trajgen.pipeline, trajgen.export.atomic as atomic\n"
        "from trajgen.errors import OutputError\n"
        f"try:\n    atomic.commit_files({{__import__('pathlib').Path({str(tmp_path / 'a.txt')!r}): b'x'}})\n"
        "except OutputError as error:\n    print(error)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert "this needs POSIX folder locks (flock): expected Linux or macOS" in done.stdout, done.stderr
    assert not (tmp_path / "a.txt").exists()


def _third_party_imports() -> dict[str, str]:
    """Top-level modules the packages import that are neither the standard library's nor their own."""
    found: dict[str, str] = {}
    for package in OWN:
        for source in sorted((REPO / package).rglob("*.py")):
            for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    names = [alias.name for alias in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names = [node.module]
                else:
                    continue
                for name in names:
                    top = name.split(".")[0]
                    if top not in OWN and top not in sys.stdlib_module_names:
                        found.setdefault(top, str(source.relative_to(REPO)))
    return found


def test_every_imported_distribution_is_declared():
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    declared = project["dependencies"] + project["optional-dependencies"]["live"]
    names = {re.match(r"[A-Za-z0-9_.-]+", d).group(0).lower().replace("_", "-") for d in declared}
    distributions = importlib.metadata.packages_distributions()
    missing = {}
    for module, where in _third_party_imports().items():
        providers = {d.lower().replace("_", "-") for d in distributions.get(module, [module])}
        if not providers & names:
            missing[module] = where
    assert missing == {}, f"imported but not declared in pyproject.toml: {missing}"
