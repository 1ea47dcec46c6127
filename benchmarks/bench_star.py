"""Junctions with k legs: planner speed, instructions seen, and optimal on 4-way crossings (issue 13).

Run: ``python benchmarks/bench_star.py [--tracks N] [--queries N] [--scenarios N] [--seed S]``.

Prints, for k = 3, 4, 6 and 8 legs:

1. the time to build a track's tables (``StarGraph`` plus its retract graph
   ``G_k``: vertices, edges, perturbed lengths, all-pairs distances and
   shortest vertex paths), median and worst in milliseconds over ``--tracks``
   random tracks (a Y's planner does not need them: it goes round its circle);
2. ``plan()`` per query after the tables are built (median, mean and 99th
   percentile in microseconds, one query at a time, ``perf_counter_ns``);
3. how often each instruction was used over the random queries, and over a
   campaign of queries placed where two (or three) candidate routes are equally
   long, alternately (random queries land there with probability zero); where
   another candidate is shorter still, rule 1 applies there;
4. ``optimal`` on ``--scenarios`` random scenarios on 4-way crossings beside
   the same number on Y tracks (legs 5-15 m, limits 1.0 m/s, 0.5 m/s²,
   1.0 m/s³, separation 1.5 m): fallbacks, solve time median and worst (the
   one-time NLP builds apart), all verified.
"""

from __future__ import annotations

import argparse
import random
import statistics
import sys
import time
from collections import Counter

from tqdm import tqdm

from limits import Limits, VehicleLimits
from topology import Configuration, GraphPoint, Instruction, StarGraph, plan
from trajgen import Optimal, SolverCache, verify
from trajgen.progress import progress
from trajgen.scenario.sampling import random_configuration, random_position

LEG_NAMES = "ABCDEFGH"


def emit(line: str) -> None:
    """Print a line above the progress bars, at once (also into a pipe)."""
    tqdm.write(line)
    sys.stdout.flush()


def random_track(rng: random.Random, legs: int, low: float = 0.5, high: float = 50.0) -> StarGraph:
    """A track of ``legs`` legs of random lengths in [low, high] metres (default angles)."""
    return StarGraph({name: rng.uniform(low, high) for name in LEG_NAMES[:legs]})


def random_query(rng: random.Random, track: StarGraph) -> tuple[Configuration, Configuration, float]:
    """A start, a goal (a swap one time in five) and a separation that both keep."""
    while True:
        start = Configuration(random_position(rng, track), random_position(rng, track))
        goal = (
            start.swapped()
            if rng.random() < 0.2
            else Configuration(random_position(rng, track), random_position(rng, track))
        )
        ceiling = min(track.shortest_leg, track.separation(start), track.separation(goal))
        if ceiling > 1e-9:
            return start, goal, rng.uniform(0.0, ceiling)


def tie_query(
    rng: random.Random, track: StarGraph, three: bool
) -> tuple[Configuration, Configuration] | None:
    """A start and a goal on ``G_k`` where two (or three) candidate routes are equally short, or None."""
    graph = track.retract_graph
    distances = graph.distances
    e1, e2 = rng.randrange(len(graph.edges)), rng.randrange(len(graph.edges))
    (p1, v1), (p2, v2) = graph.edges[e1], graph.edges[e2]
    length1, length2 = graph.perturbed_lengths[e1], graph.perturbed_lengths[e2]
    # offsets (perturbed) from the peaks: via (p1, p2) == via (p1, v2) fixes t; == via (v1, p2) fixes s
    t = 0.5 * (distances[p1, v2] + length2 - distances[p1, p2])
    s = 0.5 * (length1 + distances[v1, p2] - distances[p1, p2]) if three else rng.uniform(0.0, length1)
    if not (0.0 < s < length1 and 0.0 < t < length2) or e1 == e2:
        return None
    x = GraphPoint(-1, e1, s * graph.edge_lengths[e1] / length1)
    y = GraphPoint(-1, e2, t * graph.edge_lengths[e2] / length2)
    return graph.configuration(x), graph.configuration(y)


