"""``trajgen simulate``: a scenario run in closed loop under faults, its trace and plot committed together.

Everything that can be bad input (the fault specs, the control period, the
position margin, the method, the output paths) is checked before anything is
computed. The trace (``DIR/<vehicle name>.csv``, one row per control period)
and the plot (``DIR/simulation.png``) are rendered after the run and committed
together (:func:`~trajgen.export.atomic.commit_files`), also when the run
missed its goal or had violations: they are the evidence.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from topology.validation import finite_real, short_repr
from trajgen.errors import InputError
from trajgen.execution.messages import PERIOD_RANGE
from trajgen.execution.simulation import SimulationResult, parse_faults, simulate
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.csv import CsvOptions, profile_paths
from trajgen.methods import METHODS
from trajgen.model.schedule import TimingMethod
from trajgen.model.summary import closest_text, format_provenance
from trajgen.plots import plot_simulation, png_bytes
from trajgen.scenario import GraphScenario, Scenario
from trajgen.verification import VerifiedSchedule

__all__ = ["SIMULATION_PLOT_NAME", "SimulationRun", "format_simulation", "run_simulation", "simulation_paths"]

#: The file written into the plot folder.
SIMULATION_PLOT_NAME = "simulation.png"


def _folder(value: object, option: str) -> Path | None:
    if value is None:
        return None
    if not isinstance(value, (str, Path)) or str(value) == "":
        raise InputError(f"{option} must name a folder, got {short_repr(value)}")
    return Path(value)


def simulation_paths(
    names: tuple[str, ...], *, trace_dir: str | Path | None = None, plot_dir: str | Path | None = None
) -> tuple[Path, ...]:
    """Every file a simulation writes: ``trace_dir/<name>.csv`` per vehicle, ``plot_dir/simulation.png``.

    Parameters
    ----------
    names : tuple of str
        The vehicles' names (file names of their traces), one per vehicle.
    trace_dir, plot_dir : path or None
        ``None``: no trace, no plot.

    Raises
    ------
    InputError
        A folder that is not a path, or names that are no portable file names.
    """
    trace_dir = _folder(trace_dir, "trace output folder")
    plot_dir = _folder(plot_dir, "plot output folder")
    paths: list[Path] = []
    if trace_dir is not None:
        paths += profile_paths(names, trace_dir)
    if plot_dir is not None:
        paths.append(plot_dir / SIMULATION_PLOT_NAME)
    return tuple(paths)


def _check_settings(period: object, position_margin: object) -> tuple[float, float]:
    """The control period (s) and position margin (m), checked as the executor will check them."""
    period = finite_real(period, "control period (seconds)", InputError)
    low, high = PERIOD_RANGE
    if not low <= period <= high:
        raise InputError(f"control period must be {low:g} to {high:g} s, got {period!r}")
    if (
        isinstance(position_margin, bool)
        or not isinstance(position_margin, (int, float))
        or not math.isfinite(position_margin)
        or position_margin <= 0.0
    ):
        raise InputError(
            f"position margin (m) must be a finite number > 0, got {short_repr(position_margin)}"
        )
    return period, float(position_margin)


@dataclass(frozen=True, slots=True)
class SimulationRun:
    """What :func:`run_simulation` did and wrote.

    Attributes
    ----------
    result : SimulationResult
        The closed-loop run: goal reached, makespan, separation, violations, events.
    files : tuple of Path
        Every file written (the trace and the plot, committed together).
    """

    result: SimulationResult
    files: tuple[Path, ...]

    def summary(self) -> dict:
        """The JSON-ready summary ``trajgen simulate --json`` prints: the result's and ``files``."""
        return {**self.result.summary(), "files": [str(path) for path in self.files]}


