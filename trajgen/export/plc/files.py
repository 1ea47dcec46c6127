"""PLC tables of a verified schedule: resampled, rendered, read back and verified as interpolated.

What is verified is what is written: the rendered bytes are read back with the
dialect's own reader and the two tables are checked along the schedule's route
(:func:`trajgen.export.plc.table_check.check_tables`) as the controllers interpolate them.
A table set that fails is never returned.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from limits import Limits
from trajgen.errors import OptionError, VerificationError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.numbers import limit_cap
from trajgen.export.plc.dialects import DECIMALS, DIALECTS, TableDialect
from trajgen.export.plc.resample import Resampled, resample
from trajgen.export.plc.table_check import TableCheck, check_tables
from trajgen.export.plc.tables import Interpolation, limit_ratios, slowdown
from trajgen.scenario.naming import check_vehicle_names
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["PlcTables", "check_dialect_method", "plc_tables", "table_paths", "write_tables"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class PlcTables:
    """Both vehicles' files in one dialect, verified as their controllers interpolate them.

    Attributes
    ----------
    dialect : TableDialect
    max_points : int
        The point limit the tables were made for.
    resampled : Resampled
        The tables and their error against the schedule.
    check : TableCheck
        The verdict on the tables as read back from ``contents``.
    contents : tuple of bytes
        The files of vehicle 1 and vehicle 2.
    """

    dialect: TableDialect
    max_points: int
    resampled: Resampled
    check: TableCheck
    contents: tuple[bytes, ...]

    def summary(self) -> dict:
        """JSON-ready figures of the export (``export`` in ``trajgen schedule --json``)."""
        return {
            "dialect": self.dialect.name.value,
            "point_limit": self.max_points,
            **self.resampled.summary(),
            "verified": self.check.passed,
            "min_separation_m": self.check.report.min_separation,
        }


#: How often the tables are made again, slower, when their written values exceed a limit.
SCALE_ATTEMPTS = 3


def check_dialect_method(dialect: TableDialect, jerk_limited: bool) -> None:
    """Refuse a cubic-spline dialect for a schedule without jerk limits (its spline would overshoot).

    Raises
    ------
    OptionError
    """
    if dialect.interpolation is Interpolation.CUBIC and not jerk_limited:
        raise OptionError(
            f"dialect {dialect.name.value!r} interpolates a cubic spline: it needs a jerk-limited "
            "schedule (method optimal or exact), got a method without jerk limits"
        )


def _written_above(dialect: TableDialect, contents: tuple[bytes, ...], limits: Limits) -> float:
    """How far the largest velocity a velocity table writes is above its limit as written (<= 1: not).

    The ratio of the largest written ``|v|`` to the largest number of the file's decimals at most
    the limit (:func:`~trajgen.export.numbers.limit_cap`, in mm/s), both vehicles; 0 for a
    position table (it writes no velocity).
    """
    if dialect.interpolation is not Interpolation.VELOCITY:
        return 0.0
    end = "\r\n" if dialect.crlf else "\n"
    worst = 0.0
    for vehicle, data in enumerate(contents):
        lines = data.decode("ascii").split(end)[(0 if dialect.header is None else 1) : -1]
        largest = max(abs(float(line.split(dialect.delimiter)[1])) for line in lines)
        cap = limit_cap(limits.vehicles[vehicle].max_velocity * 1000.0, DECIMALS)
        worst = max(worst, largest / cap)
    return worst


def table_paths(dialect: TableDialect, names: Sequence[str], directory: str | Path) -> tuple[Path, ...]:
    """``directory/<name><suffix>`` for each vehicle, in the order of ``names``."""
    directory = Path(directory)
    return tuple(directory / f"{name}{dialect.suffix}" for name in check_vehicle_names(names))


def plc_tables(
    verified: VerifiedSchedule, dialect: TableDialect | str, *, max_points: int | None = None
) -> PlcTables:
    """Every vehicle's table in ``dialect``, at most ``max_points`` points each, verified as written.

    Parameters
    ----------
    verified : VerifiedSchedule
    dialect : TableDialect or str
        A dialect other than ``generic`` (:data:`~trajgen.export.plc.dialects.DIALECTS`).
    max_points : int, optional
        Points per table (default: the dialect's limit).

    Raises
    ------
    OptionError
        ``generic`` (it is sampled, not resampled), too many points for the dialect, or a cubic
        dialect for a schedule without jerk limits.
    OutputLimitError
        A vehicle starts, stops and reverses more often than ``max_points`` allows.
    VerificationError
        The tables, as their controllers interpolate them, fail the checks.
    """
    schedule = require_verified(verified, "plc_tables").schedule
    dialect = DIALECTS.lookup(dialect)
    if not isinstance(dialect, TableDialect):
        raise OptionError(
            f"dialect {dialect.name.value!r} is sampled, not resampled: expected a table dialect"
        )
    points = dialect.check_points(max_points)
    check_dialect_method(dialect, schedule.jerk_limited)
    scale = 1.0
    for _ in range(SCALE_ATTEMPTS):  # what is written (rounded) may need a little more time than computed
        resampled = resample(
            verified, interpolation=dialect.interpolation, max_points=points, min_scale=scale
        )
        contents = tuple(dialect.render(table) for table in resampled.tables)
        parsed = tuple(
            dialect.read(data, source=f"vehicle {vehicle + 1}'s table").table
            for vehicle, data in enumerate(contents)
        )
        needed = slowdown(limit_ratios(parsed, schedule.limits, jerk=schedule.jerk_limited))
        # and no velocity a velocity table writes above its limit: slowed down, never clipped (the
        # positions are its integral)
        above = _written_above(dialect, contents, schedule.limits)
        if needed <= 1.0 + 1e-9 and above <= 1.0:
            break
        scale = resampled.time_scale * max(needed, above) * (1.0 + 1e-6)
    if above > 1.0:  # never written: a number above its limit, however little
        raise VerificationError(
            f"the {dialect.name.value} tables write a velocity {above:.12g} times its limit after "
            f"{SCALE_ATTEMPTS} slower resamplings: expected at most the limit"
        )
    check = check_tables(parsed, schedule.route, schedule.limits, jerk=schedule.jerk_limited)
    if not check.passed:
        raise VerificationError(
            f"the {dialect.name.value} tables ({points} points) fail as their controllers interpolate "
            f"them: {'; '.join(check.failures[:3])} (more points may help: max_points=... or --max-points)",
            details=check.report.details,
        )
    logger.info(
        "%s tables: %s points, position error %.3g m, verified",
        dialect.name.value,
        [table.times.size for table in parsed],
        max(resampled.position_error),
    )
    return PlcTables(dialect, points, resampled, check, contents)


def write_tables(
    verified: VerifiedSchedule,
    names: Sequence[str],
    directory: str | Path,
    *,
    dialect: TableDialect | str,
    max_points: int | None = None,
) -> tuple[Path, ...]:
    """Write every vehicle's table in a PLC ``dialect`` into ``directory``, all or none.

    The tables are those of :func:`plc_tables` (verified as their controllers interpolate them);
    the output paths are checked before anything is computed.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verification.certify`.
    names : sequence of str
        Vehicle names, one per vehicle of the schedule, used as file names (``<name><suffix>``:
        ``.txt`` for ``codesys-xy``).
    directory : path
        Created if missing.
    dialect : TableDialect or str
        A table dialect (:data:`~trajgen.export.plc.dialects.DIALECTS`, not ``generic``: for it see
        :func:`~trajgen.export.csv.write_profiles`).
    max_points : int, optional
        Points per table (default: the dialect's limit).

    Returns
    -------
    tuple of Path
        Each vehicle's table, as committed, in the order of ``names``.

    Raises
    ------
    InputError
        Bad names, dialect, points or output folder; nothing written.
    VerificationError
        The tables fail as interpolated; nothing written.

    Examples
    --------
    >>> import tempfile
    >>> from trajgen import Exact, certify, default_scenario, make_schedule
    >>> scenario = default_scenario()
    >>> verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact()))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     [p.name for p in write_tables(verified, scenario.names, folder, dialect="codesys-xy")]
    ['agv1.txt', 'agv2.txt']
    """
    chosen = DIALECTS.lookup(dialect)
    if not isinstance(chosen, TableDialect):
        raise OptionError(
            f"dialect {chosen.name.value!r} is sampled, not resampled: write it with write_profiles"
        )
    check_vehicle_names(names, count=require_verified(verified, "write_tables").schedule.limits.count)
    paths = check_output_paths(table_paths(chosen, names, directory))
    tables = plc_tables(verified, chosen, max_points=max_points)
    return tuple(commit_files(dict(zip(paths, tables.contents, strict=True))))
