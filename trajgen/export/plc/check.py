"""``trajgen check``: profile files a PLC engineer received or edited, verified against the scenario.

The files alone are read with their dialect's reader (a file that cannot be
read is bad input) and verified as the controllers interpolate them
(:func:`trajgen.export.plc.table_check.check_tables`): the separation along the track
between the two vehicles, the limits, the start and goal, the homotopy class,
plus what their format requires (line ends, header, point count). A generic
CSV of a schedule that does not limit jerk records so before its header
(:class:`~trajgen.export.csv.ScheduleRecord`): files that both record it are
not held to the jerk limits (the verdict says so). The files
do not say which homotopy class they take, so both of the planner's classes
are tried (on a Y both ways round the configuration circle; on 4 to 8 legs
the shortest and the second-shortest route on the retract graph ``G_k``, the
classes ``trajgen schedule`` takes); the files pass if they pass along one.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from topology import GraphRoute, Homotopy, Route, plan, plan_graph_classes
from topology.indexed import track_distance
from topology.validation import short_repr
from trajgen.errors import OptionError, ProfileFileError
from trajgen.export.csv import ScheduleRecord, profile_paths
from trajgen.export.plc.dialects import DIALECTS, Dialect, DialectName, TableDialect
from trajgen.export.plc.files import table_paths
from trajgen.export.plc.table_check import TableCheck, check_tables
from trajgen.export.plc.tables import ProfileTable
from trajgen.model.summary import class_name, graph_class_label
from trajgen.scenario import GraphScenario, Scenario
from trajgen.scenario.reading import FileKind, file_label, read_bounded

__all__ = ["MAX_FILE_BYTES", "ProfileCheck", "check_profiles", "profile_files"]

#: Largest profile file read, bytes (a generic CSV of 1,000,000 rows is about 100 MB).
MAX_FILE_BYTES = 256 << 20
#: Most points (rows) per file the checker reads.
MAX_POINTS = 1_000_000
#: Travel short of its route's that a generic CSV at rest in its last row ends early by, metres.
_SHORT_OF_GOAL = 1e-3
#: How profile files are read (:func:`~trajgen.scenario.reading.read_bounded`).
PROFILE_FILE = FileKind("a profile file", "a profile file", MAX_FILE_BYTES, ProfileFileError)


@dataclass(frozen=True, slots=True)
class ProfileCheck:
    """The verdict on two profile files.

    Attributes
    ----------
    dialect : Dialect
    files : tuple of Path
    problems : tuple of str
        What in the files' format a controller would not take.
    tables : tuple of ProfileTable
        The tables as read.
    check : TableCheck
        The tables' verdict along the route of the class that fits them best.
    jerk_checked : bool
        Whether the files were held to the jerk limits (not if asked not to, nor if both are generic
        CSVs that record a schedule without jerk limits).
    record : ScheduleRecord or None
        What the files record of their schedule (a generic CSV's line before its header), if both
        record it alike; ``None``: neither does (a table dialect's files never do).
    """

    dialect: Dialect
    files: tuple[Path, ...]
    problems: tuple[str, ...]
    tables: tuple[ProfileTable, ...]
    check: TableCheck
    jerk_checked: bool = True
    record: ScheduleRecord | None = None

    @property
    def passed(self) -> bool:
        """No format problem and no violation."""
        return not self.problems and self.check.passed

    @property
    def failures(self) -> tuple[str, ...]:
        """Format problems, then violations, each naming where, the quantity, the value and the limit."""
        return self.problems + self.check.failures

    def summary(self) -> dict:
        """JSON-ready verdict (``trajgen check --json``); 4 to 8 legs add ``class`` (a route on ``G_k``)."""
        route = self.check.route
        if isinstance(route, GraphRoute):  # a track graph: the class is the moves, in order
            where = {"class": graph_class_label(route)}
        else:
            where = {"homotopy": route.homotopy.value}
            if route.graph.cycle is None:
                where["class"] = class_name(route)
        return {
            "dialect": self.dialect.name.value,
            "files": [str(path) for path in self.files],
            "passed": self.passed,
            "failures": list(self.failures),
            "points": [int(table.times.size) for table in self.tables],
            "min_separation_m": self.check.report.min_separation,
            **where,
            "jerk_checked": self.jerk_checked,
            "record": (
                None
                if self.record is None
                else {"method": self.record.method, "jerk_limited": self.record.jerk_limited}
            ),
            "ratios": {k: (list(v) if v is not None else None) for k, v in self.check.ratios.items()},
        }


def profile_files(
    scenario: Scenario | GraphScenario, directory: str | Path, dialect: Dialect
) -> tuple[Path, ...]:
    """The two files of ``dialect`` for the scenario's vehicles in ``directory``."""
    if isinstance(dialect, TableDialect):
        return table_paths(dialect, scenario.names, directory)
    return profile_paths(scenario.names, directory)


def _routes(scenario: Scenario | GraphScenario) -> tuple[Route | GraphRoute, ...]:
    """The planner's route in its instruction's class, then the other class's (if there is another).

    On a track graph: the classes the timing methods take (:func:`topology.plan_graph_classes`).
    """
    separation = scenario.limits.min_separation
    if isinstance(scenario, GraphScenario):
        return plan_graph_classes(
            scenario.track, scenario.start, scenario.goal, min_separation=separation, names=scenario.names
        )
    routes = [plan(scenario.track, scenario.start, scenario.goal, min_separation=separation)]
    # where start and goal retract to one boundary point, the other way round is a full turn: none
    with contextlib.suppress(OptionError):
        routes.append(
            plan(
                scenario.track,
                scenario.start,
                scenario.goal,
                min_separation=separation,
                homotopy=Homotopy.OTHER,
            )
        )
    return tuple(routes)


def _graph_places(parsed, vehicle: int, check: TableCheck, scenario: GraphScenario) -> list[str]:
    """A track graph's generic CSV: each row's edge and s are where its axis puts the vehicle, x/y on them."""
    columns, table, track = parsed.columns, parsed.table, scenario.track
    name = f"vehicle {vehicle + 1}"
    known = {edge.name: k for k, edge in enumerate(track.edges)}
    names = columns["edge"]
    unknown = [k for k, edge in enumerate(names) if edge not in known]
    if unknown:
        k = unknown[0]
        return [
            f"{name} row at t={table.times[k]:.6f} s: edge {short_repr(names[k])} is not on the track: "
            f"expected one of {short_repr(sorted(known))}"
        ]
    edges = np.array([known[edge] for edge in names], dtype=int)
    s = columns["s"]
    failures = []
    lengths = np.array([edge.length for edge in track.edges])[edges]
    outside = (s < -1e-6) | (s > lengths + 1e-6)
    if outside.any():
        k = int(np.argmax(outside))
        failures.append(
            f"{name} row at t={table.times[k]:.6f} s: s {s[k]:.9g} m is off edge {names[k]!r} "
            f"(0 to {track.edges[edges[k]].length:g} m)"
        )
    if check.schedule is not None:
        # where the axis puts it, also past either end of its path (a vehicle creeping on)
        travel = check.schedule.travel(table.times)[vehicle, 0]
        on_edge, along = check.schedule.paths[vehicle].locate(travel, extend=True)
        along = np.clip(along, 0.0, np.array([edge.length for edge in track.edges])[on_edge])
        apart = track.distances(edges, np.clip(s, 0.0, lengths), on_edge, along)
        where = np.nonzero(apart > 1e-6)[0]
        if where.size:
            k = int(where[0])
            failures.append(
                f"{name} row at t={table.times[k]:.6f} s says edge {names[k]!r}, s {s[k]:.9g} m, but its "
                f"axis puts it on edge {track.edges[on_edge[k]].name!r}, s {along[k]:.9g} m"
            )
    if "x" in columns and track.coordinates is not None:
        coordinates = np.asarray(track.coordinates, dtype=float)
        ends = np.array([track.ends(k) for k in range(len(track.edges))], dtype=int)[edges]
        point = coordinates[ends[:, 0]] + (s / lengths)[:, None] * (
            coordinates[ends[:, 1]] - coordinates[ends[:, 0]]
        )
        off = np.hypot(columns["x"] - point[:, 0], columns["y"] - point[:, 1])
        if np.any(off > 1e-6):
            k = int(np.argmax(off))
            failures.append(
                f"{name} row at t={table.times[k]:.6f} s: x, y do not lie at edge {names[k]!r}, "
                f"s {s[k]:.9g} m"
            )
    return failures


def _star_places(parsed, vehicle: int, check: TableCheck, scenario: Scenario) -> list[str]:
    """A junction's generic CSV: each row's leg and s are where its axis puts the vehicle, x/y on them."""
    columns, table = parsed.columns, parsed.table
    name = f"vehicle {vehicle + 1}"
    failures = []
    if check.schedule is not None:
        state = check.schedule.state(table.times)
        legs = columns["leg"].astype(int) - 1  # 1-based in the file, JUNCTION_INDEX (-1) at the junction
        apart = track_distance(legs, columns["s"], state.leg[vehicle], state.s[vehicle])
        where = np.nonzero(apart > 1e-6)[0]
        if where.size:
            k = int(where[0])
            failures.append(
                f"{name} row at t={table.times[k]:.6f} s says leg {int(columns['leg'][k])}, s "
                f"{columns['s'][k]:.9g} m, but its axis puts it on leg {int(state.leg[vehicle, k]) + 1}, s "
                f"{state.s[vehicle, k]:.9g} m"
            )
    angles = np.radians(np.array(scenario.track.angles_deg))
    legs = columns["leg"].astype(int)
    known = (legs >= 0) & (legs <= len(angles))
    if np.any(~known):
        k = int(np.argmax(~known))
        failures.append(
            f"{name} row at t={table.times[k]:.6f} s: leg {legs[k]} is not on the track: expected 0 "
            f"(the junction) or a leg 1 to {len(angles)} (1-based, {len(angles)} legs)"
        )
    angle = angles[np.where(legs > 0, legs - 1, 0)[known]]
    off = np.hypot(
        columns["x"][known] - columns["s"][known] * np.cos(angle),
        columns["y"][known] - columns["s"][known] * np.sin(angle),
    )
    if np.any(off > 1e-6):
        k = int(np.nonzero(known)[0][np.argmax(off)])
        failures.append(
            f"{name} row at t={table.times[k]:.6f} s: x, y do not lie at leg {legs[k]}, "
            f"s {columns['s'][k]:.9g} m"
        )
    return failures


def _generic_columns(
    parsed, vehicle: int, check: TableCheck, scenario: Scenario | GraphScenario, jerk: bool
) -> list[str]:
    """A generic CSV's other columns agree with its motion and keep the limits they state."""
    columns, table = parsed.columns, parsed.table
    limits = scenario.limits.vehicles[vehicle]
    name = f"vehicle {vehicle + 1}"
    if isinstance(scenario, GraphScenario) != ("edge" in columns):
        expected = (
            "a track graph's (an edge column)" if isinstance(scenario, GraphScenario) else "a junction's"
        )
        return [f"{name}'s generic CSV is not for this scenario's track: expected {expected} columns"]
    if isinstance(scenario, GraphScenario):
        failures = _graph_places(parsed, vehicle, check, scenario)
    else:
        failures = _star_places(parsed, vehicle, check, scenario)
    # the v column against the positions: for any motion within max_acceleration the central
    # difference is within max_acceleration (h0^2 + h1^2) / (2 (h0 + h1)) of the velocity
    if table.times.size >= 3:
        h = np.diff(table.times)
        central = (table.values[2:] - table.values[:-2]) / (h[1:] + h[:-1])
        bound = limits.max_acceleration * (h[:-1] ** 2 + h[1:] ** 2) / (2.0 * (h[:-1] + h[1:]))
        bound = bound * (1.0 + 1e-6) + 2.0 * table.round_off / (h[1:] + h[:-1]) + 1e-9
        gap = np.abs(columns["v"][1:-1] - central) - bound
        if np.any(gap > 0.0):
            k = int(np.argmax(gap)) + 1
            failures.append(
                f"{name} velocity column {columns['v'][k]:.9g} m/s at t={table.times[k]:.6f} s disagrees "
                f"with its positions ({central[k - 1]:.9g} m/s between its neighbours)"
            )
    stated = [
        ("velocity", "v", limits.max_velocity, "m/s"),
        ("acceleration", "a", limits.max_acceleration, "m/s^2"),
    ]
    if jerk:
        stated.append(("jerk", "j", limits.max_jerk, "m/s^3"))
    for quantity, column, limit, unit in stated:
        peak = np.abs(columns[column])
        k = int(np.argmax(peak))
        if peak[k] > limit * (1.0 + 1e-6) + 1e-9:
            failures.append(
                f"{name} {quantity} column reaches {peak[k]:.9g} {unit} at t={table.times[k]:.6f} s, "
                f"exceeds its max_{quantity} {limit:g} {unit}"
            )
    return failures


def _read(dialect: Dialect, text, source: str):
    """``dialect.read``; a file the dialect refuses names what does read it.

    A generic CSV read as a table is called one (not "9 fields, expected 2"); a table the generic
    reader refuses names the dialects that read it.
    """
    try:
        return dialect.read(text, source=source)
    except ProfileFileError as error:
        if dialect.name is not DialectName.GENERIC:
            try:
                DIALECTS.lookup(DialectName.GENERIC.value).read(text, source=source)
            except (ProfileFileError, ValueError):
                raise error from None
            raise ProfileFileError(
                f"{source} is a generic CSV (trajgen's own columns t_s, axis_m, v, a, j, ...), not a "
                f"{dialect.name.value} table: check it with --dialect generic, the default "
                "(in Python: dialect='generic')"
            ) from None
        readers = []
        for other in DIALECTS:
            named_like = not isinstance(other, TableDialect) or other.suffix == ".csv"
            if other.name is DialectName.GENERIC or not named_like:
                continue
            with contextlib.suppress(ProfileFileError, ValueError):
                other.read(text, source=source)
                readers.append(other.name.value)
        if not readers:
            raise
        if len(readers) == 1:
            hint = f"it reads as dialect {readers[0]!r}: pass --dialect {readers[0]}"
        else:  # these formats share a layout: only the writer knows which it meant
            listed = ", ".join(repr(name) for name in readers)
            hint = f"it reads as each of the dialects {listed}: pass --dialect with the one that wrote it"
        raise ProfileFileError(f"{error}; {hint} (in Python: dialect=...)") from None


def check_profiles(
    scenario: Scenario | GraphScenario,
    directory: str | Path,
    *,
    dialect: Dialect | str = "generic",
    jerk: bool = True,
    max_points: int | None = None,
) -> ProfileCheck:
    """Read each vehicle's file of ``dialect`` in ``directory`` and verify them against ``scenario``.

    Parameters
    ----------
    scenario : Scenario or GraphScenario
    directory : path
        Holds ``<vehicle name><suffix>`` of each vehicle.
    dialect : Dialect or str, optional
        Default ``generic``.
    jerk : bool, optional
        Hold the tables to the jerk limits (default True), unless both are generic CSVs that record
        that their schedule does not limit jerk (:attr:`ProfileCheck.jerk_checked` says which).
    max_points : int, optional
        Most points the target takes per table (default: the dialect's limit; ``generic``: none).

    Returns
    -------
    ProfileCheck

    Raises
    ------
    ProfileFileError
        A file is missing, too large, or not readable as the dialect.
    VehicleCountError
        The scenario has a number of vehicles the planners do not plan (its files cannot be checked
        against a plan).
    """
    scenario.check_planned()
    dialect = DIALECTS.lookup(dialect)
    limit = dialect.check_points(max_points) if isinstance(dialect, TableDialect) else None
    files = profile_files(scenario, directory, dialect)
    parsed = [
        _read(dialect, read_bounded(path, f"profile file {file_label(path)}", PROFILE_FILE), str(path))
        for path in files
    ]
    tables = (parsed[0].table, parsed[1].table)
    problems = list(parsed[0].problems + parsed[1].problems)
    record, unlike = _records(parsed, files)
    problems += unlike
    jerk = jerk and (record is None or record.jerk_limited)
    for path, table in zip(files, tables, strict=True):
        if table.times.size > MAX_POINTS:
            raise ProfileFileError(
                f"{path} has {table.times.size:,} points: expected at most {MAX_POINTS:,} "
                "(the checker's limit)"
            )
        if limit is not None and table.times.size > limit:
            problems.append(f"{path}: {table.times.size:,} points, more than the target takes ({limit:,})")
    verdicts = []
    routes = _routes(scenario)
    for route in routes:
        verdicts.append(check_tables(tables, route, scenario.limits, jerk=jerk))
        if verdicts[-1].passed:
            break
    best = verdicts[-1] if verdicts[-1].passed else min(verdicts, key=lambda verdict: len(verdict.failures))
    if parsed[0].columns is not None:
        for vehicle in range(2):
            problems += _generic_columns(parsed[vehicle], vehicle, best, scenario, jerk)
        # said first: a file cut short fails everything after it, and that is the news
        problems = _early_ends(parsed, files, routes) + problems
    return ProfileCheck(dialect, files, tuple(problems), tables, best, jerk, record)


def _records(parsed, files) -> tuple[ScheduleRecord | None, list[str]]:
    """The files' common record of their schedule, and a problem if they say different things of jerk.

    Files of one schedule record it alike; where they do not, neither record counts (the jerk is
    checked) and that is a problem of the files.
    """
    records = [profile.record for profile in parsed]
    said = [record is not None and not record.jerk_limited for record in records]
    if said[0] != said[1]:
        which = 0 if said[0] else 1
        return None, [
            f"{files[which]} records that its schedule is not jerk-limited (method "
            f"{records[which].method}), {files[1 - which]} does not: expected both files of one "
            "schedule to record it alike (neither record counts)"
        ]
    if records[0] is None or records[1] is None:
        return None, []
    return records[0], []


def _early_ends(parsed, files, routes) -> list[str]:
    """A generic CSV that ends early: its last row not at rest, or at rest short of its goal.

    A schedule ends at rest at its goal. A file whose vehicle rests at its last row but has
    travelled less than its route drives (the shortest of ``routes``, the classes the check tries)
    stops short of the goal: cut where both vehicles stood, between two moves.
    """
    most = max(profile.table.times.size for profile in parsed)
    ends = []
    for vehicle, (profile, path) in enumerate(zip(parsed, files, strict=True)):
        table = profile.table
        rows, velocity = table.times.size, float(profile.columns["v"][-1])
        of = f" of {most:,} in the other vehicle's file" if most > rows else ""
        last = f"its last row (row {rows:,}{of}, t = {float(table.times[-1]):.3f} s)"
        if abs(velocity) > 1e-6:
            ends.append(
                f"{path}: the file ends early: {last} is not at rest ({velocity:.6g} m/s), where a "
                "schedule ends at rest at its goal"
            )
            continue
        driven = float(np.sum(np.abs(np.diff(table.values)))) if rows > 1 else 0.0
        needed = min(float(route.travel[vehicle]) for route in routes)
        if driven < needed - _SHORT_OF_GOAL:
            ends.append(
                f"{path}: the file ends early: {last} is at rest after {driven:.3f} m of the "
                f"{needed:.3f} m its route drives to its goal"
            )
    return ends