def bench_planner(legs: int, tracks: int, queries: int, rng: random.Random) -> None:
    build_ms, plan_us = [], []
    used: Counter[Instruction] = Counter()
    clock = time.perf_counter_ns
    for _ in progress(range(tracks), description=f"k={legs} tracks"):
        lengths = {name: rng.uniform(0.5, 50.0) for name in LEG_NAMES[:legs]}
        begin = clock()
        track = StarGraph(lengths)
        track.retract_graph  # noqa: B018 - build the tables now
        build_ms.append((clock() - begin) / 1e6)
        for _ in range(queries):
            start, goal, separation = random_query(rng, track)
            begin = clock()
            route = plan(track, start, goal, min_separation=separation)
            plan_us.append((clock() - begin) / 1000.0)
            used[route.instruction] += 1
        # free the track's tables here, not inside the next track's first timed plan() (the last
        # route holds the track)
        del route, track
    plan_us.sort()
    emit(
        f"k={legs}: tables {statistics.median(build_ms):6.2f} ms median, {max(build_ms):6.2f} ms worst; "
        f"plan {statistics.median(plan_us):6.1f} us median, {statistics.fmean(plan_us):6.1f} us mean, "
        f"{plan_us[int(0.99 * len(plan_us))]:6.1f} us p99 over {len(plan_us)} queries"
    )
    emit(f"      random queries: {format_counts(legs, used)}")
    if legs == 3:
        return
    tied: Counter[Instruction] = Counter()
    track = random_track(rng, legs)
    while sum(tied.values()) < 2 * queries:
        three = sum(tied.values()) % 2 == 1
        query = tie_query(rng, track, three)
        if query is None:
            continue
        try:
            route = plan(track, *query)
        except ValueError:  # the vehicles at one point: not a query
            continue
        tied[route.instruction] += 1
    emit(f"      tie-set queries: {format_counts(legs, tied)}")


def format_counts(legs: int, counts: Counter[Instruction]) -> str:
    track = random_track(random.Random(0), legs)
    return ", ".join(f"{i.value} {counts[i]}" for i in Instruction.of_track(track))


def bench_optimal(count: int, seed: int) -> None:
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits(vehicles=(agv, agv), min_separation=1.5)
    optimal = Optimal(cache=SolverCache(maxsize=256))
    for legs in (3, 4):
        rng = random.Random(seed + legs)
        solve, solve_cached, fallbacks, verified, durations = [], [], 0, 0, []
        for _ in progress(range(count), description=f"optimal k={legs}"):
            track = random_track(rng, legs, 5.0, 15.0)
            start = random_configuration(rng, track, limits.min_separation)
            goal = random_configuration(rng, track, limits.min_separation)
            route = plan(track, start, goal, min_separation=limits.min_separation)
            schedule = optimal.schedule(route, limits)
            info = schedule.info
            solve.append(info.solve_time)
            if not info.built:
                solve_cached.append(info.solve_time)
            fallbacks += schedule.fallback_reason is not None
            verified += verify(schedule).passed
            durations.append(schedule.duration)
        cached = (
            f"; without the {count - len(solve_cached)} one-time builds: median "
            f"{1e3 * statistics.median(solve_cached):.0f} ms, worst {1e3 * max(solve_cached):.0f} ms"
            if solve_cached
            else ""
        )
        emit(
            f"optimal, {count} random scenarios with {legs} legs: fallbacks {fallbacks}, verified "
            f"{verified}/{count}, solve median {1e3 * statistics.median(solve):.0f} ms, worst "
            f"{1e3 * max(solve):.0f} ms{cached}; makespan median {statistics.median(durations):.2f} s"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracks", type=int, default=200, help="random tracks per k (200)")
    parser.add_argument("--queries", type=int, default=50, help="queries per track (50)")
    parser.add_argument("--scenarios", type=int, default=50, help="optimal scenarios per k (50)")
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    for legs in (3, 4, 6, 8):
        bench_planner(legs, args.tracks, args.queries, rng)
    if args.scenarios > 0:
        bench_optimal(args.scenarios, args.seed)


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
