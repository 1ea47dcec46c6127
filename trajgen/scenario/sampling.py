"""Seeded random scenarios, for property tests and benchmarks, on junctions of 3 to 8 legs."""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass

from limits import Limits, VehicleLimits
from topology import MAX_LEGS, MIN_LEGS, Configuration, Position, StarGraph, YGraph
from trajgen.errors import InputError
from trajgen.scenario import Scenario

__all__ = [
    "ReferenceSet",
    "campaign_faults",
    "campaign_scenarios",
    "fault_specs",
    "online_campaign",
    "random_configuration",
    "random_position",
    "random_scenarios",
    "random_track",
    "reference_sets",
]

#: Leg names of random tracks, in counterclockwise order (the first ``k`` of them).
LEG_NAMES = "ABCDEFGH"


def random_position(rng: random.Random, track: StarGraph) -> Position:
    """A position on ``track``; the junction and the leg ends are drawn often on purpose."""
    roll = rng.random()
    if roll < 0.08:
        return track.junction
    leg = rng.choice(track.names)
    if roll < 0.3:
        return track.endpoint(leg)
    return Position(leg, rng.uniform(0.0, track.length(leg)))


def random_configuration(rng: random.Random, track: StarGraph, min_separation: float) -> Configuration:
    """A configuration whose vehicles are at least ``min_separation`` apart (and not at one point)."""
    while True:
        configuration = Configuration(random_position(rng, track), random_position(rng, track))
        distance = track.separation(configuration)
        if distance >= min_separation and distance > 0.0:
            return configuration


def random_track(
    rng: random.Random, *, leg_count: int = 3, lengths: tuple[float, float] = (0.5, 30.0)
) -> StarGraph:
    """A track of ``leg_count`` legs named A, B, ... with log-uniform random lengths.

    Parameters
    ----------
    rng : random.Random
    leg_count : int, optional
        Number of legs, 3 to 8 (default 3: a :class:`~topology.YGraph`).
    lengths : tuple of 2 float, optional
        Shortest and longest leg drawn, metres (default 0.5 to 30 m).

    Raises
    ------
    InputError
        ``leg_count`` not an integer from 3 to 8.

    Examples
    --------
    >>> random_track(random.Random(1), leg_count=5).names
    ('A', 'B', 'C', 'D', 'E')
    """
    if isinstance(leg_count, bool) or not isinstance(leg_count, int) or not MIN_LEGS <= leg_count <= MAX_LEGS:
        raise InputError(
            f"leg_count (number of legs) must be an integer from {MIN_LEGS} to {MAX_LEGS}, got {leg_count!r}"
        )
    low, high = (math.log(length) for length in lengths)
    legs = {name: math.exp(rng.uniform(low, high)) for name in LEG_NAMES[:leg_count]}
    return YGraph(legs) if leg_count == 3 else StarGraph(legs)


def random_scenarios(count: int, *, seed: int, track: StarGraph, limits: Limits) -> list[Scenario]:
    """``count`` seeded random start/goal pairs on one track with the given limits.

    Parameters
    ----------
    count : int
    seed : int
        Same seed, same scenarios.
    track : StarGraph
        A track of 3 to 8 legs.
    limits : Limits
    """
    rng = random.Random(seed)
    scenarios = []
    for k in range(count):
        start = random_configuration(rng, track, limits.min_separation)
        goal = random_configuration(rng, track, limits.min_separation)
        scenarios.append(Scenario(track, limits, ("agv1", "agv2"), start, goal, f"<random {seed}:{k}>"))
    return scenarios


@dataclass(frozen=True, slots=True)
class ReferenceSet:
    """A named set of scenarios on one track with one set of limits (the benchmark's sets).

    Attributes
    ----------
    label : str
    track : StarGraph
    limits : Limits
    scenarios : tuple of (str, Configuration, Configuration)
        Name, start and goal of each scenario.
    """

    label: str
    track: StarGraph
    limits: Limits
    scenarios: tuple[tuple[str, Configuration, Configuration], ...]


