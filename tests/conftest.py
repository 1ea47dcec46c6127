"""Test configuration: seeded (derandomized) hypothesis runs, the repository's path."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from tests.support.slow_guard import SlowGuard

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

#: End-to-end tests are marked ``slow`` where they are written (``pytestmark`` in a file of them,
#: ``pytest.mark.slow`` on a test, ``marks=`` on a case): the docs build, the examples, installs,
#: live runs over a broker, demos and simulations on the command line, runs under load, other
#: processes, the optimal method's accuracy set, the online campaign, and the property tests over
#: many random solves. ``pytest -m "not slow" -n auto`` is the fast set a developer runs after a
#: change (at most 90 s on two cores); CI runs everything. A test that starts a process or listens
#: on a socket and is not marked slow fails (:mod:`tests.support.slow_guard`).
GUARD = SlowGuard()
sys.addaudithook(GUARD.audit)


def pytest_configure(config) -> None:
    """Give the run its own store of compiled NLPs and vehicle places (in the process that starts the others).

    The optimal method keeps the NLPs it builds in a disk store (``$TRAJGEN_CACHE_DIR``, else the
    user's cache folder). The run points it at a new temporary folder, which every worker and
    every process the tests start inherit: nothing of the user's cache is read, and each shape is
    built once for the whole run. It is deleted when the run ends.
    """
    # matplotlib builds its font cache with fc-list when it is cold: before any test is watched
    import matplotlib.font_manager  # noqa: F401

    if hasattr(config, "workerinput"):
        return
    import tempfile

    store = tempfile.TemporaryDirectory(prefix="trajgen-test-nlp-")
    config._trajgen_store = store  # kept alive until pytest_unconfigure
    os.environ["TRAJGEN_CACHE_DIR"] = store.name
    # the vehicles' remembered places (trajgen.live.memory) too: nothing of the user's home is read
    os.environ["TRAJGEN_STATE_DIR"] = os.path.join(store.name, "state")


def pytest_unconfigure(config) -> None:
    """Delete the run's store of compiled NLPs (after the workers and the runs they started)."""
    store = getattr(config, "_trajgen_store", None)
    if store is not None:
        store.cleanup()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """Watch a test not marked slow from its setup to its teardown (:data:`GUARD`)."""
    GUARD.watch(item.get_closest_marker("slow") is None)
    try:
        yield
    finally:
        GUARD.watch(False)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Fail a phase of a fast test in which it started a process or bound a socket."""
    outcome = yield
    report = outcome.get_result()
    found = GUARD.take()
    if found is not None and report.outcome != "failed":
        report.outcome = "failed"
        report.longrepr = (
            f"{item.nodeid} {found} in its {report.when}, and is not marked slow: "
            "mark it pytest.mark.slow (the fast set starts nothing)"
        )
