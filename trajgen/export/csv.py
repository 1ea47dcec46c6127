"""CSV speed profiles for AGV PLCs, one file per vehicle (the ``generic`` format).

Renderers return bytes and take only a :class:`~trajgen.verify.VerifiedSchedule`;
:func:`write_profiles` commits both files together
(:func:`~trajgen.export.atomic.commit_files`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from topology import JUNCTION_INDEX, Option
from trajgen.errors import InputError, OptionError
from trajgen.export.atomic import commit_files
from trajgen.schedule import Schedule, ScheduleState, check_period
from trajgen.verify import VerifiedSchedule, require_verified

__all__ = ["HEADER_NAMES", "CsvOptions", "Units", "profile_paths", "render_profile", "write_profiles"]


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
    angle = angles[np.where(leg == JUNCTION_INDEX, 0, leg)]
    return s * np.cos(angle), s * np.sin(angle)


def _rows(schedule: Schedule, vehicle: int, options: CsvOptions) -> list[str]:
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


def render_profile(verified: VerifiedSchedule, vehicle: int, options: CsvOptions | None = None) -> bytes:
    """One vehicle's CSV profile: header, one row per sample period, CRLF after every line.

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
    schedule = require_verified(verified, "render_profile").schedule
    if vehicle not in (0, 1):
        raise InputError(f"vehicle must be 0 or 1, got {vehicle!r}")
    return ("\r\n".join(_rows(schedule, vehicle, options or CsvOptions())) + "\r\n").encode("ascii")


def profile_paths(names: Sequence[str], directory: str | Path) -> tuple[Path, Path]:
    """``directory/<name>.csv`` for both vehicles.

    Raises
    ------
    InputError
        Not two distinct names.
    """
    if isinstance(names, str) or len(names) != 2 or names[0] == names[1]:
        raise InputError(f"vehicle names must be two distinct names, got {names!r}")
    directory = Path(directory)
    return (directory / f"{names[0]}.csv", directory / f"{names[1]}.csv")


def write_profiles(
    verified: VerifiedSchedule,
    names: Sequence[str],
    directory: str | Path,
    *,
    options: CsvOptions | None = None,
) -> tuple[Path, Path]:
    """Write ``directory/<name>.csv`` for both vehicles, both or neither.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verify.certify`.
    names : sequence of 2 str
        Vehicle names, used as file names.
    directory : path
        Created if missing.
    options : CsvOptions, optional

    Returns
    -------
    (Path, Path)
        The two files written.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names, options or output folder; nothing was written.
    """
    require_verified(verified, "write_profiles")
    paths = profile_paths(names, directory)
    commit_files({path: render_profile(verified, vehicle, options) for vehicle, path in enumerate(paths)})
    return paths
