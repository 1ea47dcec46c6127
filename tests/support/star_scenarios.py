"""Scenarios of junctions of 4 to 8 legs (STAR-JUNCTIONS.md), as parsed TOML and as files, scheduled once.

Shared by the tests of what comes after the planner on a star: schedules, the verifier, CSV and
table exports, VDA 5050 orders, the command line.
"""

from __future__ import annotations

import csv
import functools
import json

import numpy as np

from tests.conftest import REPO
from tests.support.helpers import AGV, SLOW
from topology import JUNCTION_INDEX
from trajgen import Exact, Optimal, Toppra, make_schedule, parse_scenario

#: The built-in 4-way crossing (``trajgen demo --scenario crossing``), as packaged.
CROSSING = REPO / "trajgen" / "data" / "crossing.toml"


def star_data(legs: dict, angles: dict | None, first, second, *, separation: float = 1.5) -> dict:
    """A scenario as parsed TOML: ``first``/``second`` are (start, goal, limits)."""
    track = {"legs": dict(legs)}
    if angles is not None:
        track["angles_deg"] = dict(angles)
    vehicles = [
        {
            "name": name,
            "start": start,
            "goal": goal,
            "max_velocity": limits.max_velocity,
            "max_acceleration": limits.max_acceleration,
            "max_jerk": limits.max_jerk,
        }
        for name, (start, goal, limits) in zip(("agv1", "agv2"), (first, second), strict=True)
    ]
    return {"track": track, "safety": {"min_separation": separation}, "vehicle": vehicles}


def toml_text(data: dict) -> str:
    """The scenario file of ``star_data``'s output."""

    def table(mapping: dict) -> str:
        return "{ " + ", ".join(f"{k} = {float(v)!r}" for k, v in mapping.items()) + " }"

    lines = ["[track]", f"legs = {table(data['track']['legs'])}"]
    if "angles_deg" in data["track"]:
        lines.append(f"angles_deg = {table(data['track']['angles_deg'])}")
    lines += ["[safety]", f"min_separation = {data['safety']['min_separation']!r}"]
    for vehicle in data["vehicle"]:
        lines.append("[[vehicle]]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in vehicle.items()]
    return "\n".join(lines) + "\n"


#: k -> a scenario of k legs: the crossing's head-on swap; five unequal legs, odd angles, mixed
#: vehicles; eight legs, the first vehicle on the 8th leg (H), odd angles.
STAR_SCENARIOS = {
    4: star_data(
        {"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0},
        {"N": 90.0, "W": 180.0, "S": 270.0, "E": 0.0},
        ("N:10", "S:10", AGV),
        ("S:10", "N:10", AGV),
    ),
    5: star_data(
        {"A": 12.0, "B": 7.0, "C": 9.0, "D": 15.0, "E": 6.0},
        {"A": 10.0, "B": 80.0, "C": 170.0, "D": 220.0, "E": 300.0},
        ("A:12", "D:15", AGV),
        ("D:14", "A:11", SLOW),
    ),
    8: star_data(
        dict(zip("ABCDEFGH", (10.0, 6.0, 8.0, 12.0, 5.0, 9.0, 7.0, 11.0), strict=True)),
        dict(zip("ABCDEFGH", (0.0, 40.0, 95.0, 140.0, 185.0, 230.0, 275.0, 320.0), strict=True)),
        ("H:11", "B:6", AGV),
        ("B:5", "H:9", AGV),
        separation=2.0,
    ),
}
#: The methods every star scenario is scheduled by, by name.
STAR_METHODS = {"exact": Exact, "toppra": Toppra, "optimal": Optimal}


@functools.cache
def star_scenario(k: int):
    return parse_scenario(STAR_SCENARIOS[k], source=f"<{k} legs>")


@functools.cache
def star_schedule(k: int, method: str):
    scenario = star_scenario(k)
    return make_schedule(scenario.route(), scenario.limits, method=STAR_METHODS[method]())


def leg_index(scenario, position) -> int:
    return JUNCTION_INDEX if position.leg is None else scenario.track.index(position.leg)


def read_csv(path) -> dict[str, np.ndarray]:
    """The columns of a generic CSV file (a profile or a trace), by header name."""
    with path.open(newline="", encoding="ascii") as handle:
        rows = list(csv.reader(handle, delimiter=";"))
    header, body = rows[0], np.array(rows[1:], dtype=float)
    return {name: body[:, k] for k, name in enumerate(header)}
