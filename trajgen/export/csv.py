"""CSV speed profiles for AGV PLCs, one file per vehicle (the ``generic`` format).

Renderers return bytes and take only a :class:`~trajgen.verification.VerifiedSchedule`;
:func:`write_profiles` commits both files together
(:func:`~trajgen.export.atomic.commit_files`). Numbers are formatted with numpy
(:mod:`trajgen.export.numbers`), a block of :data:`ROWS_PER_CHUNK` rows at a time; the velocity,
acceleration and (where the schedule limits it) jerk columns are held to their limits as written
(:func:`~trajgen.export.limited.limited_columns`). The file of a schedule that does not limit jerk
records so on a line before its header (:class:`ScheduleRecord`), which ``trajgen check`` reads.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from limits import VehicleLimits
from topology import Option, TrackGraph
from topology.validation import short_repr
from trajgen.errors import InputError, OptionError, OutputLimitError
from trajgen.export.atomic import commit_files
from trajgen.export.rows import LEG_HEADER_NAMES, check_edge_names, format_rows_block, header
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.schedule import Schedule, check_period, sample_block, sample_rows
from trajgen.model.state import TrackState
from trajgen.scenario.naming import check_vehicle_index, check_vehicle_names
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "DEFAULT_MAX_ROWS",
    "HEADER_NAMES",
    "ROWS_PER_CHUNK",
    "CsvOptions",
    "ScheduleRecord",
    "Units",
    "check_row_limit",
    "format_block",
    "format_rows",
    "profile_chunk_pair",
    "profile_chunks",
    "profile_paths",
    "profile_rows",
    "render_profile",
    "write_profiles",
]

#: Most rows of one CSV profile unless ``CsvOptions.max_rows`` says otherwise (a day at 10 ms: 8.64 million).
DEFAULT_MAX_ROWS = 10_000_000
#: What a profile over the row limit can change, in Python and on the command line.
_ROW_LIMIT_REMEDY = (
    "(raise CsvOptions(max_rows=...) or --max-rows, or sample less often: sample_period, --sample-period)"
)
#: Rows sampled (once for both vehicles' files: :func:`profile_chunk_pair`) and formatted at a time while
#: streaming a profile; memory is bounded by this many rows whatever the duration.
ROWS_PER_CHUNK = 20_000


class Units(Option):
    """Length unit of a CSV export (time stays in seconds)."""

    METRES = "m"
    MILLIMETRES = "mm"

    @property
    def scale(self) -> float:
        """Multiplier from metres."""
        return 1000.0 if self is Units.MILLIMETRES else 1.0

    @property
    def decimals(self) -> int:
        """Decimal places written (nanometre resolution in either unit)."""
        return 6 if self is Units.MILLIMETRES else 9


#: Column names per unit on a star's track (its legs numbered); :func:`~trajgen.export.rows.header`
#: gives any track's.
HEADER_NAMES = {unit: LEG_HEADER_NAMES[unit.value] for unit in Units}


#: The record line of a generic CSV: ``# schedule timed by METHOD: jerk not limited ...`` (or ``limited``).
_RECORD = re.compile(r"# schedule timed by (?P<method>[^:]+): jerk (?P<jerk>not limited|limited)(?: \(.*\))?")


@dataclass(frozen=True, slots=True)
class ScheduleRecord:
    """What a generic CSV records of its schedule, on a line before its header.

    trajgen writes the line for a schedule that does not limit jerk (``toppra``)::

        # schedule timed by toppra: jerk not limited (velocity and acceleration are)

    A file without it is of a jerk-limited schedule (every file before 0.7 too); a line saying
    ``jerk limited`` claims so explicitly. ``trajgen check`` reads it: a file of a schedule that
    does not limit jerk is not held to the jerk limits.

    Attributes
    ----------
    method : str
        The timing method's name (ASCII, no ``:``).
    jerk_limited : bool
        Whether the schedule limits jerk.
    """

    method: str
    jerk_limited: bool

    def line(self) -> str:
        """The record line, without its line end."""
        if self.jerk_limited:
            return f"# schedule timed by {self.method}: jerk limited"
        return f"# schedule timed by {self.method}: jerk not limited (velocity and acceleration are)"

    @classmethod
    def of(cls, schedule: Schedule | GraphSchedule) -> ScheduleRecord:
        """The record of ``schedule``: its method's name (made ASCII without ``:``) and its jerk."""
        name = str(getattr(schedule.method, "name", "unknown"))
        name = "".join(c if c.isascii() and c.isprintable() and c != ":" else "?" for c in name).strip()
        return cls(name or "unknown", bool(schedule.jerk_limited))

    @classmethod
    def parse(cls, line: str) -> ScheduleRecord | None:
        """The record a line states, or ``None`` if it is no record line."""
        found = _RECORD.fullmatch(line.strip())
        if found is None:
            return None
        return cls(found["method"].strip(), found["jerk"] == "limited")


