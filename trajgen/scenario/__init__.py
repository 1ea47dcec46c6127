"""Scenarios: TOML files, factsheets, bounded reading, vehicle names, seeded random scenarios.

The names of :mod:`trajgen.scenario.definition` are available from here.
"""

from trajgen.scenario.definition import (
    DEFAULT_SCENARIO_NAME,
    MAX_SCENARIO_BYTES,
    PLAUSIBLE,
    BuiltinScenario,
    Scenario,
    builtin_scenario,
    default_scenario,
    load_scenario,
    parse_scenario,
)
from trajgen.scenario.graph import GraphScenario

__all__ = [
    "DEFAULT_SCENARIO_NAME",
    "MAX_SCENARIO_BYTES",
    "PLAUSIBLE",
    "BuiltinScenario",
    "GraphScenario",
    "Scenario",
    "builtin_scenario",
    "default_scenario",
    "load_scenario",
    "parse_scenario",
]
