"""Seeded random scenarios on track graphs (trees and graphs with loops), for campaigns and benchmarks."""

from __future__ import annotations

import math
import random

from limits import Limits, VehicleLimits
from topology import EdgePoint, InfeasibleError, TrackGraph, plan_graph
from trajgen.scenario.graph import GraphScenario
from trajgen.scenario.sampling import fault_specs

__all__ = ["graph_campaign_faults", "graph_online_campaign", "random_graph_track"]

#: Separations of the campaign's scenarios, metres.
_SEPARATIONS = (1.0, 1.5, 2.0, 3.0)


def random_graph_track(rng: random.Random, *, junctions: int, loops: int) -> TrackGraph:
    """A random tree of ``junctions`` junctions (each of degree 3 or more), plus ``loops`` extra edges.

    Edges between junctions are 2 to 12 m, leaves 1 to 8 m; an extra edge joins two junctions (a
    parallel edge is a passing loop). Lengths are multiples of 0.5 m.
    """
    edges: dict[str, tuple[str, str, float]] = {}
    names = ["J0"]
    for j in range(1, junctions):
        edges[f"e{len(edges)}"] = (rng.choice(names), f"J{j}", rng.randint(4, 24) * 0.5)
        names.append(f"J{j}")
    degree = dict.fromkeys(names, 0)
    for start, end, _ in edges.values():
        degree[start] += 1
        degree[end] += 1
    leaves = 0
    for name in names:
        while degree[name] < 3:
            edges[f"e{len(edges)}"] = (name, f"L{leaves}", rng.randint(2, 16) * 0.5)
            leaves += 1
            degree[name] += 1
    for _ in range(loops if len(names) > 1 else 0):
        start, end = rng.sample(names, 2)
        edges[f"e{len(edges)}"] = (start, end, rng.randint(4, 24) * 0.5)
    return TrackGraph.from_edges(edges)


def _random_point(rng: random.Random, track: TrackGraph) -> EdgePoint:
    """A random place on ``track``, to 0.1 mm."""
    edge = rng.randrange(track.edge_count)
    return EdgePoint(edge, math.floor(rng.uniform(0.0, track.length(edge)) * 1e4) / 1e4)


def graph_online_campaign(count: int, *, seed: int) -> list[GraphScenario]:
    """Seeded random track-graph scenarios for the closed-loop fault campaign, each with a route.

    Half trees of 1 to 5 junctions, half graphs with loops of 2 to 4 junctions and 1 or 2 extra
    edges (:func:`random_graph_track`); each vehicle's limits drawn independently (0.2-3 m/s,
    0.2-3 m/s², 0.5-10 m/s³, log-uniform); the separation 1, 1.5, 2 or 3 m; a random start and
    goal at least the separation apart. Layouts where the planner finds no route are drawn again.
    Pair with :func:`graph_campaign_faults`.
    """
    rng = random.Random(f"graph-online-{seed}")

    def log_uniform(low: float, high: float) -> float:
        return math.exp(rng.uniform(math.log(low), math.log(high)))

    scenarios: list[GraphScenario] = []
    while len(scenarios) < count:
        loops = len(scenarios) % 2 == 1
        track = random_graph_track(
            rng, junctions=rng.randint(2, 4) if loops else rng.randint(1, 5), loops=rng.randint(1, 2) * loops
        )
        separation = rng.choice(_SEPARATIONS)
        vehicles = tuple(
            VehicleLimits(log_uniform(0.2, 3.0), log_uniform(0.2, 3.0), log_uniform(0.5, 10.0))
            for _ in range(2)
        )
        pairs = []
        for _ in range(200):
            pair = (_random_point(rng, track), _random_point(rng, track))
            if track.distance(*pair) >= separation + 0.2:
                pairs.append(pair)
                if len(pairs) == 2:
                    break
        if len(pairs) < 2:
            continue
        try:
            plan_graph(track, pairs[0], pairs[1], min_separation=separation)
        except InfeasibleError:
            continue
        label = f"<graph online {seed}:{len(scenarios)}>"
        limits = Limits(vehicles, separation)
        scenarios.append(GraphScenario(track, limits, ("agv1", "agv2"), pairs[0], pairs[1], label))
    return scenarios


def graph_campaign_faults(
    scenario: GraphScenario, duration: float, *, seed: int, margin: float
) -> tuple[str, ...]:
    """One to three random ``--fault`` specs for a track-graph scenario (times within ``duration``).

    As :func:`~trajgen.scenario.sampling.campaign_faults`: stops, slow drives, lags, jumps within
    the position ``margin`` (none if 0), and new goals ``EDGE:s`` anywhere on the track.
    """

    def place(rng: random.Random) -> str:
        point = _random_point(rng, scenario.track)
        return f"{scenario.track.edges[point.edge].name}:{point.s:g}"

    return fault_specs(scenario, duration, seed=seed, margin=margin, place=place)
