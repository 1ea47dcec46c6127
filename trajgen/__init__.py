"""trajgen: collision-free, time-optimal schedules for AGVs on track graphs and junctions of 3 to 8 legs.

The package face: scenarios (:class:`Scenario` on a junction, :class:`GraphScenario` on a track
graph), the planners' types (:class:`TrackGraph`, :class:`EdgePoint`, :class:`GraphRoute`,
:func:`plan_graph`; :class:`StarGraph`, :class:`Route`, :func:`plan`), the timing methods, the
verifier and the pipeline. The planners live in :mod:`topology`, the vehicle limits in
:mod:`limits`. Heavy dependencies (CasADi, TOPPRA, matplotlib) are imported only when used.

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
    from topology import (
        Configuration,
        EdgePoint,
        GraphRoute,
        Instruction,
        Position,
        Route,
        StarGraph,
        TrackGraph,
        YGraph,
        plan,
        plan_graph,
    )
    from trajgen.errors import InputError, TrajgenError, VerificationError
    from trajgen.export import CsvOptions, Units, write_profiles
    from trajgen.methods import METHODS, Exact, HomotopyChoice, Optimal, SolverCache, Toppra, make_schedule
    from trajgen.model.analysis import lower_bound
    from trajgen.model.schedule import FallbackReason, Schedule, TimingMethod
    from trajgen.pipeline import Outputs, RunResult, run
    from trajgen.scenario import (
        BuiltinScenario,
        GraphScenario,
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
    "EdgePoint": "topology",
    "Exact": "trajgen.methods",
    "FallbackReason": "trajgen.model.schedule",
    "GraphRoute": "topology",
    "GraphScenario": "trajgen.scenario",
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
    "TrackGraph": "topology",
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
    "plan_graph": "topology",
    "run": "trajgen.pipeline",
    "verify": "trajgen.verification",
    "write_profiles": "trajgen.export",
}

__all__ = [
    "METHODS",
    "BuiltinScenario",
    "Configuration",
    "CsvOptions",
    "EdgePoint",
    "Exact",
    "FallbackReason",
    "GraphRoute",
    "GraphScenario",
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
    "TrackGraph",
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
    "plan_graph",
    "run",
    "verify",
    "write_profiles",
]
__version__ = "0.6.0"


__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
