"""trajgen: collision-free, time-optimal schedules for two AGVs on a track junction of 3 to 8 legs.

The package face: scenarios, the planner's types, the timing methods, the
verifier and the pipeline. The planner lives in :mod:`topology`, the vehicle
limits in :mod:`limits`. Heavy dependencies (CasADi, TOPPRA, matplotlib) are
imported only when used.

Examples
--------
>>> from trajgen import default_scenario, make_schedule, certify, Exact
>>> scenario = default_scenario()
>>> verified = certify(make_schedule(scenario.plan(), scenario.limits, method=Exact()))
>>> verified.report.passed, round(verified.schedule.duration, 1)
(True, 67.5)
"""

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
from trajgen.verify import VerificationReport, VerifiedSchedule, certify, verify

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
