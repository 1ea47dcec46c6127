"""Figures of the order-keeping online executor: cycle cost, and the fault campaign.

1. Per-cycle cost of :meth:`trajgen.execution.Executor.step` for both vehicles (the executor only: the
   simulated plant and the bookkeeping are not timed), over the first ``--timed`` campaign scenarios
   run one at a time in this process: median, 99th percentile, worst, in microseconds. The cycles
   that re-plan for a new goal (planner, timing method, verifier), and those during which Python's
   garbage collector ran, are left out and reported apart. Each timed scenario runs ``--repeats``
   times (default 3): a run is deterministic, so each cycle's fastest time is its own cost, without
   the spikes of the machine. Beside them, the machine's own jitter: a fixed loop of the median's
   duration, timed as often.
2. The campaign: ``--count`` seeded random scenarios (:func:`trajgen.scenario.sampling.online_campaign`),
   each with 1-3 random faults (:func:`trajgen.scenario.sampling.campaign_faults`: stops, slow drives, lags,
   position jumps within the margin, new goals), simulated closed loop: goals reached, deadlocks
   (a run that never reaches its goals), separation violations computed from the true positions,
   limit violations, emergency brakes, the braking check's holds, and the time lost against the
   plans driven (the undisturbed plan, or across a new goal the old plan's part and the new plan:
   ``SimulationResult.planned_s``; median, worst). Scenarios are spread over ``--workers`` processes.
3. With ``--fault-free``, each scenario also runs without faults: the makespan against the plan.
4. With ``--graph``, the scenarios are random track graphs instead
   (:func:`trajgen.scenario.graph_sampling.graph_online_campaign`: trees and graphs with loops),
   their faults :func:`~trajgen.scenario.graph_sampling.graph_campaign_faults`.

Run: ``python benchmarks/bench_online.py [--count 200] [--seed 11] [--timed 20] [--workers 2]
[--method NAME] [--repeats 3] [--fault-free] [--graph]``.
"""

from __future__ import annotations

import argparse
import gc
import logging
import math
import multiprocessing
import statistics
import time

from trajgen.execution import Executor
from trajgen.execution.goals import execution_margin, schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.progress import progress
from trajgen.scenario.graph_sampling import graph_campaign_faults, graph_online_campaign
from trajgen.scenario.sampling import campaign_faults, online_campaign


def run_case(args: tuple[int, int, str | None, bool] | tuple[int, int, str | None, bool, bool]) -> dict:
    """One campaign scenario: its faults and the summary of its simulation (and of a fault-free one)."""
    k, seed, method, fault_free, *graph = args
    logging.disable(logging.WARNING)
    on_graph = bool(graph and graph[0])
    scenario = (graph_online_campaign if on_graph else online_campaign)(k + 1, seed=seed)[k]
    verified = schedule_for_execution(scenario, method=method)
    margin = execution_margin(scenario, 0.05)
    faults = graph_campaign_faults if on_graph else campaign_faults
    specs = faults(scenario, verified.schedule.duration, seed=1000 + k, margin=margin)
    try:
        result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    except Exception as error:  # a crash is a failed scenario, reported with the others
        return {"k": k, "specs": specs, "method": verified.schedule.method.name, "error": repr(error)}
    row = {"k": k, "specs": specs, "method": verified.schedule.method.name, **result.summary()}
    if fault_free:
        clean, _ = simulate(scenario, (), verified=verified)
        row["fault_free"] = clean.summary()
    return row


