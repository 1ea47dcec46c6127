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

The track has 3 to 8 legs (a Y, a 4-way crossing as in
``examples/crossing.toml``, ...); without ``angles_deg`` they are spread
evenly, ``90 + 360 j / k`` degrees. A minimum separation longer than a leg is
refused, naming the legs that could not serve as sidings.

A vehicle may take ``max_velocity`` and ``max_acceleration`` from a VDA 5050
factsheet instead (``factsheet = "agv.json"``, relative to the scenario file's
folder; see :mod:`trajgen.scenario.factsheet`); it still gives ``max_jerk``.
"""

from __future__ import annotations

import itertools
import tomllib
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from limits import Limits, VehicleLimits
from topology import Configuration, Option, Position, Route, StarGraph, TrackGraph, YGraph, plan
from topology.validation import check_vehicle_count, short_repr
from trajgen.errors import InputError, OptionError, ScenarioError
from trajgen.scenario.factsheet import read_factsheet
from trajgen.scenario.graph import GraphScenario
from trajgen.scenario.naming import check_vehicle_name, check_vehicle_names
from trajgen.scenario.reading import FileKind, file_label, read_bounded

__all__ = [
    "DEFAULT_SCENARIO_NAME",
    "MAX_SCENARIO_BYTES",
    "PLAUSIBLE",
    "BuiltinScenario",
    "Scenario",
    "builtin_scenario",
    "default_scenario",
    "load_scenario",
    "parse_scenario",
]

DEFAULT_SCENARIO_NAME = "swap.toml"


class BuiltinScenario(Option):
    """The scenarios shipped with trajgen (``trajgen/data/<name>.toml``; ``trajgen demo --scenario``)."""

    #: two AGVs at the far ends of legs A and B of a Y swap places (``examples/swap.toml``); the default
    SWAP = "swap"
    #: a 4-way crossing N/W/S/E of 10 m legs: two AGVs at the ends of N and S cross straight over,
    #: so one waits in a side leg while the other passes (``examples/crossing.toml``)
    CROSSING = "crossing"
    #: an H of two Y junctions joined by an 8 m middle edge, a track graph: two AGVs swap the ends
    #: A and D, one waits in a side edge while the other passes (``examples/graphs/h.toml``)
    H = "h"

    @classmethod
    def lookup(cls, name: object) -> BuiltinScenario:
        """The scenario named ``name`` (case-insensitive).

        Raises
        ------
        OptionError
            Naming the value and the known scenarios.
        """
        try:
            return super().lookup(name)
        except OptionError:
            raise OptionError(
                f"built-in scenario {name!r} is unknown: expected one of {[m.value for m in cls]!r}"
            ) from None

    @property
    def file_name(self) -> str:
        """The packaged file, e.g. ``swap.toml``."""
        return f"{self.value}.toml"

    @property
    def description(self) -> str:
        """What happens in it, for people."""
        if self is BuiltinScenario.SWAP:
            return "two AGVs swap ends of legs A and B"
        if self is BuiltinScenario.H:
            return "a track graph, an H of two junctions: two AGVs swap its ends A and D"
        return "a 4-way crossing: two AGVs cross from N to S and S to N, one waits in a side leg"


#: Largest scenario file read, bytes; a larger one is refused unread.
MAX_SCENARIO_BYTES = 1 << 20
#: How scenario files are read (:func:`~trajgen.scenario.reading.read_bounded`).
SCENARIO_FILE = FileKind("a scenario file", "a scenario TOML file", MAX_SCENARIO_BYTES, ScenarioError)
#: Plausible range of each quantity of a scenario (SI units): outside it a scenario is refused.
PLAUSIBLE = {
    "leg length": (1e-3, 1e5),
    "max_velocity": (1e-4, 100.0),
    "max_acceleration": (1e-4, 1000.0),
    "max_jerk": (1e-4, 1e6),
    "emergency_deceleration": (1e-4, 1000.0),
}
_TOP_KEYS = {"track": True, "safety": True, "vehicle": True}
_TRACK_KEYS = {"legs": True, "angles_deg": False}
_GRAPH_TRACK_KEYS = {"edges": True, "nodes": False}
_EDGE_KEYS = {"from": True, "to": True, "length": False}
_SAFETY_KEYS = {"min_separation": True}
_VEHICLE_KEYS = {
    "name": True,
    "max_velocity": False,  # required unless a factsheet gives it
    "max_acceleration": False,  # required unless a factsheet gives it
    "max_jerk": True,
    "emergency_deceleration": False,
    "factsheet": False,
    "start": True,
    "goal": True,
}


@dataclass(frozen=True, slots=True)
class Scenario:
    """A complete planning problem.

    Attributes
    ----------
    track : StarGraph
        The track: a :class:`~topology.YGraph` for three legs, a
        :class:`~topology.StarGraph` for four to eight.
    limits : Limits
        Both vehicles' limits and the minimum separation.
    names : tuple of 2 str
        Vehicle names (file names of their CSV profiles).
    start, goal : Configuration
    source : str, optional
        Where it came from (file path, ``<built-in swap.toml>``; default ``<python>``).

    Examples
    --------
    >>> from limits import Limits, VehicleLimits
    >>> from topology import Configuration, Position, YGraph
    >>> agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    >>> start = Configuration(Position("A", 10.0), Position("B", 10.0))
    >>> scenario = Scenario(
    ...     track=YGraph({"A": 10.0, "B": 10.0, "C": 10.0}),
    ...     limits=Limits(vehicles=(agv, agv), min_separation=1.5),
    ...     names=("agv1", "agv2"),
    ...     start=start,
    ...     goal=start.swapped(),
    ... )
    >>> scenario.names, scenario.source, len(scenario.route().waypoints)
    (('agv1', 'agv2'), '<python>', 7)
    """

    track: StarGraph
    limits: Limits
    names: tuple[str, str]
    start: Configuration
    goal: Configuration
    source: str = "<python>"

    def __post_init__(self) -> None:
        if not isinstance(self.track, StarGraph):
            raise InputError(f"scenario track must be a StarGraph or YGraph, got {type(self.track).__name__}")
        if not isinstance(self.limits, Limits):
            raise InputError(f"scenario limits must be Limits, got {type(self.limits).__name__}")
        object.__setattr__(self, "names", check_vehicle_names(self.names, count=self.limits.count))
        self.check_planned()
        _check_plausible_track(self.track)
        for k, vehicle in enumerate(self.limits.vehicles, start=1):
            _check_plausible_vehicle(vehicle, f"vehicle {k}")

    def check_planned(self) -> None:
        """Refuse, naming :attr:`source`, a number of vehicles the junction planner does not plan (two).

        Raises
        ------
        VehicleCountError
        """
        check_vehicle_count(self.limits.count, "the junction planner (the paper's)", source=self.source)

    def route(self) -> Route:
        """The planner's route from start to goal, keeping the scenario's minimum separation."""
        return plan(self.track, self.start, self.goal, min_separation=self.limits.min_separation)

    def plan(self) -> Route:
        """Deprecated name of :meth:`route` (trajgen 0.6), kept for one release."""
        warnings.warn("Scenario.plan() is deprecated: use Scenario.route()", DeprecationWarning, stacklevel=2)
        return self.route()


def _check_plausible_track(track: StarGraph) -> None:
    low, high = PLAUSIBLE["leg length"]
    for name, length in zip(track.names, track.lengths, strict=True):
        if not low <= length <= high:
            raise InputError(f"leg {short_repr(name)} is {length!r} m long: expected {low:g} to {high:g} m")


def _check_plausible_vehicle(vehicle: VehicleLimits, where: str) -> None:
    for key in ("max_velocity", "max_acceleration", "max_jerk", "emergency_deceleration"):
        low, high = PLAUSIBLE[key]
        value = getattr(vehicle, key)
        if value is None:
            continue
        if not low <= value <= high:
            raise InputError(f"{where} {key} is {value!r}: expected {low:g} to {high:g} (SI units)")


def _check_keys(table: dict, allowed: dict[str, bool], where: str, source: str) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ScenarioError(
            f"{source}: {where} has unknown key(s) {short_repr(unknown)}: expected only {sorted(allowed)!r}"
        )
    missing = [key for key, required in allowed.items() if required and key not in table]
    if missing:
        raise ScenarioError(f"{source}: {where} is missing required key(s) {short_repr(missing)}")


def _table(value: object, where: str, source: str) -> dict:
    if not isinstance(value, dict):
        raise ScenarioError(
            f"{source}: {where} must be a table, got {type(value).__name__} {short_repr(value)}"
        )
    return value


def _number(value: object, where: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(
            f"{source}: {where} must be a number, got {type(value).__name__} {short_repr(value)}"
        )
    return float(value)


def _parse_track(data: dict, source: str) -> StarGraph:
    track_table = _table(data["track"], "[track]", source)
    _check_keys(track_table, _TRACK_KEYS, "[track]", source)
    legs = _table(track_table["legs"], "[track] legs", source)
    lengths = {
        name: _number(length, f"[track] legs.{short_repr(name)}", source) for name, length in legs.items()
    }
    angles = None
    if "angles_deg" in track_table:
        angle_table = _table(track_table["angles_deg"], "[track] angles_deg", source)
        angles = {
            name: _number(a, f"[track] angles_deg.{short_repr(name)}", source)
            for name, a in angle_table.items()
        }
    try:
        kind = YGraph if len(lengths) == 3 else StarGraph
        track = kind(lengths, angles_deg=angles)
        _check_plausible_track(track)
        return track
    except InputError as error:
        raise ScenarioError(f"{source}: [track]: {error}") from None


def _factsheet_limits(vehicle: dict, where: str, source: str, folder: Path | None) -> dict[str, float]:
    """``max_velocity`` and ``max_acceleration`` of a vehicle from its factsheet, or ``{}`` without one."""
    if "factsheet" not in vehicle:
        missing = [key for key in ("max_velocity", "max_acceleration") if key not in vehicle]
        if missing:
            raise ScenarioError(
                f"{source}: {where} is missing required key(s) {short_repr(missing)} "
                "(or a VDA 5050 'factsheet' that gives them)"
            )
        return {}
    given = [key for key in ("max_velocity", "max_acceleration") if key in vehicle]
    if given:
        raise ScenarioError(
            f"{source}: {where} gives both 'factsheet' and {short_repr(given)}: "
            "expected the limits from one of them (remove one)"
        )
    name = vehicle["factsheet"]
    if not isinstance(name, str) or not name:
        raise ScenarioError(
            f"{source}: {where} factsheet must be a file path string, "
            f"got {type(name).__name__} {short_repr(name)}"
        )
    path = Path(name) if folder is None else folder / name
    try:
        sheet = read_factsheet(
            path, velocity_range=PLAUSIBLE["max_velocity"], acceleration_range=PLAUSIBLE["max_acceleration"]
        )
    except InputError as error:
        raise ScenarioError(f"{source}: {where}: {error}") from None
    return {"max_velocity": sheet.speed_max, "max_acceleration": sheet.max_acceleration}


def _parse_vehicle(
    vehicle: object,
    k: int,
    position: Callable[[str], object],
    taken: list[str],
    source: str,
    folder: Path | None = None,
):
    """Name, limits, start and goal of ``[[vehicle]]`` number ``k`` (``position`` reads a position)."""
    where = f"[[vehicle]] {k}"
    vehicle = _table(vehicle, where, source)
    _check_keys(vehicle, _VEHICLE_KEYS, where, source)
    from_factsheet = _factsheet_limits(vehicle, where, source, folder)
    name = vehicle["name"]
    try:
        check_vehicle_name(name)
    except InputError as error:
        raise ScenarioError(f"{source}: {where} name: {error}") from None
    if any(name.casefold() == other.casefold() for other in taken):
        raise ScenarioError(
            f"{source}: {where} name {name!r} is used by two vehicles (case ignored): expected distinct names"
        )
    numbers = {
        key: _number(vehicle[key], f"{where} {key}", source)
        for key in ("max_velocity", "max_acceleration", "max_jerk", "emergency_deceleration")
        if key in vehicle
    }
    numbers.update(from_factsheet)
    try:
        limits = VehicleLimits(**numbers)
        _check_plausible_vehicle(limits, "vehicle")
    except InputError as error:
        raise ScenarioError(f"{source}: {where}: {error}") from None
    ends = []
    for key in ("start", "goal"):
        text = vehicle[key]
        if not isinstance(text, str):
            raise ScenarioError(
                f"{source}: {where} {key} must be a string like 'A:10.0' or 'O', "
                f"got {type(text).__name__} {short_repr(text)}"
            )
        try:
            ends.append(position(text))
        except InputError as error:
            raise ScenarioError(f"{source}: {where} {key}: {error}") from None
    return name, limits, ends[0], ends[1]


def _parse_vehicles(data: dict, position: Callable[[str], object], source: str, folder: Path | None):
    """``[safety]`` and the two ``[[vehicle]]`` tables: separation, limits, names, (starts, goals).

    ``position`` reads a position of the track (``"A:10.0"`` on a junction, ``"EDGE:s"`` on a graph).
    """
    safety = _table(data["safety"], "[safety]", source)
    _check_keys(safety, _SAFETY_KEYS, "[safety]", source)
    separation = _number(safety["min_separation"], "[safety] min_separation", source)
    vehicles = data["vehicle"]
    if not isinstance(vehicles, list) or not vehicles:
        count = len(vehicles) if isinstance(vehicles, list) else type(vehicles).__name__
        raise ScenarioError(f"{source}: expected one or more [[vehicle]] tables, got {count}")
    names: list[str] = []
    parsed = []
    for k, vehicle in enumerate(vehicles, start=1):
        parsed.append(_parse_vehicle(vehicle, k, position, names, source, folder))
        names.append(parsed[-1][0])
    try:
        limits = Limits(vehicles=tuple(p[1] for p in parsed), min_separation=separation)
    except InputError as error:
        raise ScenarioError(f"{source}: [safety]: {error}") from None
    ends = (tuple(p[2] for p in parsed), tuple(p[3] for p in parsed))
    return separation, limits, tuple(names), ends


def parse_scenario(
    data: dict, *, source: str = "<scenario>", folder: str | Path | None = None
) -> Scenario | GraphScenario:
    """Build a Scenario from parsed TOML data, naming ``source`` and the key in every error.

    A ``[track]`` with ``legs`` is a junction (:class:`Scenario`); with ``edges``, a track graph
    (:class:`~trajgen.scenario.graph.GraphScenario`, docs/graphs.md).

    ``folder`` is where relative ``factsheet`` paths are found (``None``: the
    current working directory).

    Raises
    ------
    ScenarioError
        Unknown, missing or mistyped keys, malformed positions, invalid
        track, limits or separation, or vehicles closer than the separation.
    """
    _check_keys(_table(data, "the scenario", source), _TOP_KEYS, "the scenario", source)
    if isinstance(data["track"], dict) and "edges" in data["track"]:
        return _parse_graph_scenario(data, source, None if folder is None else Path(folder))
    track = _parse_track(data, source)
    separation, limits, names, ends = _parse_vehicles(
        data, _star_position(track), source, None if folder is None else Path(folder)
    )
    try:  # a junction's start and goal are configurations of the paper's planner: two vehicles
        check_vehicle_count(len(names), "the junction planner (the paper's)")
    except InputError as error:
        raise ScenarioError(f"{source}: {error}") from None
    start, goal = Configuration(*ends[0]), Configuration(*ends[1])
    shortest = track.shortest_leg
    if separation > shortest:
        too_short = [
            name for name, length in zip(track.names, track.lengths, strict=True) if length < separation
        ]
        raise ScenarioError(
            f"{source}: [safety] min_separation {separation!r} m exceeds the shortest leg {shortest!r} m: "
            f"legs {short_repr(too_short, 200)} could not serve as sidings, so some swaps would be impossible"
        )
    for label, configuration in (("start", start), ("goal", goal)):
        distance = track.separation(configuration)
        if distance < separation or distance == 0.0:
            raise ScenarioError(
                f"{source}: the vehicles' {label} positions {configuration} are {distance!r} m apart: "
                f"expected at least [safety] min_separation {separation!r} m"
            )
    try:
        return Scenario(track, limits, names, start, goal, source)
    except InputError as error:
        raise ScenarioError(f"{source}: {error}") from None


def _star_position(track: StarGraph) -> Callable[[str], Position]:
    return lambda text: track.check(Position.parse(text))


def _parse_graph_track(table: dict, source: str) -> TrackGraph:
    """``[track]`` with ``edges`` (and optional ``nodes`` x/y) as a :class:`~topology.TrackGraph`."""
    _check_keys(table, _GRAPH_TRACK_KEYS, "[track]", source)
    coordinates = None
    if "nodes" in table:
        coordinates = {}
        for name, xy in _table(table["nodes"], "[track] nodes", source).items():
            where = f"[track] nodes.{short_repr(name)}"
            if not isinstance(xy, list) or len(xy) != 2:
                raise ScenarioError(f"{source}: {where} must be [x, y] in metres, got {short_repr(xy)}")
            coordinates[name] = (_number(xy[0], where, source), _number(xy[1], where, source))
    edges = {}
    for name, edge in _table(table["edges"], "[track] edges", source).items():
        where = f"[track] edges.{short_repr(name)}"
        edge = _table(edge, where, source)
        _check_keys(edge, _EDGE_KEYS, where, source)
        ends = [edge[key] for key in ("from", "to")]
        if not all(isinstance(end, str) for end in ends):
            raise ScenarioError(f"{source}: {where} from and to must be node names, got {short_repr(ends)}")
        length = _number(edge["length"], f"{where} length", source) if "length" in edge else None
        edges[name] = (ends[0], ends[1], length)
    try:
        track = TrackGraph.from_edges(edges, coordinates=coordinates)
    except InputError as error:
        raise ScenarioError(f"{source}: [track]: {error}") from None
    low, high = PLAUSIBLE["leg length"]
    for edge in track.edges:
        if not low <= edge.length <= high:
            raise ScenarioError(
                f"{source}: [track]: edge {edge.name!r} is {edge.length!r} m long: "
                f"expected {low:g} to {high:g} m"
            )
    return track


def _parse_graph_scenario(data: dict, source: str, folder: Path | None) -> GraphScenario:
    track = _parse_graph_track(_table(data["track"], "[track]", source), source)
    separation, limits, names, (start, goal) = _parse_vehicles(data, track.point, source, folder)
    for label, points in (("start", start), ("goal", goal)):
        for first, second in itertools.combinations(range(len(points)), 2):
            pair = (points[first], points[second])
            gap = track.distance(*pair)
            if gap < separation or gap == 0.0:
                between = "the vehicles'" if len(points) == 2 else f"{names[first]}'s and {names[second]}'s"
                raise ScenarioError(
                    f"{source}: {between} {label} positions ({track.name(pair[0])}, "
                    f"{track.name(pair[1])}) are {gap!r} m apart along the track: expected at least "
                    f"[safety] min_separation {separation!r} m"
                )
    try:
        return GraphScenario(track, limits, names, start, goal, source)
    except InputError as error:
        raise ScenarioError(f"{source}: {error}") from None


def _read_scenario_file(path: Path, label: str) -> str:
    """The text of a scenario file: a regular file of at most :data:`MAX_SCENARIO_BYTES`, UTF-8."""
    data = read_bounded(path, label, SCENARIO_FILE)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        hint = " (it looks like UTF-16: save it as UTF-8)" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else ""
        raise ScenarioError(
            f"{label}: is not UTF-8 text: byte {data[error.start]:#04x} at offset {error.start}{hint}"
        ) from None


def load_scenario(path: str | Path) -> Scenario | GraphScenario:
    """Read a scenario TOML file (UTF-8, at most :data:`MAX_SCENARIO_BYTES`).

    Raises
    ------
    ScenarioError
        The file cannot be read, is too large, not UTF-8, not TOML, or not a valid scenario.
    """
    if not isinstance(path, (str, Path)) or str(path) == "":
        raise ScenarioError(f"scenario path must name a file, got {short_repr(path)}")
    path = Path(path)
    label = file_label(path)
    return _parse_text(_read_scenario_file(path, label), label, path.parent)


def _parse_text(text: str, source: str, folder: Path | None = None) -> Scenario | GraphScenario:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{source}: not valid TOML: {error}") from None
    except RecursionError:
        raise ScenarioError(f"{source}: not a scenario: arrays or tables nested too deeply") from None
    return parse_scenario(data, source=source, folder=folder)


def builtin_scenario(name: BuiltinScenario | str = BuiltinScenario.SWAP) -> Scenario | GraphScenario:
    """A scenario shipped with trajgen, by name (:class:`BuiltinScenario`).

    Parameters
    ----------
    name : BuiltinScenario or str, optional
        ``"swap"`` (default, :func:`default_scenario`), ``"crossing"``, or ``"h"`` (a track graph).

    Raises
    ------
    OptionError
        An unknown name, naming the known ones.

    Examples
    --------
    >>> crossing = builtin_scenario("crossing")
    >>> crossing.track.names, crossing.source
    (('N', 'W', 'S', 'E'), '<built-in crossing.toml>')
    """
    file_name = BuiltinScenario.lookup(name).file_name
    text = resources.files("trajgen").joinpath("data", file_name).read_text(encoding="utf-8")
    return _parse_text(text, f"<built-in {file_name}>")


def default_scenario() -> Scenario:
    """The built-in default scenario: the swap of ``examples/swap.toml``."""
    return builtin_scenario(BuiltinScenario.SWAP)
