"""Vehicle names that are portable file names (they name the CSV files)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from numbers import Integral

from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = ["check_vehicle_index", "check_vehicle_name", "check_vehicle_names"]

_PORTABLE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
#: Names Windows reserves for devices, with any extension.
_RESERVED = {"con", "prn", "aux", "nul"} | {f"{kind}{n}" for kind in ("com", "lpt") for n in range(10)}


def check_vehicle_name(name: object) -> str:
    """Return ``name`` if it is a portable file name (see :func:`check_vehicle_names`), else raise."""
    if not isinstance(name, str) or not _PORTABLE.fullmatch(name) or name.endswith("."):
        raise InputError(
            f"vehicle name {short_repr(name)} is not a portable file name: expected 1-64 letters, digits, "
            "'_', '.' or '-', starting with a letter or digit and not ending with '.'"
        )
    if name.split(".")[0].lower() in _RESERVED:
        raise InputError(
            f"vehicle name {short_repr(name)} is a reserved device name on Windows: choose another"
        )
    return name


def check_vehicle_names(names: Sequence[str], *, count: int | None = None) -> tuple[str, ...]:
    """Return the vehicle names if each is a portable file name and all are distinct, else raise.

    A portable name has 1 to 64 characters: letters, digits, ``_``, ``.``,
    ``-``, starting with a letter or digit and not ending with ``.``; it is no
    Windows device name (``CON``, ``NUL``, ``COM1``, ...); no two names
    differ only in case (they name files, and some file systems ignore case).

    Parameters
    ----------
    names : sequence of str
        One per vehicle, at least one.
    count : int, optional
        How many vehicles the names are for (a schedule's): that many names are expected.

    Raises
    ------
    InputError
        Naming the name and what was expected.

    Examples
    --------
    >>> check_vehicle_names(["agv1", "agv2"])
    ('agv1', 'agv2')
    """
    if isinstance(names, (str, bytes)) or not isinstance(names, Sequence) or not names:
        raise InputError(
            f"vehicle names must be a sequence of names, one per vehicle, got {short_repr(names)}"
        )
    if count is not None and len(names) != count:
        raise InputError(f"vehicle names {short_repr(names)}: expected {count}, one per vehicle")
    seen: dict[str, str] = {}
    for name in names:
        check_vehicle_name(name)
        key = name.casefold()
        if key in seen:
            raise InputError(
                f"vehicle names {seen[key]!r} and {name!r} name the same file where case is ignored: "
                "expected distinct names"
            )
        seen[key] = name
    return tuple(names)


def check_vehicle_index(vehicle: object, count: int) -> int:
    """Return ``vehicle`` if it indexes one of ``count`` vehicles (0 for vehicle 1), else raise.

    Raises
    ------
    InputError
        Not an integer from 0 to ``count - 1``.

    Examples
    --------
    >>> check_vehicle_index(1, 2)
    1
    """
    if isinstance(vehicle, bool) or not isinstance(vehicle, Integral) or not 0 <= vehicle < count:
        raise InputError(
            f"vehicle must be an index from 0 to {count - 1} (one of {count} vehicles), "
            f"got {short_repr(vehicle)}"
        )
    return int(vehicle)