def timed_cycles(
    count: int, seed: int, method: str | None, repeats: int = 1, graph: bool = False
) -> tuple[list[float], list[float], list[float], list[float]]:
    """Wall time of every executor step (µs) that does not plan, and of those that do (ms).

    A step plans when both vehicles have come to rest for a new goal: it re-plans, or refuses the goal
    if no plan keeps the separation from there. Steps during which Python's cyclic garbage collector
    ran are returned apart (µs): the collector's pause belongs to the host process, which a control
    loop tunes (``gc.freeze()`` after loading, collections between runs), not to the executor.

    Each scenario runs ``repeats`` times: a run is deterministic, so its n-th step does the same work
    every time, and the smallest of its times is that step's own cost, without the machine's
    spikes (returned fourth, µs; with one repeat, the same as the first).
    """
    logging.disable(logging.WARNING)
    cycles: list[float] = []
    collected: list[float] = []
    replans: list[float] = []
    own: list[float] = []
    collections = [0]
    steps: list[tuple[str, float]] = []

    def count_collections(phase: str, _info: dict) -> None:
        if phase == "start":
            collections[0] += 1

    original = Executor.step

    def step(self, states, *more):
        before = self.replans + self.rejected_goals
        runs = collections[0]
        start = time.perf_counter_ns()
        command = original(self, states, *more)
        elapsed = time.perf_counter_ns() - start
        if self.replans + self.rejected_goals > before:
            steps.append(("plan", elapsed / 1e6))
        elif collections[0] > runs:
            steps.append(("collected", elapsed / 1e3))
        else:
            steps.append(("cycle", elapsed / 1e3))
        return command

    Executor.step = step
    gc.callbacks.append(count_collections)
    try:
        for k in progress(range(count), description="timed scenarios"):
            runs = []
            for _ in range(max(1, repeats)):
                steps.clear()
                run_case((k, seed, method, False, graph))
                runs.append(list(steps))
            for kind, elapsed in runs[0]:
                {"plan": replans, "collected": collected, "cycle": cycles}[kind].append(elapsed)
            if len({len(run) for run in runs}) == 1:  # deterministic, as it should be: step by step
                for column in zip(*runs, strict=True):
                    timed = [elapsed for kind, elapsed in column if kind == "cycle"]
                    if timed:
                        own.append(min(timed))
    finally:
        Executor.step = original
        gc.callbacks.remove(count_collections)
    return cycles, collected, replans, own


