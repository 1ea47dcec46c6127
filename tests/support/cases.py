"""The table of cases every stage's suite runs over: junctions and track graphs, each built once per run.

A case is a scenario and its verified plans (by method), made the first time a test asks for them in
a process and shared after (all immutable). The table: the Y (the built-in swap), the 4-leg crossing,
an 8-leg star, the H, the passing loop and the ring with spurs.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from tests.support.graph_cases import EXAMPLES
from tests.support.star_scenarios import CROSSING, star_scenario
from trajgen import certify
from trajgen.methods import make_schedule
from trajgen.scenario import BuiltinScenario, builtin_scenario, load_scenario

__all__ = ["CASES", "Case", "case"]


@dataclass(frozen=True, slots=True)
class Case:
    """One case of the table: its id and how its scenario is read."""

    name: str
    source: str

    def scenario(self):
        """The case's scenario (read once per process)."""
        return _scenario(self.source)

    def verified(self, method: str = "exact"):
        """The scenario's verified plan by ``method`` (made once per process)."""
        return _verified(self.source, method)


@functools.cache
def _scenario(source: str):
    if source == "swap":
        return builtin_scenario(BuiltinScenario.SWAP)
    if source == "crossing":
        return load_scenario(CROSSING)
    if source.startswith("star-"):
        return star_scenario(int(source.removeprefix("star-")))
    return load_scenario(EXAMPLES / f"{source}.toml")


@functools.cache
def _verified(source: str, method: str):
    scenario = _scenario(source)
    return certify(make_schedule(scenario.route(), scenario.limits, method=method))


#: The table: junctions of 3, 4 and 8 legs, and three track graphs.
CASES = (
    Case("y", "swap"),
    Case("4-leg", "crossing"),
    Case("8-leg", "star-8"),
    Case("h", "h"),
    Case("passing-loop", "passing-loop"),
    Case("ring", "ring-with-spurs"),
)


def case(name: str) -> Case:
    """The case of the table named ``name`` (``"y"`` is the demo swap)."""
    return next(c for c in CASES if c.name == name)
