"""The example track graphs' files, byte for byte as before issue 49: generic CSV, tables, VDA 5050."""

from __future__ import annotations

import json

import pytest

from tests.conftest import REPO
from tests.support.graph_digests import GRAPHS, METHODS, digests

GOLDEN = json.loads((REPO / "tests" / "data" / "golden-graphs.json").read_text(encoding="utf-8"))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", GRAPHS)
def test_the_example_graphs_files_are_byte_identical_to_the_stored_digests(name, method):
    made = digests(name, method)
    stored = {key: value for key, value in GOLDEN.items() if key.startswith(f"{name}-{method}/")}
    assert sorted(made) == sorted(stored)
    different = [key for key in made if made[key] != stored[key]]
    assert not different, different


def test_every_stored_digest_belongs_to_a_case():
    cases = {f"{name}-{method}" for name in GRAPHS for method in METHODS}
    assert {key.split("/")[0] for key in GOLDEN} == cases
