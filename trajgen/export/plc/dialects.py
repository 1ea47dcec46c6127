"""PLC dialects of the profile files: one writer and one reader per controller's format.

Every dialect is a peer behind :class:`Dialect`, found through :data:`DIALECTS`:

- ``generic``: the CSV of :mod:`trajgen.export.csv`, one row per sample period (no resampling);
- ``twincat-cam``: Beckhoff TwinCAT non-equidistant cam table (``MC_CAM_REF``), linear;
- ``codesys-xy``: CODESYS SoftMotion non-equidistant XY cam table as text, linear;
- ``logix-time-cam``: Rockwell Logix time cam rows ``Master,Slave,SegmentType`` (cubic);
- ``siemens-xy``: x/y interpolation points for a SIMATIC ``TO_Cam`` / ``TO_Cam_10k``, linear;
- ``velocity-profile``: (time, velocity) pairs for PLCopen ``MC_VelocityProfile``.

The cam dialects write master = time in seconds and slave = the vehicle's axis
in millimetres (the velocity profile: mm/s), nine decimals, one point per
line; ``docs/formats/`` gives each format with its public source. Readers are
strict: what a controller would reject or misread is reported.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from topology import Option
from topology.validation import short_repr
from trajgen.errors import OptionError, ProfileFileError
from trajgen.export.csv import HEADER_NAMES, ScheduleRecord, Units
from trajgen.export.numbers import format_number_rows
from trajgen.export.plc.tables import Interpolation, ProfileTable
from trajgen.export.rows import GRAPH_HEADER_NAMES
from trajgen.lazy import RenamedAttribute

__all__ = [
    "DIALECTS",
    "Dialect",
    "DialectName",
    "DialectRegistry",
    "GenericDialect",
    "ParsedProfile",
    "TableDialect",
]

#: Decimal places of the times and values the table dialects write.
DECIMALS = 9
#: The columns of the generic CSV, in order (:data:`~trajgen.export.csv.HEADER_NAMES`); on a track
#: graph ``edge`` (the name) stands where ``leg`` does, and ``x``, ``y`` are there with coordinates only.
GENERIC_COLUMNS = ("t", "axis", "v", "a", "j", "leg", "s", "x", "y")
#: Where the leg, or a track graph's edge name, is among the columns.
EDGE_COLUMN = 5


class DialectName(Option):
    """Name of a profile file dialect (``--dialect``)."""

    @classmethod
    def label(cls) -> str:
        """``dialect``, as the option is called."""
        return "dialect"

    GENERIC = "generic"
    TWINCAT_CAM = "twincat-cam"
    CODESYS_XY = "codesys-xy"
    LOGIX_TIME_CAM = "logix-time-cam"
    SIEMENS_XY = "siemens-xy"
    VELOCITY_PROFILE = "velocity-profile"


@dataclass(frozen=True, slots=True)
class ParsedProfile:
    """A profile file as read: the table, and what in its format a controller would not take.

    Attributes
    ----------
    table : ProfileTable
    problems : tuple of str
        Format deviations (line ends, header, point count), each naming the line.
    columns : dict of str to ndarray, or None
        Every column of a ``generic`` file in SI units (``t``, ``axis``, ``v``, ``a``, ``j``,
        ``leg`` (1-based, 0 at the junction), ``s``, ``x``, ``y``), shape (n,) each; on a track
        graph ``edge`` (names, dtype object) instead of ``leg``, and ``x``, ``y`` only if written.
    record : ScheduleRecord or None
        What a ``generic`` file records of its schedule on the line before its header (its method,
        whether it limits jerk); ``None``: no such line (a jerk-limited schedule's file).
    """

    table: ProfileTable
    problems: tuple[str, ...]
    columns: dict | None = None
    record: ScheduleRecord | None = None


class Dialect(abc.ABC):
    """Interface of the profile file dialects."""

    __slots__ = ()

    #: ``--dialect NAME``.
    name: ClassVar[DialectName]
    #: One line for the help texts.
    description: ClassVar[str]
    #: Deprecated name of ``description`` (0.7).
    summary = RenamedAttribute("description", "0.7")
    #: The file name suffix.
    suffix: ClassVar[str] = ".csv"

    @property
    @abc.abstractmethod
    def point_limit(self) -> int | None:
        """Most points a table of this dialect has by default (``None``: sampled, no limit)."""

    @property
    @abc.abstractmethod
    def interpolation(self) -> Interpolation:
        """How the controller interpolates the file's points."""

    @abc.abstractmethod
    def read(self, data: bytes, *, source: str) -> ParsedProfile:
        """The table in ``data`` (a whole file) and its format problems.

        Raises
        ------
        ProfileFileError
            The file cannot be read as this dialect (``source`` names it in the message).
        """


def _decode(data: bytes, source: str) -> str:
    if not data:
        raise ProfileFileError(f"{source} is empty: expected a profile table")
    try:
        return data.decode("ascii")
    except UnicodeDecodeError as error:
        raise ProfileFileError(
            f"{source} is not ASCII text (byte {data[error.start]:#04x} at offset {error.start})"
        ) from None


def _lines(text: str, source: str, *, crlf: bool) -> tuple[list[str], list[str]]:
    """The lines of ``text`` and problems with their ends."""
    problems = []
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    elif crlf:
        problems.append(f"{source} line {len(lines)}: no CRLF after the last line, expected one")
    bare = [n + 1 for n, line in enumerate(lines) if not line.endswith("\r")]
    if crlf and bare:
        problems.append(f"{source} line {bare[0]}: ends with LF only, expected CRLF ({len(bare)} such lines)")
    return [line.removesuffix("\r") for line in lines], problems


def _number(field: str, source: str, line: int, what: str) -> tuple[float, int]:
    """A decimal number and its number of decimal places."""
    text = field
    try:
        value = float(text)
    except ValueError:
        raise ProfileFileError(
            f"{source} line {line}: {what} {short_repr(text)} is not a number "
            "(expected digits with '.' as the decimal mark)"
        ) from None
    digits = text.removeprefix("-")
    if not math.isfinite(value) or not digits.replace(".", "", 1).isdigit() or not digits[:1].isdigit():
        raise ProfileFileError(
            f"{source} line {line}: {what} {short_repr(text)} is not a finite decimal number"
        )
    return value, len(text.partition(".")[2])


@dataclass(frozen=True, slots=True)
class TableDialect(Dialect):
    """A table of points ``master<delimiter>slave[<delimiter>extra]``, one per line.

    Parameters
    ----------
    name : DialectName
    description : str
    default_points : int
        Points per table unless ``--max-points`` says otherwise.
    most_points : int or None
        Most points any target of the dialect takes (``--max-points`` may not exceed it).
    table_interpolation : Interpolation
    delimiter : str
    crlf : bool
        CRLF after every line, the last included (else LF).
    header : str or None
        A first line naming the columns.
    extra : str or None
        A third column's value on every line (Logix: the segment type).
    file_suffix : str
    """

    name: DialectName
    description: str
    default_points: int
    most_points: int | None
    table_interpolation: Interpolation
    delimiter: str
    crlf: bool = True
    header: str | None = None
    extra: str | None = None
    file_suffix: str = ".csv"

    @property
    def point_limit(self) -> int:
        """Points per table by default."""
        return self.default_points

    @property
    def interpolation(self) -> Interpolation:
        """How the controller interpolates the points."""
        return self.table_interpolation

    @property
    def suffix(self) -> str:
        """The file name suffix."""
        return self.file_suffix

    @property
    def unit(self) -> str:
        """Unit of the slave column."""
        return "mm/s" if self.table_interpolation is Interpolation.VELOCITY else "mm"

    def check_points(self, max_points: int | None) -> int:
        """``max_points`` (or the default) if this dialect's targets can take that many, else raise.

        Raises
        ------
        OptionError
        """
        if max_points is None:
            return self.default_points
        if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
            raise OptionError(f"max points must be an integer >= 2, got {short_repr(max_points)}")
        if self.most_points is not None and max_points > self.most_points:
            raise OptionError(
                f"max points {max_points:,} is more than dialect {self.name.value!r} takes: "
                f"expected at most {self.most_points:,}"
            )
        return max_points

    def lines(self, table: ProfileTable) -> Iterator[str]:
        """The file's lines, without line ends."""
        end = "\r\n" if self.crlf else "\n"
        yield from self.render(table).decode("ascii").split(end)[:-1]

    def render(self, table: ProfileTable) -> bytes:
        """The whole file as ASCII bytes.

        Times in seconds and slave values in millimetres (mm/s), :data:`DECIMALS` decimals each, as
        :func:`~trajgen.export.numbers.fixed_point_text` writes them.
        """
        end = "\r\n" if self.crlf else "\n"
        header = b"" if self.header is None else (self.header + end).encode("ascii")
        last = end if self.extra is None else self.delimiter + self.extra + end
        values = table.values * 1000.0  # metres to millimetres (m/s to mm/s)
        columns = [(table.times, DECIMALS), (values, DECIMALS)]
        return header + format_number_rows(columns, [self.delimiter, last])

    def read(self, data: bytes, *, source: str) -> ParsedProfile:
        """The table in ``data`` and its format problems (see :meth:`Dialect.read`)."""
        lines, problems = _lines(_decode(data, source), source, crlf=self.crlf)
        first = 1
        if self.header is not None:
            if not lines or lines[0].strip() != self.header:
                raise ProfileFileError(
                    f"{source} line 1: header {short_repr(lines[0] if lines else '')} is not {self.header!r}"
                )
            lines, first = lines[1:], 2
        if not lines:
            raise ProfileFileError(f"{source} has no points: expected at least one line of values")
        columns = 2 if self.extra is None else 3
        times, values, places = np.empty(len(lines)), np.empty(len(lines)), []
        segment_types = set()
        for n, line in enumerate(lines):
            fields = line.split(self.delimiter)
            if len(fields) != columns:
                raise ProfileFileError(
                    f"{source} line {n + first}: {len(fields)} field(s) separated by "
                    f"{self.delimiter!r}, expected {columns} ({short_repr(line)})"
                )
            times[n], _ = _number(fields[0], source, n + first, "master value (time, s)")
            values[n], decimals = _number(fields[1], source, n + first, f"slave value ({self.unit})")
            places.append(decimals)
            if self.extra is not None:
                segment_types.add(fields[2])
        interpolation = self.table_interpolation
        if self.extra is not None:
            interpolation = _logix_interpolation(segment_types, source)
        if times[0] != 0.0:
            raise ProfileFileError(
                f"{source} line {first}: the first master value is {float(times[0])!r} s, expected 0"
            )
        if self.most_points is not None and len(lines) > self.most_points:
            problems.append(f"{source}: {len(lines):,} points, more than {self.most_points:,}")
        # the file's precision: a value written with fewer places (a "0" from a spreadsheet) is exact
        resolution = 0.5 * 10.0 ** -max(places) / 1000.0
        table = ProfileTable(times, values / 1000.0, interpolation, resolution=resolution)
        return ParsedProfile(table, tuple(problems))


def _logix_interpolation(segment_types: set[str], source: str) -> Interpolation:
    """All cubic (1) or all linear (0) segments; a mix is beyond this checker."""
    if segment_types == {"1"}:
        return Interpolation.CUBIC
    if segment_types == {"0"}:
        return Interpolation.LINEAR
    raise ProfileFileError(
        f"{source}: segment types {sorted(segment_types)!r}: expected all 1 (cubic) or all 0 (linear)"
    )


@dataclass(frozen=True, slots=True)
class GenericDialect(Dialect):
    """The generic CSV (:mod:`trajgen.export.csv`): a row per sample period.

    Read as a cubic Hermite table: between two rows the axis is the cubic that
    matches both rows' position and velocity (``axis`` and ``v`` columns).
    """

    name: ClassVar[DialectName] = DialectName.GENERIC
    description: ClassVar[str] = "trajgen's CSV: t, axis, v, a, j, leg, s, x, y every sample period (default)"

    @property
    def point_limit(self) -> None:
        """Sampled, not resampled: the row limit is ``--max-rows``."""
        return None

    @property
    def interpolation(self) -> Interpolation:
        """Rows are read as a cubic Hermite table (position and velocity per row)."""
        return Interpolation.HERMITE

    def read(self, data: bytes, *, source: str) -> ParsedProfile:
        """The ``t``, ``axis`` and ``v`` columns; delimiter, decimal mark and unit from the header row.

        A first line ``# schedule timed by ...`` is the file's record of its schedule
        (:class:`~trajgen.export.csv.ScheduleRecord`); the header follows it.
        """
        lines, problems = _lines(_decode(data, source), source, crlf=True)
        if not lines:
            raise ProfileFileError(f"{source} is empty: expected a header row")
        record = None
        if lines[0].startswith("#"):
            record = ScheduleRecord.parse(lines[0])
            if record is None:
                raise ProfileFileError(
                    f"{source} line 1: {short_repr(lines[0])} is not trajgen's record of its schedule: "
                    f"expected {ScheduleRecord('METHOD', False).line()!r} (or 'jerk limited'), or the header"
                )
            lines = lines[1:]
            if not lines:
                raise ProfileFileError(f"{source} has no header row after its record line: expected one")
        first = 1 if record is None else 2  # the header's line number
        header = lines[0]
        delimiter = header[3:4] if header.startswith("t_s") else ""
        names = header.split(delimiter) if delimiter else []
        units = next((unit for unit, expected in HEADER_NAMES.items() if tuple(names) == expected), None)
        graph = False
        for unit in Units if units is None else ():  # a track graph's: the edge by name, x/y optional
            if tuple(names) in (GRAPH_HEADER_NAMES[unit.value], GRAPH_HEADER_NAMES[unit.value][:7]):
                units, graph = unit, True
        if units is None:
            raise ProfileFileError(
                f"{source} line {first}: header {short_repr(header)} is not trajgen's: expected "
                f"{';'.join(HEADER_NAMES[Units.METRES])!r} (on a track graph "
                f"{';'.join(GRAPH_HEADER_NAMES['m'])!r}; any delimiter, or the mm columns)"
            )
        rows = lines[1:]
        if not rows:
            raise ProfileFileError(f"{source} has no rows: expected at least one")
        comma = delimiter != "," and any("," in row for row in rows[:1])
        columns = np.empty((len(names), len(rows)))
        places = []
        edges: list[str] = []
        for n, row in enumerate(rows):
            fields = row.split(delimiter)
            if len(fields) != len(names):
                if n == len(rows) - 1 and len(fields) < len(names) and not data.endswith(b"\n"):
                    raise ProfileFileError(
                        f"{source}: the file ends early: its last line (line {n + first + 1}) is cut short, "
                        f"{len(fields)} of {len(names)} fields and no line end ({short_repr(row)})"
                    )
                raise ProfileFileError(
                    f"{source} line {n + first + 1}: {len(fields)} field(s) separated by {delimiter!r}, "
                    f"expected {len(names)} ({short_repr(row)})"
                )
            for k, field in enumerate(fields):
                if graph and k == EDGE_COLUMN:
                    edges.append(field)
                    columns[k, n] = 0.0
                    continue
                columns[k, n], decimals = _number(
                    field.replace(",", ".") if comma else field, source, n + first + 1, names[k]
                )
                if k == 1:
                    places.append(decimals)
        if columns[0, 0] != 0.0:
            raise ProfileFileError(
                f"{source} line {first + 1}: the first time is {float(columns[0, 0])!r} s, expected 0"
            )
        legs = columns[EDGE_COLUMN]
        if not graph and not np.all(legs == np.round(legs)):
            bad = int(np.argmax(legs != np.round(legs)))
            raise ProfileFileError(
                f"{source} line {bad + first + 1}: leg {legs[bad]!r} is not a whole number"
            )
        resolution = 0.5 * 10.0 ** -max(places) / units.scale
        scaled = {
            name: columns[k] / (1.0 if k in (0, EDGE_COLUMN) else units.scale)
            for k, name in enumerate(GENERIC_COLUMNS[: len(names)])
        }
        if graph:
            del scaled["leg"]
            scaled["edge"] = np.array(edges, dtype=object)
        table = ProfileTable(
            columns[0],
            scaled["axis"],
            Interpolation.HERMITE,
            resolution=resolution,
            velocities=scaled["v"],
        )
        return ParsedProfile(table, tuple(problems), scaled, record)


class DialectRegistry:
    """The dialects by name, in a fixed order; ``generic`` is the default.

    Examples
    --------
    >>> DIALECTS.lookup("TwinCAT-Cam").point_limit
    10000
    """

    __slots__ = ("_by_name",)

    def __init__(self, dialects: tuple[Dialect, ...]) -> None:
        self._by_name = {dialect.name: dialect for dialect in dialects}

    @property
    def names(self) -> tuple[str, ...]:
        """Dialect names, in registration order."""
        return tuple(name.value for name in self._by_name)

    def __iter__(self) -> Iterator[Dialect]:
        return iter(self._by_name.values())

    def lookup(self, name: object) -> Dialect:
        """The dialect named ``name`` (case-insensitive), or ``name`` itself if it is one.

        Raises
        ------
        OptionError
            Naming the value and the accepted names.
        """
        if isinstance(name, Dialect):
            return name
        return self._by_name[DialectName.lookup(name)]

    def help(self) -> str:
        """One line per dialect for help texts."""
        lines = []
        for dialect in self:
            limit = "" if dialect.point_limit is None else f" [{dialect.point_limit:,} points]"
            lines.append(f"{dialect.name.value}: {dialect.description}{limit}")
        return "\n".join(lines)


#: Every dialect, ``generic`` first (the default).
DIALECTS = DialectRegistry(
    (
        GenericDialect(),
        TableDialect(
            DialectName.TWINCAT_CAM,
            "Beckhoff TwinCAT MC_CAM_REF non-equidistant cam table: s;mm, linear",
            default_points=10_000,
            most_points=None,
            table_interpolation=Interpolation.LINEAR,
            delimiter=";",
        ),
        TableDialect(
            DialectName.CODESYS_XY,
            "CODESYS SoftMotion non-equidistant XY cam table (text): s<TAB>mm, linear",
            default_points=10_000,
            most_points=None,
            table_interpolation=Interpolation.LINEAR,
            delimiter="\t",
            file_suffix=".txt",
        ),
        TableDialect(
            DialectName.LOGIX_TIME_CAM,
            "Rockwell Logix time cam (MCCP/MATC) rows Master,Slave,SegmentType: s,mm,1 (cubic)",
            default_points=1_000,
            most_points=None,
            table_interpolation=Interpolation.CUBIC,
            delimiter=",",
            header="Master,Slave,SegmentType",
            extra="1",
        ),
        TableDialect(
            DialectName.SIEMENS_XY,
            "SIMATIC TO_Cam interpolation points x;y: s;mm, linear (TO_Cam_10k: --max-points 10000)",
            default_points=1_000,
            most_points=10_000,
            table_interpolation=Interpolation.LINEAR,
            delimiter=";",
        ),
        TableDialect(
            DialectName.VELOCITY_PROFILE,
            "PLCopen MC_VelocityProfile (time, velocity) pairs: s;mm/s, velocity linear",
            default_points=100,
            most_points=None,
            table_interpolation=Interpolation.VELOCITY,
            delimiter=";",
        ),
    )
)
