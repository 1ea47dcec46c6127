"""trajgen: collision-free, time-optimal schedules for two AGVs on a track junction of 3 to 8 legs.

The package face: scenarios, the planner's types, the timing methods, the
verifier and the pipeline. The planner lives in :mod:`topology`, the vehicle
limits in :mod:`limits`. Heavy dependencies (CasADi, TOPPRA, matplotlib) are
imported only when used.

Examples
--------
>>> from trajgen import default_scenario, make_schedule, certify, Exact
>>> scenario = default_scenario()
>>> verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact()))
>>> verified.report.passed, round(verified.schedule.duration, 1)
(True, 67.5)
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:  # the names as a type checker sees them; at run time each is imported when first used
    from limits import Limits, VehicleLimits
    from topology import Configuration, Instruction, Position, Route, StarGraph, YGraph, plan
    from trajgen.errors import InputError, TrajgenError, VerificationError
    from trajgen.export import CsvOptions, Units, write_profiles
    from trajgen.methods import METHODS, Exact, HomotopyChoice, Optimal, SolverCache, Toppra, make_schedule
    from trajgen.model.analysis import lower_bound
    from trajgen.model.schedule import FallbackReason, Schedule, TimingMethod
    from trajgen.pipeline import Outputs, RunResult, run
    from trajgen.scenario import (
        BuiltinScenario,
        Scenario,
        builtin_scenario,
        default_scenario,
        load_scenario,
        parse_scenario,
    )
    from trajgen.verification import VerificationReport, VerifiedSchedule, certify, verify

#: Where each public name lives: ``import trajgen`` stays light (no NumPy, no solvers) until one is used.
_SOURCES = {
    "BuiltinScenario": "trajgen.scenario",
    "Configuration": "topology",
    "CsvOptions": "trajgen.export",
    "Exact": "trajgen.methods",
    "FallbackReason": "trajgen.model.schedule",
    "HomotopyChoice": "trajgen.methods",
    "InputError": "trajgen.errors",
    "Instruction": "topology",
    "Limits": "limits",
    "METHODS": "trajgen.methods",
    "Optimal": "trajgen.methods",
    "Outputs": "trajgen.pipeline",
    "Position": "topology",
    "Route": "topology",
    "RunResult": "trajgen.pipeline",
    "Scenario": "trajgen.scenario",
    "Schedule": "trajgen.model.schedule",
    "SolverCache": "trajgen.methods",
    "StarGraph": "topology",
    "TimingMethod": "trajgen.model.schedule",
    "Toppra": "trajgen.methods",
    "TrajgenError": "trajgen.errors",
    "Units": "trajgen.export",
    "VehicleLimits": "limits",
    "VerificationError": "trajgen.errors",
    "VerificationReport": "trajgen.verification",
    "VerifiedSchedule": "trajgen.verification",
    "YGraph": "topology",
    "builtin_scenario": "trajgen.scenario",
    "certify": "trajgen.verification",
    "default_scenario": "trajgen.scenario",
    "load_scenario": "trajgen.scenario",
    "lower_bound": "trajgen.model.analysis",
    "make_schedule": "trajgen.methods",
    "parse_scenario": "trajgen.scenario",
    "plan": "topology",
    "run": "trajgen.pipeline",
    "verify": "trajgen.verification",
    "write_profiles": "trajgen.export",
}

__all__ = [
    "METHODS",
    "BuiltinScenario",
    "Configuration",
    "CsvOptions",
    "Exact",
    "FallbackReason",
    "HomotopyChoice",
    "InputError",
    "Instruction",
    "Limits",
    "Optimal",
    "Outputs",
    "Position",
    "Route",
    "RunResult",
    "Scenario",
    "Schedule",
    "SolverCache",
    "StarGraph",
    "TimingMethod",
    "Toppra",
    "TrajgenError",
    "Units",
    "VehicleLimits",
    "VerificationError",
    "VerificationReport",
    "VerifiedSchedule",
    "YGraph",
    "builtin_scenario",
    "certify",
    "default_scenario",
    "load_scenario",
    "lower_bound",
    "make_schedule",
    "parse_scenario",
    "plan",
    "run",
    "verify",
    "write_profiles",
]
__version__ = "0.6.0"


__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
