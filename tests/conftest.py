"""Test configuration: seeded (derandomized) hypothesis runs, the repository's path."""

from __future__ import annotations

import os
import sys
from pathlib import Path

# The test run caches bytecode, also where none is written by default (PYTHONDONTWRITEBYTECODE):
# pytest's rewrite of hypothesis (a pytest plugin's modules, 2 s) is then done once, here, before the
# workers start, and they read it; the packages are compiled once for every process (pytest_configure).
sys.dont_write_bytecode = False

from hypothesis import HealthCheck, settings  # noqa: E402  (with the bytecode cached)

# "seeded" (the default): what CI runs. "thorough": twenty times the examples, for a release or a
# change to the planner (HYPOTHESIS_PROFILE=thorough); tests that set max_examples keep theirs.
settings.register_profile(
    "seeded",
    derandomize=True,
    max_examples=50,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
settings.register_profile("thorough", settings.get_profile("seeded"), max_examples=1000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "seeded"))

#: The repository (a clone of it): the tests read nothing outside it (tests/test_clone.py).
REPO = Path(__file__).resolve().parent.parent


def pytest_configure(config) -> None:
    """Compile the packages once, and give the run its own store of compiled NLPs.

    Runs in the process that starts the others, before they import the packages. The
    pytest-xdist workers, and the command-line, example and documentation runs the tests start,
    all import the packages of this checkout; where no bytecode is written
    (``PYTHONDONTWRITEBYTECODE``), each would compile them again (0.5 s a process).

    The optimal method keeps the NLPs it builds in a disk store (``$TRAJGEN_CACHE_DIR``, else the
    user's cache folder). The run points it at a new temporary folder, which every worker and
    every process the tests start inherit: nothing of the user's cache is read, and each shape is
    built once for the whole run. It is deleted when the run ends.
    """
    if hasattr(config, "workerinput"):
        return
    import compileall
    import tempfile

    for package in ("trajgen", "topology", "limits"):
        compileall.compile_dir(REPO / package, quiet=1)
    store = tempfile.TemporaryDirectory(prefix="trajgen-test-nlp-")
    config._trajgen_store = store  # kept alive until pytest_unconfigure
    os.environ["TRAJGEN_CACHE_DIR"] = store.name


def pytest_unconfigure(config) -> None:
    """Delete the run's store of compiled NLPs (after the workers and the runs they started)."""
    store = getattr(config, "_trajgen_store", None)
    if store is not None:
        store.cleanup()
