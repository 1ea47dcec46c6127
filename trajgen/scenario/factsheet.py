"""Vehicle limits from a VDA 5050 factsheet (``physicalParameters``).

A scenario's ``[[vehicle]]`` may name a factsheet (``factsheet =
"agv.json"``, relative to the scenario file's folder) in place of
``max_velocity`` and ``max_acceleration``. The factsheet (VDA 5050 2.1.0,
``factsheet.schema``) gives ``speedMax`` (m/s), ``accelerationMax`` and
``decelerationMax`` (m/s², with maximum load). trajgen's limits are
symmetric, so the acceleration limit is the smaller of the two. A factsheet
has no jerk limit: the scenario still gives ``max_jerk``.

Only ``physicalParameters`` is read; the rest of the factsheet is not checked
(validate it against the VDA 5050 schema with your fleet tools).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.scenario.reading import FileKind, file_label, read_bounded

__all__ = ["FACTSHEET_KEYS", "MAX_FACTSHEET_BYTES", "FactsheetLimits", "read_factsheet"]

#: Largest factsheet file read, bytes; a larger one is refused unread.
MAX_FACTSHEET_BYTES = 1 << 20
#: How factsheets are read (:func:`~trajgen.scenario.reading.read_bounded`).
FACTSHEET_FILE = FileKind("a factsheet", "a VDA 5050 factsheet JSON file", MAX_FACTSHEET_BYTES)
#: The keys of ``physicalParameters`` that are read.
FACTSHEET_KEYS = ("speedMax", "accelerationMax", "decelerationMax")


@dataclass(frozen=True, slots=True)
class FactsheetLimits:
    """The drive limits a VDA 5050 factsheet gives.

    Attributes
    ----------
    speed_max : float
        ``physicalParameters.speedMax``, m/s.
    acceleration_max : float
        ``physicalParameters.accelerationMax``, m/s².
    deceleration_max : float
        ``physicalParameters.decelerationMax``, m/s².
    source : str
        The file read.
    """

    speed_max: float
    acceleration_max: float
    deceleration_max: float
    source: str

    @property
    def max_acceleration(self) -> float:
        """The symmetric acceleration limit, m/s²: the smaller of acceleration and deceleration."""
        return min(self.acceleration_max, self.deceleration_max)


def _refuse_constant(name: str) -> float:
    raise ValueError(f"{name} is not a JSON number")


def _unique_keys(pairs: list[tuple[str, object]]) -> dict:
    keys = [key for key, _ in pairs]
    for key in keys:
        if keys.count(key) > 1:
            raise ValueError(f"key {key!r} is given twice")
    return dict(pairs)


def _parse(data: bytes, label: str) -> dict:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(
            f"factsheet {label}: is not UTF-8 text: byte {data[error.start]:#04x} at offset {error.start}"
        ) from None
    try:
        document = json.loads(text, parse_constant=_refuse_constant, object_pairs_hook=_unique_keys)
    except RecursionError:
        raise InputError(f"factsheet {label}: not a factsheet: arrays or objects nested too deeply") from None
    except ValueError as error:  # json.JSONDecodeError is a ValueError, and so are the hooks' errors
        raise InputError(f"factsheet {label}: not valid JSON: {error}") from None
    if not isinstance(document, dict):
        raise InputError(
            f"factsheet {label}: the document is {type(document).__name__} {short_repr(document)}: "
            "expected a JSON object (a VDA 5050 factsheet)"
        )
    return document


def read_factsheet(
    path: str | Path,
    *,
    velocity_range: tuple[float, float],
    acceleration_range: tuple[float, float],
) -> FactsheetLimits:
    """Read ``speedMax``, ``accelerationMax`` and ``decelerationMax`` from a VDA 5050 factsheet.

    Parameters
    ----------
    path : str or Path
        The factsheet file: a regular file of at most :data:`MAX_FACTSHEET_BYTES`, UTF-8 JSON.
    velocity_range : (float, float)
        Accepted ``speedMax``, m/s (inclusive).
    acceleration_range : (float, float)
        Accepted ``accelerationMax`` and ``decelerationMax``, m/s² (inclusive).

    Returns
    -------
    FactsheetLimits

    Raises
    ------
    InputError
        The file is missing, unreadable, too large, not UTF-8, not JSON, or
        ``physicalParameters`` or one of its three keys is missing, not a
        number, or outside its range; the message names the file, the key,
        the value and what was expected.
    """
    if not isinstance(path, (str, Path)) or str(path) == "":
        raise InputError(f"factsheet path must name a file, got {short_repr(path)}")
    path = Path(path)
    label = file_label(path)
    document = _parse(read_bounded(path, f"factsheet {label}", FACTSHEET_FILE), label)
    parameters = document.get("physicalParameters")
    if parameters is None:
        raise InputError(
            f"factsheet {label}: has no 'physicalParameters': "
            f"expected an object with {list(FACTSHEET_KEYS)!r}"
        )
    if not isinstance(parameters, dict):
        raise InputError(
            f"factsheet {label}: 'physicalParameters' is {type(parameters).__name__} "
            f"{short_repr(parameters)}: expected an object with {list(FACTSHEET_KEYS)!r}"
        )
    ranges = {
        "speedMax": (velocity_range, "m/s"),
        "accelerationMax": (acceleration_range, "m/s^2"),
        "decelerationMax": (acceleration_range, "m/s^2"),
    }
    values = {}
    for key in FACTSHEET_KEYS:
        (low, high), unit = ranges[key]
        if key not in parameters:
            raise InputError(
                f"factsheet {label}: physicalParameters has no {key!r}: expected a number of {unit} "
                f"from {low:g} to {high:g}"
            )
        value = parameters[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(
                f"factsheet {label}: physicalParameters.{key} is {type(value).__name__} {short_repr(value)}: "
                f"expected a number of {unit} from {low:g} to {high:g}"
            )
        try:
            number = float(value)
        except OverflowError:  # an integer beyond any float
            number = math.nan
        if not low <= number <= high:
            raise InputError(
                f"factsheet {label}: physicalParameters.{key} is {short_repr(value)}: "
                f"expected {low:g} to {high:g} {unit}"
            )
        values[key] = number
    return FactsheetLimits(
        values["speedMax"], values["accelerationMax"], values["decelerationMax"], str(path)
    )