def run_simulation(
    scenario: Scenario | GraphScenario,
    specs: Sequence[str] = (),
    *,
    period: float = 0.01,
    method: TimingMethod | str | None = None,
    position_margin: float = 0.05,
    trace_dir: str | Path | None = None,
    plot_dir: str | Path | None = None,
    csv_options: CsvOptions | None = None,
    verified: VerifiedSchedule | None = None,
) -> SimulationRun:
    """Simulate ``scenario`` under the faults ``specs`` and commit its trace and plot.

    Parameters
    ----------
    scenario : Scenario or GraphScenario
    specs : sequence of str
        ``--fault`` specs (:mod:`trajgen.execution.faults`), e.g. ``stop:agv1@8+3``.
    period : float, optional
        Control period, seconds (0.002 to 0.1; default 0.01); also the trace's row period.
    method : TimingMethod or str, optional
        How the undisturbed plan is timed (default: the registry's default, ``optimal``).
    position_margin : float, optional
        The executor's position margin, metres (default 0.05); also the largest ``jump``.
    trace_dir : path, optional
        Folder for ``<vehicle name>.csv`` of every vehicle: its executed (true) motion.
    plot_dir : path, optional
        Folder for ``simulation.png`` (:func:`~trajgen.plots.plot_simulation`).
    csv_options : CsvOptions, optional
        Dialect of the trace (delimiter, decimal mark, units); its ``sample_period`` and
        ``max_rows`` do not apply: the trace has one row per control period.
    verified : VerifiedSchedule, optional
        The plan to execute, if already made for ``scenario``
        (:func:`~trajgen.execution.goals.schedule_for_execution`, or a plan of any number of
        vehicles made otherwise: the planners plan two today); ``method`` is then its method.

    Returns
    -------
    SimulationRun
        What the run did (``.result``) and every file written (``.files``, committed together). A
        run that missed its goal or had violations still writes its files.

    Raises
    ------
    InputError
        A bad fault spec (:class:`~trajgen.execution.faults.FaultError`), period, margin, method,
        CSV options or output path; raised before anything is computed, nothing written.
    """
    if not isinstance(scenario, (Scenario, GraphScenario)):
        raise InputError(
            f"run_simulation expects a Scenario or a GraphScenario, got {type(scenario).__name__}"
        )
    if isinstance(specs, str):
        raise InputError(f"fault specs must be a sequence of str, got the string {short_repr(specs)}")
    period, position_margin = _check_settings(period, position_margin)
    chosen = METHODS.create(method)
    options = CsvOptions() if csv_options is None else csv_options
    if not isinstance(options, CsvOptions):
        raise InputError(f"csv options must be CsvOptions, got {type(options).__name__}")
    faults = parse_faults(scenario, list(specs), position_margin=position_margin, verified=verified)
    paths = simulation_paths(scenario.names, trace_dir=trace_dir, plot_dir=plot_dir)
    check_output_paths(paths)
    traced = trace_dir is not None
    result, trace = simulate(
        scenario,
        faults,
        period=period,
        method=chosen if verified is None else None,  # a plan at hand tells its own method
        position_margin=position_margin,
        trace=options if traced else None,
        verified=verified,
    )
    try:
        files: dict[Path, object] = {}
        if traced:  # streamed from the trace's temporary files into the commit
            for vehicle, path in enumerate(paths[: len(scenario.names)]):
                files[path] = trace.chunks(vehicle)
        if plot_dir is not None:
            files[paths[-1]] = png_bytes(
                plot_simulation(result, names=scenario.names, min_separation=scenario.limits.min_separation)
            )
        written = commit_files(files) if files else ()
    finally:
        if trace is not None:
            trace.close()
    return SimulationRun(result, tuple(written))


def _event_lines(events: list[dict]) -> list[str]:
    """One line per event; a run of events of one kind and text is one line with its count and span."""
    lines = []
    for (kind, detail), run in itertools.groupby(events, key=lambda e: (e["kind"], e["detail"])):
        run = list(run)
        line = f"event {run[0]['t_s']:10.3f} s  {kind}: {detail}"
        lines.append(line + (f" (x{len(run)}, until {run[-1]['t_s']:.3f} s)" if len(run) > 1 else ""))
    return lines


def _plan_end(plan: dict, following: dict | None) -> str:
    """How a plan of a run with re-plans ended: left for a new goal, or driven to its goals first."""
    if following is None:
        return ""
    if following["started_s"] > plan["ended_s"] + 1e-9:
        return f" (at its goals, then a new goal at {following['started_s']:.3f} s)"
    return " (left for a new goal)"


def format_simulation(summary: dict, *, min_separation: float) -> str:
    """Human-readable lines of a simulation's summary (:meth:`SimulationResult.summary`).

    Parameters
    ----------
    summary : dict
        The summary, with ``files`` (paths written) added.
    min_separation : float
        The scenario's minimum separation, metres.
    """
    reached = "yes" if summary["reached_goal"] else "no"
    lines = [
        f"reached goal: {reached}  makespan: {summary['makespan_s']:.3f} s "
        f"(planned {summary['planned_s']:.3f} s, lost {summary['time_lost_s']:.3f} s"
        + (f", {summary['idle_s']:.3f} s at the goals waiting for a new one" if summary.get("idle_s") else "")
        + ")",
        f"plan: {format_provenance(summary)}",
        f"separation: min {closest_text(summary['min_separation_m'])}, certified between cycles "
        f"{closest_text(summary['certified_separation_m'])} (required {min_separation:g} m)",
        f"worst setpoints: |v|/limit {summary['velocity_ratio']:.6f}, |a|/limit "
        f"{summary['acceleration_ratio']:.6f}, |j|/limit {summary['jerk_ratio']:.6f}",
        f"replans: {summary['replans']}  rejected goals: {summary['rejected_goals']}",
        f"violations: {summary['violations']} (separation {summary['separation_violations']}, "
        f"limits {summary['limit_violations']}) in {summary['cycles']} cycles",
    ]
    plans = summary.get("plans", ())
    if len(plans) > 1:  # a re-plan: each plan's part, so the time lost is read against the plan driven
        lines += [
            f"plan {k} of {len(plans)}: {plan['started_s']:.3f} to {plan['ended_s']:.3f} s, "
            f"planned {plan['planned_s']:.3f} s of its {plan['duration_s']:.3f} s, "
            f"lost {plan['lost_s']:.3f} s" + _plan_end(plan, plans[k] if k < len(plans) else None)
            for k, plan in enumerate(plans, start=1)
        ]
    unapplied = set(summary.get("unapplied_faults", ()))
    lines += [
        f"fault: {spec}"
        + (f" (never applied: the run ended at {summary['makespan_s']:.3f} s)" if spec in unapplied else "")
        for spec in summary["faults"]
    ]
    lines += _event_lines(summary["events"])
    lines += [f"wrote {path}" for path in summary.get("files", ())]
    return "\n".join(lines)
