"""Shared builders for schedule tests."""

from __future__ import annotations

import functools

import pytest

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from topology import Configuration, Position, YGraph, plan
from trajgen import Optimal, Schedule, load_scenario
from trajgen.execution.goals import schedule_for_execution

#: The files a run with CSV and plots into one folder writes (sorted): the demo's, the README's.
#: The files of a run with CSV profiles and plots on a track graph; a junction's adds ``configuration.png``.
GRAPH_RUN_FILES = ["agv1.csv", "agv2.csv", "coordination.png", "layout.png", "separation.png", "speed.png"]
RUN_FILES = sorted([*GRAPH_RUN_FILES, "configuration.png"])

SLOW = VehicleLimits(max_velocity=0.7, max_acceleration=0.35, max_jerk=0.6)
AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
LIMITS = Limits(vehicles=(AGV, AGV), min_separation=1.5)
MIXED = Limits(vehicles=(AGV, SLOW), min_separation=1.5)


def legs_id(legs: int) -> str:
    """The id of a test case on a junction of ``legs`` legs: ``legs3`` (a Y), ``legs4`` ... ``legs8``."""
    return f"legs{legs}"


def legs_cases(counts, slow=()) -> list:
    """Cases of a test over junctions of ``counts`` legs; those in ``slow`` marked slow.

    A property every junction has runs on the Y in the fast set, and on the stars end to end.
    """
    return [
        pytest.param(legs, id=legs_id(legs), marks=pytest.mark.slow if legs in slow else ())
        for legs in sorted(counts)
    ]


def conf(first: str, second: str) -> Configuration:
    return Configuration(Position.parse(first), Position.parse(second))


def route_of(legs, start, goal, separation=1.5):
    track = YGraph(dict(zip("ABC", legs, strict=True)))
    return plan(track, conf(*start), conf(*goal), min_separation=separation)


def too_close(schedule: Schedule, separation: float = 10.5) -> Schedule:
    """The same motion relabelled with a minimum separation it does not keep (a broken schedule)."""
    limits = Limits(schedule.limits.vehicles, min_separation=separation)
    return Schedule(schedule.route, limits, schedule.method, schedule.sections, schedule.jerk_limited)


@functools.cache
def execution_plan(name: str, method: str):
    """``(scenario, schedule_for_execution(scenario))`` of ``examples/NAME.toml``, once per test process.

    Several modules test the same plans; solved once, each worker shares them.
    """
    scenario = load_scenario(REPO / "examples" / f"{name}.toml")
    chosen = Optimal() if method == "optimal" else method
    return scenario, schedule_for_execution(scenario, method=chosen)


def animation_gif(verified, **options) -> bytes:
    """The GIF the command line writes of ``animate(verified, **options)``."""
    from trajgen.plots import animate, encode_gif

    return encode_gif(animate(verified, **options))


def scenario_vehicle(scenario, v: int, identity, *, broker, clock, **options):
    """Vehicle ``v`` of ``scenario`` simulated at its start, not started (``options``: SimulatedVehicle's)."""
    from trajgen.live.places import scenario_starts, start_place
    from trajgen.live.vehicle import SimulatedVehicle

    xy, node = start_place(scenario.track, scenario_starts(scenario)[v])
    return SimulatedVehicle(
        identity,
        scenario.limits.vehicles[v],
        xy,
        start_node=node,
        broker=broker,
        clock=clock,
        **options,
    )


#: The "+ 1 s" of the online stop bound D + 3 max_i(v_i/a_i + a_i/j_i) + 1 s, seconds.
STOP_BOUND_SLACK = 1.0


def stop_bound(scenario, duration: float) -> float:
    """What a stop of ``duration`` seconds may cost at most: D + 3 max_i(v_i/a_i + a_i/j_i) + 1 s."""
    slack = max(
        v.max_velocity / v.max_acceleration + v.max_acceleration / v.max_jerk
        for v in scenario.limits.vehicles
    )
    return duration + 3.0 * slack + STOP_BOUND_SLACK
