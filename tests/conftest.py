"""Test configuration: seeded (derandomized) hypothesis runs, the repository's path."""

from __future__ import annotations

import os
from pathlib import Path

from hypothesis import HealthCheck, settings

settings.register_profile(
    "seeded",
    derandomize=True,
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "seeded"))

#: The repository (a clone of it): the tests read nothing outside it (tests/test_clone.py).
REPO = Path(__file__).resolve().parent.parent
