"""Seeded random scenarios, for property tests and benchmarks."""

from __future__ import annotations

import random

from limits import Limits
from topology import Configuration, Position, YGraph
from trajgen.scenario import Scenario

__all__ = ["random_configuration", "random_position", "random_scenarios"]


def random_position(rng: random.Random, track: YGraph) -> Position:
    """A position on ``track``; the junction and the leg ends are drawn often on purpose."""
    roll = rng.random()
    if roll < 0.08:
        return track.junction
    leg = rng.choice(track.names)
    if roll < 0.3:
        return track.endpoint(leg)
    return Position(leg, rng.uniform(0.0, track.length(leg)))


def random_configuration(rng: random.Random, track: YGraph, min_separation: float) -> Configuration:
    """A configuration whose vehicles are at least ``min_separation`` apart (and not at one point)."""
    while True:
        configuration = Configuration(random_position(rng, track), random_position(rng, track))
        distance = track.separation(configuration)
        if distance >= min_separation and distance > 0.0:
            return configuration


def random_scenarios(count: int, *, seed: int, track: YGraph, limits: Limits) -> list[Scenario]:
    """``count`` seeded random start/goal pairs on one track with the given limits.

    Parameters
    ----------
    count : int
    seed : int
        Same seed, same scenarios.
    track : YGraph
    limits : Limits
    """
    rng = random.Random(seed)
    scenarios = []
    for k in range(count):
        start = random_configuration(rng, track, limits.min_separation)
        goal = random_configuration(rng, track, limits.min_separation)
        scenarios.append(Scenario(track, limits, ("agv1", "agv2"), start, goal, f"<random {seed}:{k}>"))
    return scenarios
