"""``trajgen check``: profile files a PLC engineer received or edited, verified against the scenario.

The files alone are read with their dialect's reader (a file that cannot be
read is bad input) and verified as the controllers interpolate them
(:func:`trajgen.tables.check_tables`): the separation along the track
between the two vehicles, the limits, the start and goal, the homotopy class,
plus what their format requires (line ends, header, point count). The files
do not say which way round the configuration circle they go, so both of the
planner's classes are tried; the files pass if they pass along one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from topology import Homotopy, Route, plan
from trajgen.errors import ProfileFileError
from trajgen.export.csv import profile_paths
from trajgen.export.dialects import DIALECTS, Dialect, TableDialect
from trajgen.export.plc import table_paths
from trajgen.scenario import Scenario
from trajgen.tables import ProfileTable, TableCheck, check_tables

__all__ = ["MAX_FILE_BYTES", "ProfileCheck", "check_profiles", "profile_files"]

#: Largest profile file read (a day of 10 ms rows of the generic CSV is about 900 MB), bytes.
MAX_FILE_BYTES = 1 << 30


@dataclass(frozen=True, slots=True)
class ProfileCheck:
    """The verdict on two profile files.

    Attributes
    ----------
    dialect : Dialect
    files : tuple of 2 Path
    problems : tuple of str
        What in the files' format a controller would not take.
    tables : tuple of 2 ProfileTable
        The tables as read.
    check : TableCheck
        The tables' verdict along the route of the class that fits them best.
    """

    dialect: Dialect
    files: tuple[Path, Path]
    problems: tuple[str, ...]
    tables: tuple[ProfileTable, ProfileTable]
    check: TableCheck

    @property
    def passed(self) -> bool:
        """No format problem and no violation."""
        return not self.problems and self.check.passed

    @property
    def failures(self) -> tuple[str, ...]:
        """Format problems, then violations, each naming where, the quantity, the value and the limit."""
        return self.problems + self.check.failures

    def summary(self) -> dict:
        """JSON-ready verdict (``trajgen check --json``)."""
        return {
            "dialect": self.dialect.name.value,
            "files": [str(path) for path in self.files],
            "passed": self.passed,
            "failures": list(self.failures),
            "points": [int(table.times.size) for table in self.tables],
            "min_separation_m": self.check.report.min_separation,
            "homotopy": self.check.route.homotopy.value,
            "ratios": {k: (list(v) if v is not None else None) for k, v in self.check.ratios.items()},
        }


def profile_files(scenario: Scenario, directory: str | Path, dialect: Dialect) -> tuple[Path, Path]:
    """The two files of ``dialect`` for the scenario's vehicles in ``directory``."""
    if isinstance(dialect, TableDialect):
        return table_paths(dialect, scenario.names, directory)
    return profile_paths(scenario.names, directory)


def _read(path: Path) -> bytes:
    if not path.exists():
        raise ProfileFileError(f"profile file {path} does not exist")
    if not path.is_file():
        raise ProfileFileError(f"profile file {path} is not a regular file")
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise ProfileFileError(f"profile file {path} has {size:,} bytes: expected at most {MAX_FILE_BYTES:,}")
    return path.read_bytes()


def _routes(scenario: Scenario) -> tuple[Route, ...]:
    """The planner's route in the paper's class, then the other class's."""
    separation = scenario.limits.min_separation
    return tuple(
        plan(scenario.track, scenario.start, scenario.goal, min_separation=separation, homotopy=homotopy)
        for homotopy in (Homotopy.PAPER, Homotopy.OTHER)
    )


def check_profiles(
    scenario: Scenario, directory: str | Path, *, dialect: Dialect | str = "generic", jerk: bool = True
) -> ProfileCheck:
    """Read both vehicles' files of ``dialect`` in ``directory`` and verify them against ``scenario``.

    Parameters
    ----------
    scenario : Scenario
    directory : path
        Holds ``<vehicle name><suffix>`` of both vehicles.
    dialect : Dialect or str, optional
        Default ``generic``.
    jerk : bool, optional
        Hold the tables to the jerk limits (default True).

    Returns
    -------
    ProfileCheck

    Raises
    ------
    ProfileFileError
        A file is missing, too large, or not readable as the dialect.
    """
    dialect = DIALECTS.lookup(dialect)
    files = profile_files(scenario, directory, dialect)
    parsed = [dialect.read(_read(path), source=str(path)) for path in files]
    tables = (parsed[0].table, parsed[1].table)
    problems = parsed[0].problems + parsed[1].problems
    verdicts = [check_tables(tables, route, scenario.limits, jerk=jerk) for route in _routes(scenario)]
    best = next((verdict for verdict in verdicts if verdict.passed), None)
    if best is None:
        best = min(verdicts, key=lambda verdict: len(verdict.failures))
    return ProfileCheck(dialect, files, problems, tables, best)