def machine_jitter(count: int, target_us: float) -> list[float]:
    """Wall time (µs) of a fixed pure-Python loop sized to ``target_us``, run ``count`` times.

    The same work every time: its spread is the machine's (scheduler, virtualisation), which bounds
    how flat any cycle time measured here can be.
    """

    def work(n: int) -> float:
        total = 0.0
        for i in range(n):
            total += i * 0.5
        return total

    n = 100
    while True:  # calibrate n to the target duration (the fastest of a few tries: no spike decides)
        fastest = math.inf
        for _ in range(5):
            start = time.perf_counter_ns()
            work(n)
            fastest = min(fastest, (time.perf_counter_ns() - start) / 1e3)
        if fastest >= target_us or n > 10**7:
            break
        n *= 2
    times = []
    for _ in range(count):
        start = time.perf_counter_ns()
        work(n)
        times.append((time.perf_counter_ns() - start) / 1e3)
    return times


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=200)
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--timed", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--method", default=None, help="timing method of the plans (default: the registry's)")
    parser.add_argument(
        "--repeats", type=int, default=3, help="runs of each timed scenario (each cycle's fastest is its own)"
    )
    parser.add_argument("--fault-free", action="store_true", help="also run each scenario without faults")
    parser.add_argument(
        "--graph",
        action="store_true",
        help="random track graphs (trees and loops: trajgen.scenario.graph_sampling) instead of junctions",
    )
    args = parser.parse_args()

    if args.timed:
        cycles, collected, replans, own = timed_cycles(
            args.timed, args.seed, args.method, args.repeats, args.graph
        )
        print(f"executor cycle (both vehicles), {len(cycles)} cycles of {args.timed} scenarios:")
        print(
            f"  median {statistics.median(cycles):.1f} us, p99 {percentile(cycles, 0.99):.1f} us, "
            f"p99.9 {percentile(cycles, 0.999):.1f} us, "
            f"worst {max(cycles):.1f} us"
        )
        if args.repeats > 1 and own:
            print(
                f"  each cycle's own cost (its fastest of {args.repeats} identical runs, {len(own)} cycles): "
                f"median {statistics.median(own):.1f} us, p99 {percentile(own, 0.99):.1f} us, "
                f"p99.9 {percentile(own, 0.999):.1f} us, worst {max(own):.1f} us"
            )
        jitter = machine_jitter(len(cycles), statistics.median(cycles))
        print(
            f"the machine's own jitter: a fixed loop of about the median, {len(jitter)} times: "
            f"median {statistics.median(jitter):.1f} us, p99.9 {percentile(jitter, 0.999):.1f} us, "
            f"worst {max(jitter):.1f} us"
        )
        if collected:
            print(
                f"cycles during which the garbage collector ran ({len(collected)}): "
                f"median {statistics.median(collected):.1f} us, worst {max(collected):.1f} us"
            )
        if replans:
            print(
                f"planning cycles (a new goal, planned or refused: {len(replans)}): "
                f"median {statistics.median(replans):.1f} ms, worst {max(replans):.1f} ms"
            )

    if not args.count:
        return
    started = time.perf_counter()
    with multiprocessing.Pool(args.workers) as pool:
        cases = [(k, args.seed, args.method, args.fault_free, args.graph) for k in range(args.count)]
        done = progress(pool.imap_unordered(run_case, cases), total=len(cases), description="campaign")
        rows = sorted(done, key=lambda r: r["k"])
    wall = time.perf_counter() - started
    crashed = [r for r in rows if "error" in r]
    rows = [r for r in rows if "error" not in r]
    failed = [r for r in rows if not r["reached_goal"] or r["violations"] or r["emergency_brakes"]]
    lost = [r["time_lost_s"] for r in rows if r["reached_goal"]]
    relative = [r["time_lost_s"] / r["planned_s"] for r in rows if r["reached_goal"] and r["planned_s"] > 0]
    methods = sorted({r["method"] for r in rows})
    print(
        f"campaign: {args.count} {'track-graph ' if args.graph else ''}scenarios "
        f"(seed {args.seed}, plans by {', '.join(methods)}), "
        f"1-3 faults each, {wall:.0f} s wall"
    )
    print(f"  crashed (an exception in the run): {len(crashed)}")
    print(f"  goals reached: {sum(r['reached_goal'] for r in rows)}/{len(rows) + len(crashed)}")
    print(f"  deadlocks (goals never reached): {sum(not r['reached_goal'] for r in rows)}")
    print(f"  separation violations: {sum(r['separation_violations'] for r in rows)} cycles")
    print(f"  limit violations: {sum(r['limit_violations'] for r in rows)} cycles")
    print(f"  emergency brakes: {sum(r['emergency_brakes'] for r in rows)} cycles")
    holds = sum(r["holds"] for r in rows)
    print(f"  braking-check holds: {holds} cycles in {sum(r['holds'] > 0 for r in rows)} runs")
    replans, refused = sum(r["replans"] for r in rows), sum(r["rejected_goals"] for r in rows)
    print(f"  re-plans (new goals): {replans}; refused goals: {refused}")
    limited = [r for r in rows if r["computed_by"] != "toppra"]  # a toppra plan does not limit jerk
    jerk = f"{max(r['jerk_ratio'] for r in limited):.9f}" if limited else "not limited (toppra)"
    print(
        "  worst ratios to the limits (v, a, j): "
        f"{max(r['velocity_ratio'] for r in rows):.9f}, {max(r['acceleration_ratio'] for r in rows):.9f}, "
        f"{jerk}"
    )
    if lost:
        print(
            f"  time lost against the plans driven: median {statistics.median(lost):.2f} s "
            f"({100 * statistics.median(relative):.0f} % of the plan), worst {max(lost):.2f} s"
        )
    if args.fault_free:
        clean = [r["fault_free"] for r in rows]
        ratio = [c["makespan_s"] / c["planned_s"] - 1.0 for c in clean if c["planned_s"] > 0]
        print(
            f"  fault-free: {sum(c['reached_goal'] for c in clean)}/{len(clean)} reached, makespan over plan "
            f"median {100 * statistics.median(ratio):.2f} %, worst {100 * max(ratio):.2f} %; "
            f"holds {sum(c['holds'] for c in clean)}, "
            f"emergency brakes {sum(c['emergency_brakes'] for c in clean)}"
        )
    for r in crashed:
        print(f"  CRASHED scenario {r['k']}: {', '.join(r['specs'])}: {r['error']}")
    for r in failed:
        print(
            f"  FAILED scenario {r['k']}: {', '.join(r['specs'])}: reached {r['reached_goal']}, "
            f"separation violations {r['separation_violations']}, "
            f"limit violations {r['limit_violations']}, emergency brakes {r['emergency_brakes']}, "
            f"closest {r['min_separation_m']:.6f} m"
        )


if __name__ == "__main__":
    main()