def _swaps(track: StarGraph) -> tuple[tuple[str, Configuration, Configuration], ...]:
    """The swaps of the ends of neighbouring legs (AB, BC, CA on a Y)."""
    out = []
    count = track.leg_count
    for i, j in ((k, (k + 1) % count) for k in range(count)):
        start = Configuration(track.endpoint(track.names[i]), track.endpoint(track.names[j]))
        out.append((f"swap {track.names[i]}{track.names[j]}", start, start.swapped()))
    return tuple(out)


def reference_sets(random_count: int = 50) -> tuple[ReferenceSet, ...]:
    """The reference scenario sets of ``benchmarks/bench_optimal.py`` (limits 1.0/0.5/1.0, separation 1.5 m).

    (a) the three swaps on legs (10, 10, 10) m; (b) the three swaps on
    (12, 8, 15) m; (c) ``random_count`` seeded random start/goal pairs on
    (12, 8, 15) m; (d) set (c) with vehicle 2 limited to 0.7 m/s, 0.35 m/s²,
    0.6 m/s³.
    """
    agv = VehicleLimits(1.0, 0.5, 1.0)
    same = Limits(vehicles=(agv, agv), min_separation=1.5)
    mixed = Limits(vehicles=(agv, VehicleLimits(0.7, 0.35, 0.6)), min_separation=1.5)
    equal = YGraph({"A": 10.0, "B": 10.0, "C": 10.0})
    unequal = YGraph({"A": 12.0, "B": 8.0, "C": 15.0})
    randoms = tuple(
        (f"random {k}", s.start, s.goal)
        for k, s in enumerate(random_scenarios(random_count, seed=2026, track=unequal, limits=same))
    )
    return (
        ReferenceSet("a", equal, same, _swaps(equal)),
        ReferenceSet("b", unequal, same, _swaps(unequal)),
        ReferenceSet("c", unequal, same, randoms),
        ReferenceSet("d", unequal, mixed, randoms),
    )


def _drawn_scenarios(
    count: int,
    seed: int,
    *,
    legs: tuple[float, float],
    velocity: tuple[float, float],
    acceleration: tuple[float, float],
    jerk: tuple[float, float],
    label: str,
    leg_count: int,
) -> list[Scenario]:
    """Seeded scenarios: ``leg_count`` log-uniform legs and per-vehicle limits in the given ranges (SI units).

    The separation is drawn from 0 up to the shortest leg (every fifth scenario exactly the shortest
    leg); every fourth scenario is a swap, the others have a random start and goal.
    """
    rng = random.Random(seed)

    def log_uniform(low: float, high: float) -> float:
        return math.exp(rng.uniform(math.log(low), math.log(high)))

    scenarios = []
    for k in range(count):
        track = random_track(rng, leg_count=leg_count, lengths=legs)
        vehicles = tuple(
            VehicleLimits(log_uniform(*velocity), log_uniform(*acceleration), log_uniform(*jerk))
            for _ in range(2)
        )
        shortest = track.shortest_leg
        separation = shortest if k % 5 == 0 else rng.uniform(0.0, shortest)
        limits = Limits(vehicles=vehicles, min_separation=separation)
        start = random_configuration(rng, track, separation)
        goal = start.swapped() if k % 4 == 0 else random_configuration(rng, track, separation)
        scenarios.append(Scenario(track, limits, ("agv1", "agv2"), start, goal, f"<{label} {seed}:{k}>"))
    return scenarios


def campaign_scenarios(count: int, *, seed: int, leg_count: int = 3) -> list[Scenario]:
    """Seeded random scenarios over a wide range of tracks and vehicles, for robustness campaigns.

    Not the whole :data:`trajgen.scenario.PLAUSIBLE` range (which allows even more
    extreme ratios); the extremes of that are tested separately.

    Legs 0.5 to 5000 m (log-uniform, so short and long are both common), each
    vehicle's limits drawn independently (0.05-5 m/s, 0.05-5 m/s², 0.05-20 m/s³,
    log-uniform), the separation from 0 up to the shortest leg (a fifth of
    the scenarios exactly the shortest leg), and a swap for every fourth
    scenario, random start and goal otherwise. Tracks of ``leg_count`` legs
    (3 to 8, default 3) named A, B, ...
    """
    return _drawn_scenarios(
        count,
        seed,
        legs=(0.5, 5000.0),
        velocity=(0.05, 5.0),
        acceleration=(0.05, 5.0),
        jerk=(0.05, 20.0),
        label="campaign" if leg_count == 3 else f"campaign k={leg_count}",
        leg_count=leg_count,
    )


