"""CSV speed profiles for AGV PLCs, one file per vehicle, written atomically.

Every schedule is verified (:func:`trajgen.verify.verified`) before a byte is
written; a schedule that fails raises and nothing is written. All files of one
export are first written to temporary files in the target directory and only
then renamed into place, so a failure leaves no partial file behind.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from topology.errors import InputError, OptionError
from topology.options import Option
from trajgen.schedule import Schedule, ScheduleState, check_period
from trajgen.verify import VerificationReport, verified

__all__ = ["HEADER_NAMES", "CsvOptions", "Units", "atomic_write_files", "profile_rows", "write_profiles"]


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


#: Column names per unit.
HEADER_NAMES = {
    Units.METRES: ("t_s", "axis_m", "v_mps", "a_mps2", "j_mps3", "leg", "s_m", "x_m", "y_m"),
    Units.MILLIMETRES: ("t_s", "axis_mm", "v_mmps", "a_mmps2", "j_mmps3", "leg", "s_mm", "x_mm", "y_mm"),
}


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
    """

    sample_period: float = 0.01
    delimiter: str = ";"
    decimal: str = "."
    units: Units = Units.METRES

    def __post_init__(self) -> None:
        object.__setattr__(self, "sample_period", check_period(self.sample_period))
        if (
            not isinstance(self.delimiter, str)
            or len(self.delimiter) != 1
            or self.delimiter in '\r\n"0123456789-+'
        ):
            raise OptionError(
                f"CSV delimiter {self.delimiter!r} is not usable: expected one character, not a digit, sign, "
                "quote or line break (e.g. ';', ',', tab)"
            )
        if self.decimal not in (".", ","):
            raise OptionError(f"CSV decimal mark {self.decimal!r} is not supported: expected '.' or ','")
        if self.decimal == self.delimiter:
            raise OptionError(
                f"CSV decimal mark and delimiter are both {self.decimal!r}: expected different characters"
            )
        if not isinstance(self.units, Units):
            object.__setattr__(self, "units", Units.lookup(self.units))


def _xy(schedule: Schedule, state: ScheduleState, vehicle: int) -> tuple[np.ndarray, np.ndarray]:
    angles = np.radians(np.array(schedule.route.graph.angles_deg))
    leg = state.leg[vehicle]
    s = state.s[vehicle]
    angle = angles[np.maximum(leg, 0)]
    return s * np.cos(angle), s * np.sin(angle)


def profile_rows(schedule: Schedule, vehicle: int, options: CsvOptions) -> list[str]:
    """The lines of one vehicle's CSV profile (header first), without line ends."""
    state = schedule.sample(options.sample_period)
    scale = options.units.scale
    x, y = _xy(schedule, state, vehicle)
    columns = [
        (state.t, 6),
        (state.axis[vehicle] * scale, options.units.decimals),
        (state.velocity[vehicle] * scale, options.units.decimals),
        (state.acceleration[vehicle] * scale, options.units.decimals),
        (state.jerk[vehicle] * scale, options.units.decimals),
        None,  # leg
        (state.s[vehicle] * scale, options.units.decimals),
        (x * scale, options.units.decimals),
        (y * scale, options.units.decimals),
    ]
    legs = (state.leg[vehicle] + 1).tolist()  # 1-based leg index, 0 at the junction
    formatted = []
    for column in columns:
        if column is None:
            formatted.append([str(v) for v in legs])
            continue
        values, decimals = column
        text = [f"{round(float(v), decimals) + 0.0:.{decimals}f}" for v in values]  # + 0.0: no "-0"
        if options.decimal != ".":
            text = [t.replace(".", options.decimal) for t in text]
        formatted.append(text)
    lines = [options.delimiter.join(HEADER_NAMES[options.units])]
    lines += [options.delimiter.join(fields) for fields in zip(*formatted, strict=True)]
    return lines


def atomic_write_files(contents: dict[Path, bytes]) -> None:
    """Write several files so that either all appear complete or none is changed.

    Each file is written to a temporary file in its own directory, flushed,
    then all are renamed into place.
    """
    staged: list[tuple[str, Path]] = []
    try:
        for path, data in contents.items():
            path.parent.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
            staged.append((temporary, path))
            os.chmod(temporary, 0o666 & ~_umask())  # mkstemp makes 0600; files are for other tools too
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
                stream.flush()
                os.fsync(stream.fileno())
        for temporary, path in staged:
            os.replace(temporary, path)
        staged.clear()
    finally:
        for temporary, _ in staged:
            if os.path.exists(temporary):
                os.unlink(temporary)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_profiles(
    schedule: Schedule, names: Sequence[str], directory: str | Path, *, options: CsvOptions | None = None
) -> tuple[VerificationReport, tuple[Path, Path]]:
    """Verify a schedule, then write ``directory/<name>.csv`` for both vehicles.

    Parameters
    ----------
    schedule : Schedule
    names : sequence of 2 str
        Vehicle names, used as file names.
    directory : path
        Created if missing.
    options : CsvOptions, optional

    Returns
    -------
    (VerificationReport, (Path, Path))
        The passed verification and the two files written.

    Raises
    ------
    VerificationError
        The schedule failed verification; nothing was written.
    InputError
        Bad names or options.
    """
    options = options or CsvOptions()
    if len(names) != 2 or names[0] == names[1]:
        raise InputError(f"vehicle names must be two distinct names, got {list(names)!r}")
    report = verified(schedule)
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise InputError(f"CSV output {str(directory)!r} exists and is not a directory")
    paths = (directory / f"{names[0]}.csv", directory / f"{names[1]}.csv")
    contents = {
        path: ("\r\n".join(profile_rows(schedule, vehicle, options)) + "\r\n").encode("ascii")
        for vehicle, path in enumerate(paths)
    }
    atomic_write_files(contents)
    return report, paths
