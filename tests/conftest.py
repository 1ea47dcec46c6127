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
    """Compile the packages once, in the process that starts the others, before they import them.

    The pytest-xdist workers, and the command-line, example and documentation runs the tests
    start, all import the packages of this checkout; where no bytecode is written
    (``PYTHONDONTWRITEBYTECODE``), each would compile them again (0.5 s a process).
    """
    if hasattr(config, "workerinput"):
        return
    import compileall

    for package in ("trajgen", "topology", "limits"):
        compileall.compile_dir(REPO / package, quiet=1)