@dataclass(frozen=True, slots=True)
class CsvOptions:
    """How CSV profiles are written.

    Parameters
    ----------
    sample_period : float
        Seconds between rows (default 0.01); the last row is exactly at the goal.
    delimiter : str
        Field separator, one character (default ``;``).
    decimal : str
        Decimal mark, ``.`` or ``,`` (default ``.``); must differ from the delimiter.
    units : Units
        ``m`` (default) or ``mm`` for lengths; time in seconds either way.
    max_rows : int
        Most rows of one profile (default :data:`DEFAULT_MAX_ROWS`); a longer one is refused.
    """

    sample_period: float = 0.01
    delimiter: str = ";"
    decimal: str = "."
    units: Units = Units.METRES
    max_rows: int = DEFAULT_MAX_ROWS

    def __post_init__(self) -> None:
        object.__setattr__(self, "sample_period", check_period(self.sample_period))
        if isinstance(self.max_rows, bool) or not isinstance(self.max_rows, int) or self.max_rows < 1:
            raise OptionError(f"CSV max_rows must be an integer >= 1, got {short_repr(self.max_rows)}")
        if not _usable_delimiter(self.delimiter):
            raise OptionError(
                f"CSV delimiter {short_repr(self.delimiter)} is not usable: expected one ASCII character "
                "that is no letter, digit, sign, '_', '.', quote or line break (e.g. ';', ',', tab)"
            )
        if self.decimal not in (".", ","):
            raise OptionError(
                f"CSV decimal mark {short_repr(self.decimal)} is not supported: expected '.' or ','"
            )
        if self.decimal == self.delimiter:
            raise OptionError(
                f"CSV decimal mark and delimiter are both {self.decimal!r}: expected different characters"
            )
        if not isinstance(self.units, Units):
            object.__setattr__(self, "units", Units.lookup(self.units))


def _usable_delimiter(value: object) -> bool:
    """One ASCII character that occurs in no header and no number: tab, space or punctuation."""
    if not isinstance(value, str) or len(value) != 1:
        return False
    return value in "\t " or (
        value.isascii() and value.isprintable() and not value.isalnum() and value not in "_.-+\"'"
    )


def format_block(
    track: TrackGraph,
    state: TrackState,
    vehicle: int,
    options: CsvOptions,
    *,
    limits: VehicleLimits | None = None,
    jerk_limited: bool = True,
) -> bytes:
    """Rows of one vehicle's CSV profile for the sampled ``state`` on ``track``: ASCII, CRLF after each row.

    Numbers as :func:`~trajgen.export.numbers.fixed_point_text` writes them (time with 6 decimals,
    lengths with ``options.units.decimals``), the decimal mark and delimiter of ``options``; formatted
    with numpy (:func:`~trajgen.export.numbers.format_number_rows`). With ``limits`` the velocity,
    acceleration and (if ``jerk_limited``) jerk are held to them as written
    (:func:`~trajgen.export.limited.limited_columns`). The columns are
    :func:`~trajgen.export.rows.header`'s.

    Parameters
    ----------
    track : TrackGraph
        The schedule's track (:attr:`~trajgen.model.schedule.Schedule.track`; a star's, its track graph).
    state : TrackState
        The vehicles at n sample times.
    vehicle : int
        Index of the vehicle.
    options : CsvOptions
    limits : VehicleLimits, optional
        The vehicle's limits (a schedule's export); ``None``: the values as they are (executed motion).
    jerk_limited : bool, optional
        Whether the jerk column is held to ``limits`` too (default True).

    Returns
    -------
    bytes
        n rows.
    """
    return format_rows_block(
        track,
        state,
        vehicle,
        delimiter=options.delimiter,
        decimal=options.decimal,
        scale=options.units.scale,
        decimals=options.units.decimals,
        limits=limits,
        jerk_limited=jerk_limited,
    )


