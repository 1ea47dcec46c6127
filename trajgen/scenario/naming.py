"""Vehicle names that are portable file names (they name the CSV files)."""

from __future__ import annotations

import re
from collections.abc import Sequence

from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = ["check_vehicle_name", "check_vehicle_names"]

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


def check_vehicle_names(names: Sequence[str]) -> tuple[str, str]:
    """Return the two vehicle names if both are portable file names and distinct, else raise.

    A portable name has 1 to 64 characters: letters, digits, ``_``, ``.``,
    ``-``, starting with a letter or digit and not ending with ``.``; it is no
    Windows device name (``CON``, ``NUL``, ``COM1``, ...); the two names
    differ also when case is ignored.

    Raises
    ------
    InputError
        Naming the name and what was expected.

    Examples
    --------
    >>> check_vehicle_names(["agv1", "agv2"])
    ('agv1', 'agv2')
    """
    if isinstance(names, (str, bytes)) or not isinstance(names, Sequence) or len(names) != 2:
        raise InputError(f"vehicle names must be a pair of names, got {short_repr(names)}")
    for name in names:
        check_vehicle_name(name)
    if names[0].casefold() == names[1].casefold():
        raise InputError(
            f"vehicle names {names[0]!r} and {names[1]!r} name the same file where case is ignored: "
            "expected distinct names"
        )
    return names[0], names[1]
