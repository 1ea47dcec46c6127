"""One pipeline from a scenario to committed files.

scenario -> route (the planner) -> schedule (a timing method) -> verified
(once) -> every output rendered to bytes -> one atomic commit of all files.
Nothing touches the disk until every output is rendered from verified
schedules; a run that fails leaves the output folders as they were.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

from topology import GraphRoute, Homotopy, Route, class_signature
from trajgen.errors import InputError, VerificationError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.csv import CsvOptions, check_row_limit, profile_chunk_pair, profile_paths
from trajgen.export.plc.dialects import DIALECTS, Dialect, TableDialect
from trajgen.export.plc.files import PlcTables, check_dialect_method, plc_tables, table_paths
from trajgen.methods import METHODS, make_schedule, method_for
from trajgen.model.analysis import lower_bound
from trajgen.model.schedule import TimingMethod
from trajgen.model.summary import graph_route_summary, provenance, route_summary
from trajgen.scenario import GraphScenario, Scenario
from trajgen.verification import VerifiedSchedule, certify

__all__ = ["JUNCTION_PLOT_NAMES", "LONG_SCHEDULE_S", "PLOT_NAMES", "Outputs", "RunResult", "run"]

logger = logging.getLogger(__name__)

#: A schedule longer than this (seconds, one day) gets a warning and a note: usually a unit slip.
LONG_SCHEDULE_S = 86_400.0

#: The files written into the plot folder.
PLOT_NAMES = ("speed.png", "separation.png", "coordination.png", "layout.png")
#: The picture a junction's run adds: its configuration space (``G_k`` on four to eight legs).
JUNCTION_PLOT_NAMES = ("configuration.png",)


def _folder(value: object, option: str) -> Path | None:
    if value is None:
        return None
    if not isinstance(value, (str, Path)) or str(value) == "":
        raise InputError(f"{option} must name a folder, got {value!r}")
    return Path(value)


@dataclass(frozen=True, slots=True)
class Outputs:
    """Which files a run writes.

    Parameters
    ----------
    csv_dir : path or None
        Folder for ``<vehicle name>.csv`` of both vehicles; ``None``: no CSV.
    plot_dir : path or None
        Folder for ``speed.png``, ``separation.png``, ``coordination.png`` and
        ``configuration.png``; ``None``: no plots.
    csv : CsvOptions
        Format of the ``generic`` CSV profiles.
    dialect : Dialect or str
        The PLC dialect of the profile files (default ``generic``;
        :data:`~trajgen.export.plc.dialects.DIALECTS`).
    max_points : int or None
        Points per table of a table dialect (default: the dialect's limit).
    compare : tuple of str
        The timing methods whose schedules ``coordination.png`` compares with the run's own
        (default: every registered one). Each is computed and certified for the plot: naming
        ``optimal`` solves its NLPs. ``()``: the run's schedule alone.
    """

    csv_dir: Path | None = None
    plot_dir: Path | None = None
    csv: CsvOptions = field(default_factory=CsvOptions)
    dialect: Dialect | str = "generic"
    max_points: int | None = None
    compare: tuple = METHODS.names

    def __post_init__(self) -> None:
        if not isinstance(self.compare, tuple | list) or not all(isinstance(n, str) for n in self.compare):
            raise InputError(f"compare must be a tuple of method names, got {self.compare!r}")
        object.__setattr__(self, "compare", tuple(METHODS.canonical(name) for name in self.compare))
        object.__setattr__(self, "csv_dir", _folder(self.csv_dir, "CSV output folder"))
        object.__setattr__(self, "plot_dir", _folder(self.plot_dir, "plot output folder"))
        if not isinstance(self.csv, CsvOptions):
            raise InputError(f"csv options must be CsvOptions, got {type(self.csv).__name__}")
        dialect = DIALECTS.lookup(self.dialect)
        object.__setattr__(self, "dialect", dialect)
        if isinstance(dialect, TableDialect):
            object.__setattr__(self, "max_points", dialect.check_points(self.max_points))
        elif self.max_points is not None:
            raise InputError(
                f"max points {self.max_points!r} applies to table dialects: dialect 'generic' is "
                "sampled every sample period (its limit is max_rows)"
            )

    def paths(self, names: tuple[str, ...], *, junction: bool = False) -> tuple[Path, ...]:
        """Every file this request writes for vehicles named ``names`` (``junction``: a junction's run)."""
        paths: list[Path] = []
        if self.csv_dir is not None and isinstance(self.dialect, TableDialect):
            paths += table_paths(self.dialect, names, self.csv_dir)
        elif self.csv_dir is not None:
            paths += profile_paths(names, self.csv_dir)
        if self.plot_dir is not None:
            extra = JUNCTION_PLOT_NAMES if junction else ()
            paths += [self.plot_dir / name for name in (*PLOT_NAMES, *extra)]
        return tuple(paths)


@dataclass(frozen=True, slots=True)
class RunResult:
    """What a run computed and wrote.

    Attributes
    ----------
    scenario : Scenario
    method : TimingMethod
        The method asked for (the schedule's own ``method`` is ``exact`` after a fallback).
    route : Route
    verified : VerifiedSchedule
        The schedule, certified by the verifier.
    files : tuple of Path
        Every file written (all committed together).
    notes : tuple of str
        What the run did beyond the schedule's own notes (e.g. a method left out of a plot).
    tables : PlcTables or None
        The PLC tables written, for a table dialect.
    planned_class : bool
        Whether the schedule's route is in the class of the planner's route (``optimal`` may take
        another: on a track graph, where the other vehicle yields). The summary names the class
        ``planned`` or ``other`` by it.
    """

    scenario: Scenario | GraphScenario
    method: TimingMethod
    route: Route | GraphRoute
    verified: VerifiedSchedule
    files: tuple[Path, ...]
    notes: tuple[str, ...] = ()
    tables: PlcTables | None = None
    planned_class: bool = True

    def summary(self) -> dict:
        """The JSON-ready summary printed by ``trajgen schedule --json``."""
        schedule, report = self.verified.schedule, self.verified.report
        return {
            "scenario": self.scenario.source,
            **provenance(schedule, self.method.name),
            "duration_s": schedule.duration,
            "jerk_limited": schedule.jerk_limited,
            "verified": report.passed,
            "worst_margins": report.summary(),
            "notes": [*schedule.notes, *self.notes],
            "solver": None if schedule.info is None else schedule.info.summary(),
            "route": (
                graph_route_summary(self.route, self.scenario.names)
                | {
                    "homotopy": (Homotopy.PLANNED if self.planned_class else Homotopy.OTHER).value,
                    "planned_class": self.planned_class,
                }
                if isinstance(self.route, GraphRoute)
                else route_summary(self.route)
            ),
            "export": None if self.tables is None else self.tables.summary(),
            "files": [str(path) for path in self.files],
        }


def _comparison(
    route: Route,
    scenario: Scenario,
    chosen: TimingMethod,
    verified_chosen: VerifiedSchedule,
    compare: tuple[str, ...],
) -> tuple[dict, list[str]]:
    """The verified schedules of ``route`` by the ``compare`` methods, for the coordination plot.

    The run's own schedule stands for the method asked for (also after a fallback).
    """
    verified = {chosen.name: verified_chosen}
    notes = []
    for method in METHODS:
        if method.name == chosen.name or method.name not in compare:
            continue
        try:
            verified[method.name] = certify(make_schedule(route, scenario.limits, method=method()))
        except VerificationError as error:
            notes.append(f"coordination plot: {method.name} left out: {error}")
            logger.warning("coordination plot: %s left out: %s", method.name, error)
    return verified, notes


def run(
    scenario: Scenario | GraphScenario,
    *,
    method: TimingMethod | str | None = None,
    outputs: Outputs | None = None,
) -> RunResult:
    """Plan, schedule, verify, render and commit: the whole job.

    Parameters
    ----------
    scenario : Scenario or GraphScenario
    method : TimingMethod or str, optional
        A method object with its options, a registered name, or ``None`` for the default
        (on a track graph: ``exact``, the method that times graphs today).
    outputs : Outputs, optional
        Files to write; none by default.

    Returns
    -------
    RunResult

    Raises
    ------
    InputError
        Bad method or output paths (checked before anything is computed), or a
        CSV profile longer than ``outputs.csv.max_rows`` rows; nothing written.
    VerificationError
        The schedule failed the verifier; nothing written.
    """
    outputs = outputs if outputs is not None else Outputs()
    if not isinstance(outputs, Outputs):
        raise InputError(f"outputs must be Outputs, got {type(outputs).__name__}")
    if not isinstance(scenario, Scenario | GraphScenario):
        raise InputError(f"run expects a Scenario or a GraphScenario, got {type(scenario).__name__}")
    chosen = method_for(method, scenario.track)
    junction = isinstance(scenario, Scenario)  # the configuration space is a junction's picture
    check_output_paths(outputs.paths(scenario.names, junction=junction))
    tabled = outputs.csv_dir is not None and isinstance(outputs.dialect, TableDialect)
    if tabled:
        check_dialect_method(outputs.dialect, chosen.jerk_limited)
    route = scenario.route()
    if outputs.csv_dir is not None and not tabled:  # refuse a profile too long before computing one
        check_row_limit(lower_bound(route, scenario.limits), outputs.csv, lower_bound=True)
    verified = certify(make_schedule(route, scenario.limits, method=chosen))
    files: dict[Path, object] = {}
    notes: list[str] = []
    duration = verified.schedule.duration
    if duration > LONG_SCHEDULE_S:
        note = (
            f"the schedule takes {duration:,.0f} s ({duration / 86_400.0:,.1f} days), more than "
            f"{LONG_SCHEDULE_S:,.0f} s: check the scenario's units (metres, m/s, m/s^2, m/s^3)"
        )
        logger.warning("%s", note)
        notes.append(note)
    tables = None
    if tabled:  # resampled to the dialect's points and verified as its controllers interpolate them
        tables = plc_tables(verified, outputs.dialect, max_points=outputs.max_points)
        for path, content in zip(
            table_paths(outputs.dialect, scenario.names, outputs.csv_dir), tables.contents, strict=True
        ):
            files[path] = content
    elif outputs.csv_dir is not None:  # streamed into the commit, a block of rows at a time
        paths = profile_paths(scenario.names, outputs.csv_dir)
        files.update(zip(paths, profile_chunk_pair(verified, outputs.csv), strict=True))
    if outputs.plot_dir is not None:
        from trajgen.plots import (
            plot_configuration,
            plot_coordination,
            plot_layout,
            plot_separation,
            plot_speed,
            png_bytes,
        )

        compared, plot_notes = _comparison(route, scenario, chosen, verified, outputs.compare)
        notes += plot_notes
        speed, separation, coordination, layout = (outputs.plot_dir / name for name in PLOT_NAMES)
        files[speed] = png_bytes(plot_speed(verified, names=scenario.names))
        files[separation] = png_bytes(plot_separation(verified))
        files[coordination] = png_bytes(plot_coordination(compared))
        files[layout] = png_bytes(plot_layout(verified, names=scenario.names))
        if junction:
            configuration = outputs.plot_dir / JUNCTION_PLOT_NAMES[0]
            files[configuration] = png_bytes(plot_configuration(verified, names=scenario.names))
    written = commit_files(files) if files else ()
    # the schedule's route: optimal may have taken another class than the planner's route
    taken = verified.schedule.route
    planned = (
        class_signature(taken) == class_signature(route)
        if isinstance(taken, GraphRoute)
        else taken.homotopy is Homotopy.PLANNED
    )
    return RunResult(scenario, chosen, taken, verified, written, tuple(notes), tables, planned)