def format_rows(track: TrackGraph, state: TrackState, vehicle: int, options: CsvOptions) -> list[str]:
    """Rows of one vehicle's CSV profile for the sampled ``state`` on ``track``, without line ends.

    Also the format of executed motion (``trajgen simulate --trace``); :func:`format_block` gives the
    same rows as bytes.
    """
    return format_block(track, state, vehicle, options).decode("ascii").split("\r\n")[:-1]


def profile_rows(duration: float, options: CsvOptions) -> int:
    """Rows (header excluded) of a profile of a ``duration``-second schedule."""
    return sample_rows(duration, options.sample_period)


def check_row_limit(duration: float, options: CsvOptions, *, lower_bound: bool = False) -> int:
    """Rows of a profile of ``duration`` seconds, if within ``options.max_rows``; else raise.

    Raises
    ------
    OutputLimitError
        More rows than ``options.max_rows`` (say which option to change).
    """
    ratio = duration / options.sample_period
    rows = math.floor(ratio + 1e-9) + 1 if math.isfinite(ratio) else math.inf
    if not rows <= options.max_rows:  # the rows at 0, every period, and the goal's (rows of the sample grid)
        what = "at least " if lower_bound else ""
        raise OutputLimitError(
            f"a CSV profile of this {'scenario' if lower_bound else 'schedule'} has {what}{rows:,.0f} rows "
            f"({duration:.6g} s every {options.sample_period:g} s): expected at most max_rows "
            f"{options.max_rows:,} {_ROW_LIMIT_REMEDY}"
        )
    rows = profile_rows(duration, options)
    if rows > options.max_rows:  # the last row at the goal, after the grid
        raise OutputLimitError(
            f"a CSV profile of this schedule has {rows:,} rows: "
            f"expected at most max_rows {options.max_rows:,} {_ROW_LIMIT_REMEDY}"
        )
    return rows


class _SampledBlocks:
    """Both vehicles' states, a block of :data:`ROWS_PER_CHUNK` rows at a time; the last block is kept.

    Shared by both vehicles' chunk iterators: consumed in step, each block is sampled once.
    """

    def __init__(self, schedule: Schedule, period: float) -> None:
        self.schedule = schedule
        self.period = period
        self.first: int | None = None
        self.state: TrackState | None = None

    def block(self, first: int) -> TrackState:
        """The states of rows ``first`` to ``first + ROWS_PER_CHUNK - 1``."""
        if first != self.first:
            times = sample_block(self.schedule.duration, self.period, first, first + ROWS_PER_CHUNK)
            self.state, self.first = self.schedule.state(times), first
        return self.state


def _checked(
    verified: VerifiedSchedule, options: CsvOptions | None, caller: str
) -> tuple[Schedule, CsvOptions]:
    schedule = require_verified(verified, caller).schedule
    options = CsvOptions() if options is None else options
    if not isinstance(options, CsvOptions):
        raise OptionError(f"CSV options must be CsvOptions, got {type(options).__name__}")
    check_edge_names(schedule.track, options.delimiter)
    return schedule, options


def _chunks(
    schedule: Schedule | GraphSchedule, vehicle: int, options: CsvOptions, rows: int, blocks: _SampledBlocks
) -> Iterator[bytes]:
    limits, jerk_limited = schedule.limits.vehicles[vehicle], schedule.jerk_limited
    if not jerk_limited:  # said in the file, so that a check of it knows (a jerk-limited one: as before 0.7)
        yield (ScheduleRecord.of(schedule).line() + "\r\n").encode("ascii")
    track = schedule.track
    yield (options.delimiter.join(header(track, options.units.value)) + "\r\n").encode("ascii")
    for first in range(0, rows, ROWS_PER_CHUNK):
        yield format_block(
            track, blocks.block(first), vehicle, options, limits=limits, jerk_limited=jerk_limited
        )