def online_campaign(count: int, *, seed: int, leg_count: int = 3) -> list[Scenario]:
    """Seeded random scenarios for the closed-loop fault campaign (``trajgen simulate``).

    The range of the random planner tests (legs 0.5 to 30 m, log-uniform), each vehicle's limits
    drawn independently (0.2-3 m/s, 0.2-3 m/s², 0.5-10 m/s³, log-uniform), the separation from 0
    up to the shortest leg (a fifth of the scenarios exactly the shortest leg), a swap for every
    fourth scenario, random start and goal otherwise; tracks of ``leg_count`` legs (3 to 8, default
    3) named A, B, ... Pair with :func:`campaign_faults`.
    """
    return _drawn_scenarios(
        count,
        seed,
        legs=(0.5, 30.0),
        velocity=(0.2, 3.0),
        acceleration=(0.2, 3.0),
        jerk=(0.5, 10.0),
        label="online" if leg_count == 3 else f"online k={leg_count}",
        leg_count=leg_count,
    )


def campaign_faults(scenario: Scenario, duration: float, *, seed: int, margin: float) -> tuple[str, ...]:
    """One to three random ``--fault`` specs for ``scenario`` (their times within its planned ``duration``).

    Parameters
    ----------
    scenario : Scenario
    duration : float
        The undisturbed schedule's duration, seconds.
    seed : int
    margin : float
        The executor's position margin in this scenario, metres (jumps stay within it; none if 0).
    """

    def place(rng: random.Random) -> str:
        position = random_position(rng, scenario.track)
        return "O" if position.leg is None else f"{position.leg}:{math.floor(position.s * 1e4) / 1e4}"

    return fault_specs(scenario, duration, seed=seed, margin=margin, place=place)


def fault_specs(
    scenario, duration: float, *, seed: int, margin: float, place: Callable[[random.Random], str]
) -> tuple[str, ...]:
    """One to three random ``--fault`` specs: stops, slow drives, lags, jumps and new goals.

    Parameters
    ----------
    scenario : Scenario or GraphScenario
    duration : float
        The undisturbed schedule's duration, seconds (the faults' times lie within it).
    seed : int
    margin : float
        The executor's position margin, metres (jumps stay within it; none if 0).
    place : callable
        A random goal's text (``LEG:s`` or ``EDGE:s``) from the random generator given.
    """
    rng = random.Random(seed)
    kinds = ["stop", "slow", "lag", "goal"] + (["jump"] if margin > 0.0 else [])
    specs = []
    for _ in range(rng.randint(1, 3)):
        kind = rng.choice(kinds)
        vehicle = rng.randrange(2)
        name = scenario.names[vehicle]
        at = round(rng.uniform(0.0, 0.9) * duration, 3)
        top = scenario.limits.vehicles[vehicle].max_velocity
        if kind == "stop":
            specs.append(f"stop:{name}@{at}+{round(rng.uniform(0.2, 0.3 * duration + 0.5), 3)}")
        elif kind == "slow":
            specs.append(f"slow:{name}@{at}={round(rng.uniform(0.2, 0.9) * top, 4)}")
        elif kind == "lag":
            specs.append(f"lag:{name}@{at}={rng.randint(10, 200)}")
        elif kind == "jump":
            specs.append(f"jump:{name}@{at}={rng.choice((-1, 1)) * round(rng.uniform(0.2, 1.0) * margin, 5)}")
        else:
            specs.append(f"goal:{name}@{at}={place(rng)}")
    return tuple(specs)
