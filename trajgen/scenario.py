"""Scenario files (TOML): track, separation, and two vehicles with limits, start and goal.

Example (``examples/swap.toml``)::

    [track]
    legs = { A = 10.0, B = 10.0, C = 10.0 }          # metres, counterclockwise order
    angles_deg = { A = 90.0, B = 210.0, C = 330.0 }  # optional

    [safety]
    min_separation = 1.5                             # metres along the track

    [[vehicle]]
    name = "agv1"
    max_velocity = 1.0
    max_acceleration = 0.5
    max_jerk = 1.0
    start = "A:10.0"
    goal = "B:10.0"

    [[vehicle]]
    ...
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from limits import Limits, VehicleLimits
from topology import Configuration, Position, Route, YGraph, plan
from trajgen.errors import InputError, ScenarioError

__all__ = ["DEFAULT_SCENARIO_NAME", "Scenario", "default_scenario", "load_scenario", "parse_scenario"]

DEFAULT_SCENARIO_NAME = "swap.toml"

_VEHICLE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
_TOP_KEYS = {"track": True, "safety": True, "vehicle": True}
_TRACK_KEYS = {"legs": True, "angles_deg": False}
_SAFETY_KEYS = {"min_separation": True}
_VEHICLE_KEYS = {
    "name": True,
    "max_velocity": True,
    "max_acceleration": True,
    "max_jerk": True,
    "start": True,
    "goal": True,
}


@dataclass(frozen=True, slots=True)
class Scenario:
    """A complete planning problem.

    Attributes
    ----------
    track : YGraph
    limits : Limits
        Both vehicles' limits and the minimum separation.
    names : tuple of 2 str
        Vehicle names (file names of their CSV profiles).
    start, goal : Configuration
    source : str
        Where it came from (file path or ``<built-in swap.toml>``).
    """

    track: YGraph
    limits: Limits
    names: tuple[str, str]
    start: Configuration
    goal: Configuration
    source: str

    def plan(self) -> Route:
        """The planner's route from start to goal, keeping the scenario's minimum separation."""
        return plan(self.track, self.start, self.goal, min_separation=self.limits.min_separation)


def _check_keys(table: dict, allowed: dict[str, bool], where: str, source: str) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ScenarioError(
            f"{source}: {where} has unknown key(s) {unknown!r}: expected only {sorted(allowed)!r}"
        )
    missing = [key for key, required in allowed.items() if required and key not in table]
    if missing:
        raise ScenarioError(f"{source}: {where} is missing required key(s) {missing!r}")


def _table(value: object, where: str, source: str) -> dict:
    if not isinstance(value, dict):
        raise ScenarioError(f"{source}: {where} must be a table, got {type(value).__name__} {value!r}")
    return value


def _number(value: object, where: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(f"{source}: {where} must be a number, got {type(value).__name__} {value!r}")
    return float(value)


def _parse_track(data: dict, source: str) -> YGraph:
    track_table = _table(data["track"], "[track]", source)
    _check_keys(track_table, _TRACK_KEYS, "[track]", source)
    legs = _table(track_table["legs"], "[track] legs", source)
    lengths = {name: _number(length, f"[track] legs.{name}", source) for name, length in legs.items()}
    angles = None
    if "angles_deg" in track_table:
        angle_table = _table(track_table["angles_deg"], "[track] angles_deg", source)
        angles = {name: _number(a, f"[track] angles_deg.{name}", source) for name, a in angle_table.items()}
    try:
        return YGraph(lengths, angles_deg=angles)
    except InputError as error:
        raise ScenarioError(f"{source}: [track]: {error}") from None


def _parse_vehicle(vehicle: object, k: int, track: YGraph, taken: list[str], source: str):
    """Name, limits, start and goal of ``[[vehicle]]`` number ``k``."""
    where = f"[[vehicle]] {k}"
    vehicle = _table(vehicle, where, source)
    _check_keys(vehicle, _VEHICLE_KEYS, where, source)
    name = vehicle["name"]
    if not isinstance(name, str) or not _VEHICLE_NAME.match(name):
        raise ScenarioError(
            f"{source}: {where} name {name!r} is not usable as a file name: "
            "expected 1-64 letters, digits, '_', '.' or '-', starting with a letter or digit"
        )
    if name in taken:
        raise ScenarioError(
            f"{source}: {where} name {name!r} is used by both vehicles: expected distinct names"
        )
    numbers = {
        key: _number(vehicle[key], f"{where} {key}", source)
        for key in ("max_velocity", "max_acceleration", "max_jerk")
    }
    try:
        limits = VehicleLimits(**numbers)
    except InputError as error:
        raise ScenarioError(f"{source}: {where}: {error}") from None
    ends = []
    for key in ("start", "goal"):
        text = vehicle[key]
        if not isinstance(text, str):
            raise ScenarioError(
                f"{source}: {where} {key} must be a string like 'A:10.0' or 'O', "
                f"got {type(text).__name__} {text!r}"
            )
        try:
            ends.append(track.check(Position.parse(text)))
        except InputError as error:
            raise ScenarioError(f"{source}: {where} {key}: {error}") from None
    return name, limits, ends[0], ends[1]


def parse_scenario(data: dict, *, source: str = "<scenario>") -> Scenario:
    """Build a Scenario from parsed TOML data, naming ``source`` and the key in every error.

    Raises
    ------
    ScenarioError
        Unknown, missing or mistyped keys, malformed positions, invalid
        track, limits or separation, or vehicles closer than the separation.
    """
    _check_keys(_table(data, "the scenario", source), _TOP_KEYS, "the scenario", source)
    track = _parse_track(data, source)
    safety = _table(data["safety"], "[safety]", source)
    _check_keys(safety, _SAFETY_KEYS, "[safety]", source)
    separation = _number(safety["min_separation"], "[safety] min_separation", source)
    vehicles = data["vehicle"]
    if not isinstance(vehicles, list) or len(vehicles) != 2:
        count = len(vehicles) if isinstance(vehicles, list) else type(vehicles).__name__
        raise ScenarioError(f"{source}: expected exactly two [[vehicle]] tables, got {count}")
    names: list[str] = []
    parsed = []
    for k, vehicle in enumerate(vehicles, start=1):
        parsed.append(_parse_vehicle(vehicle, k, track, names, source))
        names.append(parsed[-1][0])
    try:
        limits = Limits(vehicles=(parsed[0][1], parsed[1][1]), min_separation=separation)
    except InputError as error:
        raise ScenarioError(f"{source}: [safety]: {error}") from None
    start = Configuration(parsed[0][2], parsed[1][2])
    goal = Configuration(parsed[0][3], parsed[1][3])
    shortest = track.shortest_leg
    if separation > shortest:
        raise ScenarioError(
            f"{source}: [safety] min_separation {separation!r} m exceeds the shortest leg {shortest!r} m: "
            "some swaps would be impossible"
        )
    for label, configuration in (("start", start), ("goal", goal)):
        distance = track.separation(configuration)
        if distance < separation or distance == 0.0:
            raise ScenarioError(
                f"{source}: the vehicles' {label} positions {configuration} are {distance!r} m apart: "
                f"expected at least [safety] min_separation {separation!r} m"
            )
    return Scenario(track, limits, (names[0], names[1]), start, goal, source)


def load_scenario(path: str | Path) -> Scenario:
    """Read a scenario TOML file.

    Raises
    ------
    ScenarioError
        The file cannot be read, is not TOML, or is not a valid scenario.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ScenarioError(f"{path}: cannot read the scenario file: {error.strerror or error}") from None
    return _parse_text(text, str(path))


def _parse_text(text: str, source: str) -> Scenario:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{source}: not valid TOML: {error}") from None
    return parse_scenario(data, source=source)


def default_scenario() -> Scenario:
    """The built-in default scenario: the swap of ``examples/swap.toml``."""
    text = resources.files("trajgen").joinpath("data", DEFAULT_SCENARIO_NAME).read_text(encoding="utf-8")
    return _parse_text(text, f"<built-in {DEFAULT_SCENARIO_NAME}>")