def profile_chunks(
    verified: VerifiedSchedule, vehicle: int, options: CsvOptions | None = None
) -> Iterator[bytes]:
    """One vehicle's CSV profile as chunks of ASCII bytes: header, one row per sample, CRLF after every line.

    The file of a schedule that does not limit jerk begins with its record line
    (:class:`ScheduleRecord`), before the header.

    Memory is bounded by :data:`ROWS_PER_CHUNK` rows, whatever the duration.

    Raises
    ------
    OutputLimitError
        The profile would have more than ``options.max_rows`` rows (raised at once, not when iterating).
    """
    check_vehicle_index(vehicle, require_verified(verified, "profile_chunks").schedule.limits.count)
    schedule, options = _checked(verified, options, "profile_chunks")
    rows = check_row_limit(schedule.duration, options)
    return _chunks(schedule, vehicle, options, rows, _SampledBlocks(schedule, options.sample_period))


def profile_chunk_pair(
    verified: VerifiedSchedule, options: CsvOptions | None = None
) -> tuple[Iterator[bytes], ...]:
    """Each vehicle's CSV profile as chunks (as :func:`profile_chunks`), sampling each block once.

    One iterator per vehicle, in the schedule's order. They share the sampled states of the block of
    rows they are at: taken in step, a chunk of each in turn (as
    :func:`~trajgen.export.atomic.commit_files` does), each block of :data:`ROWS_PER_CHUNK` rows is
    sampled once for every file. Taken otherwise, the chunks are the same, only sampled again.
    Memory stays bounded by one block.

    Raises
    ------
    OutputLimitError
        The profiles would have more than ``options.max_rows`` rows (raised at once).
    """
    schedule, options = _checked(verified, options, "profile_chunk_pair")
    rows = check_row_limit(schedule.duration, options)
    blocks = _SampledBlocks(schedule, options.sample_period)
    return tuple(_chunks(schedule, v, options, rows, blocks) for v in range(schedule.limits.count))


def render_profile(verified: VerifiedSchedule, vehicle: int, options: CsvOptions | None = None) -> bytes:
    """One vehicle's whole CSV profile as bytes (see :func:`profile_chunks` to stream it).

    Parameters
    ----------
    verified : VerifiedSchedule
    vehicle : int
        0 for vehicle 1, 1 for vehicle 2.
    options : CsvOptions, optional

    Returns
    -------
    bytes
        ASCII text.
    """
    return b"".join(profile_chunks(verified, vehicle, options))


def profile_paths(names: Sequence[str], directory: str | Path) -> tuple[Path, ...]:
    """``directory/<name>.csv`` for each vehicle, in the order of ``names``.

    Raises
    ------
    InputError
        Not portable, distinct file names (:func:`trajgen.scenario.naming.check_vehicle_names`).
    """
    names = check_vehicle_names(names)
    if not isinstance(directory, (str, Path)) or str(directory) == "":
        raise InputError(f"CSV folder must name a folder, got {short_repr(directory)}")
    directory = Path(directory)
    return tuple(directory / f"{name}.csv" for name in names)


def write_profiles(
    verified: VerifiedSchedule,
    names: Sequence[str],
    directory: str | Path,
    *,
    options: CsvOptions | None = None,
) -> tuple[Path, ...]:
    """Write ``directory/<name>.csv`` for each vehicle, all or none.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verification.certify`.
    names : sequence of str
        Vehicle names, one per vehicle of the schedule, used as file names.
    directory : path
        Created if missing.
    options : CsvOptions, optional

    Returns
    -------
    tuple of Path
        The files written, one per vehicle.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names, options or output folder; nothing was written.
    """
    check_vehicle_names(names, count=require_verified(verified, "write_profiles").schedule.limits.count)
    paths = profile_paths(names, directory)
    commit_files(dict(zip(paths, profile_chunk_pair(verified, options), strict=True)))
    return paths
