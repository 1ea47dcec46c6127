"""The optimal method: closed-form cases, order against exact and the lower bound, and fallbacks.

Also the homotopy class, verification, NLP reuse and the backup solvers.
"""

from __future__ import annotations

import logging
import threading
import time
import types

import numpy as np
import pytest

from limits import Limits, VehicleLimits
from tests.support.helpers import LIMITS, MIXED, conf, route_of
from topology import Homotopy, YGraph, plan, region_sequence
from trajgen import Exact, FallbackReason, Optimal, SolverCache, certify, lower_bound, make_schedule, verify
from trajgen.errors import InputError
from trajgen.methods.optimal import Solver, Source
from trajgen.methods.optimal.compiled import SOLUTIONS_REMEMBERED, CompiledNlp, RecentlyUsed
from trajgen.methods.optimal.solve import Outcome, SolveResult, abandoned_solver_calls, solve
from trajgen.methods.optimal.units import ProblemUnits
from trajgen.model.analysis import travelled
from trajgen.model.profiles import rest_to_rest_time
from trajgen.plots import plot_coordination, png_bytes
from trajgen.scenario.sampling import random_scenarios, reference_sets


def coordination_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_coordination(...)``."""
    return png_bytes(plot_coordination(*arguments, **options))


EQUAL = (10.0, 10.0, 10.0)
UNEQUAL = (12.0, 8.0, 15.0)
SWAPS = [
    pytest.param(legs, (f"{a}:{legs['ABC'.index(a)]}", f"{b}:{legs['ABC'.index(b)]}"), id=f"{a}{b}-{label}")
    for label, legs in (("equal", EQUAL), ("unequal", UNEQUAL))
    for a, b in (("A", "B"), ("B", "C"), ("C", "A"))
]
TRACK = YGraph(dict(zip("ABC", UNEQUAL, strict=True)))
RANDOM = random_scenarios(6, seed=404, track=TRACK, limits=MIXED)


def optimal_schedule(route, limits, **options):
    return Optimal(**options).schedule(route, limits)


def exact_schedule(route, limits):
    return Exact().schedule(route, limits)


@pytest.mark.slow
@pytest.mark.parametrize(("legs", "start"), SWAPS)
def test_swaps_are_at_most_half_of_exact_and_stay_in_the_class(legs, start):
    route = route_of(legs, start, start[::-1])
    schedule = optimal_schedule(route, LIMITS)
    assert schedule.fallback_reason is None, schedule.fallback_reason
    assert schedule.method == Optimal()
    # start and goal at leg ends: no bound may be tied to a rest equality, or fatrop stalls
    assert schedule.info.solver is Solver.FATROP, schedule.info.status
    report = verify(schedule)
    assert report.passed, report.failures
    assert report.regions_match
    exact = exact_schedule(route, LIMITS)
    assert schedule.duration <= 0.5 * exact.duration
    assert lower_bound(route, LIMITS) <= schedule.duration
    # the sampled region sequence is the homotopy class of the schedule's route, one of the two
    # shortest (on these symmetric swaps the two classes are nearly as fast)
    assert schedule.route.regions in (route.regions, route_of(legs, start, start[::-1]).regions) or (
        schedule.route.homotopy is Homotopy.OTHER
    )
    times = [k * schedule.duration / 2000 for k in range(2001)]
    sampled = region_sequence(route.graph, [schedule.configuration_at(t) for t in times])
    assert sampled == schedule.route.regions


def test_equal_legs_swaps_have_equal_makespans():
    # the three swaps on an equilateral Y are rotations of one another
    durations = [
        optimal_schedule(route_of(EQUAL, s, s[::-1]), LIMITS).duration
        for s in (("A:10", "B:10"), ("B:10", "C:10"), ("C:10", "A:10"))
    ]
    assert max(durations) - min(durations) < 1e-6 * durations[0]


def test_vehicles_that_never_interact_take_the_slower_vehicles_own_time():
    # vehicle 1 drives out of the junction into C while vehicle 2 backs up a little on A:
    # they never come near each other, so the makespan is vehicle 1's own S-curve time
    route = plan(TRACK, conf("O", "A:7.5"), conf("C:15", "A:5"), min_separation=1.5)
    schedule = optimal_schedule(route, LIMITS)
    own = max(rest_to_rest_time(15.0, 1.0, 0.5, 1.0), rest_to_rest_time(2.5, 1.0, 0.5, 1.0))
    assert own == pytest.approx(17.5)
    assert lower_bound(route, LIMITS) == pytest.approx(own)
    assert own <= schedule.duration <= own * (1 + 5e-3)
    assert verify(schedule).passed


def test_slower_vehicle_sets_the_time_when_it_moves_alone():
    slow = VehicleLimits(0.7, 0.35, 0.6)
    limits = Limits(vehicles=(slow, VehicleLimits(1.0, 0.5, 1.0)), min_separation=1.5)
    route = plan(TRACK, conf("A:2", "O"), conf("A:11", "O"), min_separation=1.5)
    schedule = optimal_schedule(route, limits)
    own = rest_to_rest_time(9.0, 0.7, 0.35, 0.6)
    assert own <= schedule.duration <= own * (1 + 5e-3)


@pytest.mark.slow
@pytest.mark.parametrize("scenario", RANDOM, ids=[s.source for s in RANDOM])
def test_lower_bound_optimal_exact_order_and_verification(scenario):
    route = scenario.route()
    schedule = optimal_schedule(route, scenario.limits)
    exact = exact_schedule(route, scenario.limits)
    report = verify(schedule)
    assert report.passed, report.failures
    assert lower_bound(route, scenario.limits) <= schedule.duration * (1 + 1e-9)
    assert schedule.duration <= exact.duration * (1 + 1e-9)
    assert schedule.route.regions == route.regions


def test_nlp_is_built_once_per_shape_and_reused():
    method = Optimal(cache=SolverCache())
    first = method.schedule(route_of(EQUAL, ("A:10", "B:10"), ("B:10", "A:10")), LIMITS)
    second = method.schedule(route_of(EQUAL, ("B:10", "C:10"), ("C:10", "B:10")), LIMITS)
    assert first.info.built is True
    assert second.info.built is False  # same region-sequence shapes, new parameters (and grids)
    assert second.duration == pytest.approx(first.duration, rel=1e-6)
    # one compiled copy per class: the swap's two classes are solved concurrently
    assert [c.makespan is not None for c in first.info.classes] == [True, True]
    assert len(method.cache) == 2


@pytest.fixture
def solver_calls(monkeypatch) -> list:
    """Every solver a compiled NLP is asked for (``CompiledNlp.solver``), in order, as the solves run."""
    calls = []
    real_solver = CompiledNlp.solver

    def counting(self, which, *, ipopt_wall_time):
        calls.append(which)
        return real_solver(self, which, ipopt_wall_time=ipopt_wall_time)

    monkeypatch.setattr(CompiledNlp, "solver", counting)
    return calls


def test_a_problem_solved_before_is_answered_from_memory_and_another_is_solved(solver_calls):
    calls = solver_calls
    method = Optimal(cache=SolverCache())
    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    first = method.schedule(route, LIMITS)
    assert calls, "the first request solves"
    calls.clear()
    again = method.schedule(route, LIMITS)
    assert calls == []  # the same problems: every pass answered from memory
    assert again.duration == first.duration
    assert again.info.attempts == first.info.attempts  # what each solver did, as it did it
    assert again.info.classes == first.info.classes
    np.testing.assert_array_equal(again.sample(0.1).axis, first.sample(0.1).axis)
    assert verify(again).passed
    method.schedule(route, MIXED)
    assert calls, "other limits are another problem: solved, not recalled"


def test_the_memory_keeps_the_last_solutions_used_only():
    memory = RecentlyUsed(SOLUTIONS_REMEMBERED)
    results = [SolveResult(np.full(2, float(i)), ()) for i in range(SOLUTIONS_REMEMBERED + 1)]
    for i, result in enumerate(results):
        memory.put(bytes([i]), result)
    assert memory.get(bytes([0])) is None  # the least recently used went first
    assert memory.get(bytes([1])) is results[1]
    memory.put(bytes([99]), results[0])
    assert memory.get(bytes([1])) is results[1]  # used just now: kept
    assert memory.get(bytes([2])) is None


def test_forced_solver_failure_falls_back_to_exact_and_logs(caplog):
    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    with caplog.at_level(logging.WARNING, logger="trajgen.methods.optimal"):
        schedule = optimal_schedule(route, LIMITS, max_iterations=1)
    exact = exact_schedule(route, LIMITS)
    assert schedule.fallback_reason is FallbackReason.SOLVER_FAILED
    assert "did not converge" in schedule.notes[0]
    assert schedule.info.source is Source.EXACT
    assert schedule.method == Exact()
    assert schedule.duration == exact.duration
    assert verify(schedule).passed
    # the warning says why in words (not "see the notes"); the note lists the attempts
    assert any(
        "fell back to the exact schedule (solver-failed): no solver converged (fatrop, then Ipopt)"
        in record.message
        for record in caplog.records
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("fatrop_iterations", "solved_by"),
    [
        pytest.param(20, Solver.IPOPT_POLISH, id="polish-from-fatrop-iterate"),
        pytest.param(5, Solver.IPOPT, id="cold-ipopt-after-failed-polish"),
    ],
)
def test_backup_solvers_reach_fatrops_optimum(fatrop_iterations, solved_by):
    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    # the chain on one class and one grid (no refinement), so that each attempt is one solver's
    single = {"homotopy": "planned", "refinements": 0}
    reference = optimal_schedule(route, LIMITS, **single)
    assert reference.info.solver is Solver.FATROP
    # a fresh NLP whose fatrop stops early: the chain must carry on to the same optimum
    schedule = optimal_schedule(
        route, LIMITS, fatrop_iterations=fatrop_iterations, cache=SolverCache(), **single
    )
    assert schedule.info.attempts[0].solver is Solver.FATROP
    assert "did not converge" in str(schedule.info.attempts[0])
    assert schedule.info.solver is solved_by
    assert schedule.fallback_reason is None
    assert verify(schedule).passed
    assert schedule.duration == pytest.approx(reference.duration, rel=1e-6)


@pytest.mark.slow
def test_fatrop_solves_the_five_phase_reordering_on_one_leg():
    # benchmark set c, random 2: both vehicles on B must swap their order, via A and C (5 phases),
    # and vehicle 1 ends at the end of B. With bounds tied to the rest and junction equalities
    # (no strict interior), fatrop crawled for 500 iterations here and Ipopt took 2.6 s.
    scenario = random_scenarios(3, seed=2026, track=TRACK, limits=LIMITS)[2]
    route = plan(TRACK, scenario.start, scenario.goal, min_separation=1.5)
    assert len(route.regions) == 5
    schedule = optimal_schedule(route, LIMITS)
    assert schedule.info.solver is Solver.FATROP, schedule.info.status
    assert verify(schedule).passed
    assert schedule.duration < 0.25 * exact_schedule(route, LIMITS).duration


BENCHMARK_SAMPLE = [
    pytest.param(reference, start, goal, id=f"{reference.label}-{name.replace(' ', '-')}")
    for reference in reference_sets(2)
    for name, start, goal in reference.scenarios
]


@pytest.mark.slow
@pytest.mark.accuracy
@pytest.mark.parametrize(("reference", "start", "goal"), BENCHMARK_SAMPLE)
def test_benchmark_scenarios_are_verified_and_between_their_bounds(reference, start, goal):
    # every set of benchmarks/bench_optimal.py (its 106 scenarios: `--count 50`), two of each random set here
    limits = reference.limits
    route = plan(reference.track, start, goal, min_separation=limits.min_separation)
    schedule = optimal_schedule(route, limits)
    assert schedule.fallback_reason is None, schedule.notes
    report = verify(schedule)
    assert report.passed, report.failures
    assert report.regions_match
    assert lower_bound(route, limits) <= schedule.duration * (1 + 1e-9)
    assert schedule.duration <= exact_schedule(route, limits).duration * (1 + 1e-9)


def test_make_schedule_dispatches_optimal():
    route = route_of(UNEQUAL, ("A:3", "B:2"), ("C:4", "C:9"))
    schedule = make_schedule(route, LIMITS, method="optimal")
    assert schedule.method == Optimal()
    assert schedule.duration < exact_schedule(route, LIMITS).duration


@pytest.mark.parametrize(
    ("options", "match"),
    [
        pytest.param({"nodes": 0}, "option nodes must be an integer >= 1, got 0", id="nodes"),
        pytest.param({"nodes": True}, "option nodes must be an integer >= 1, got True", id="nodes-bool"),
        pytest.param({"segments": 0}, "option segments must be an integer >= 1, got 0", id="segments"),
        pytest.param({"max_iterations": 0}, "max_iterations must be an integer >= 1, got 0", id="iterations"),
        pytest.param({"fatrop_iterations": 1.5}, "fatrop_iterations must be an integer", id="fatrop"),
        pytest.param({"cache": {}}, "cache must be a SolverCache or None, got dict", id="cache"),
        pytest.param(
            {"refinements": -1}, "option refinements must be an integer >= 0, got -1", id="refinements"
        ),
        pytest.param(
            {"refinement_tolerance": 0.0},
            r"refinement_tolerance must be a number in \(0, 1\), got 0.0",
            id="tolerance-zero",
        ),
        pytest.param(
            {"refinement_tolerance": "1e-3"},
            r"refinement_tolerance must be a number in \(0, 1\), got '1e-3'",
            id="tolerance-text",
        ),
        pytest.param(
            {"homotopy": "both"},
            r"homotopy choice 'both' is unknown: expected one of \['fastest', 'planned'\]",
            id="homotopy",
        ),
    ],
)
def test_bad_options(options, match):
    with pytest.raises(InputError, match=match):
        Optimal(**options)


def test_coordination_plot_is_rendered_for_verified_schedules():
    route = route_of(EQUAL, ("A:10", "B:10"), ("B:10", "A:10"))
    schedules = {
        "exact": exact_schedule(route, LIMITS),
        "optimal": optimal_schedule(route, LIMITS),
    }
    png = coordination_png({name: certify(s) for name, s in schedules.items()})
    assert png.startswith(b"\x89PNG")
    # travelled distances never decrease, and the optimal one parks shallower (drives less)
    _, exact_distance, _, _ = travelled(schedules["exact"])
    _, optimal_distance, _, _ = travelled(schedules["optimal"])
    assert (exact_distance[:, 1:] >= exact_distance[:, :-1]).all()
    assert exact_distance[1, -1] == pytest.approx(40.0, abs=1e-6)
    assert optimal_distance[1, -1] < exact_distance[1, -1]


@pytest.mark.parametrize(("a", "b"), [("A", "B"), ("B", "C"), ("C", "A")])
def test_a_separation_equal_to_the_shortest_leg_is_solved_not_fallen_back(a, b):
    # degenerate: the waiting vehicle must park at the very end of the 8 m leg while the other
    # passes the junction; with the full planning margin there is no solution at all
    track = YGraph({"A": 12.0, "B": 8.0, "C": 15.0})
    start = conf(f"{a}:{track.length(a)}", f"{b}:{track.length(b)}")
    limits = Limits(vehicles=LIMITS.vehicles, min_separation=track.shortest_leg)
    route = plan(track, start, start.swapped(), min_separation=track.shortest_leg)
    schedule = optimal_schedule(route, limits)
    assert schedule.fallback_reason is None, schedule.notes
    report = verify(schedule)
    assert report.passed, report.failures
    assert report.separation_margin >= -1e-9
    assert schedule.duration < exact_schedule(route, limits).duration


def test_a_reached_time_limit_returns_the_verified_exact_schedule_flagged():
    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    schedule = optimal_schedule(route, LIMITS, time_limit=1e-4, cache=SolverCache())
    assert schedule.fallback_reason is FallbackReason.TIME_LIMIT
    assert FallbackReason.TIME_BUDGET is FallbackReason.TIME_LIMIT  # the deprecated name
    assert schedule.method == Exact()
    assert verify(schedule).passed
    assert "not tried: the time limit was reached" in schedule.notes[0]
    with pytest.raises(InputError, match="time_limit must be a finite number of seconds > 0, got 0"):
        Optimal(time_limit=0)


def test_the_deprecated_time_budget_is_the_time_limit():
    with pytest.warns(DeprecationWarning, match=r"Optimal\(time_budget=\.\.\.\) is deprecated"):
        method = Optimal(time_budget=7.5)
    assert method.time_limit == 7.5
    assert method == Optimal(time_limit=7.5)


class _SleepySolver:
    """A stand-in for a CasADi solver that takes ``seconds`` to answer."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds

    def __call__(self, **_arguments):
        time.sleep(self.seconds)
        return {"x": np.zeros(3), "lam_x": np.zeros(3), "lam_g": np.zeros(0)}

    def stats(self) -> dict:
        return {"success": True, "iter_count": 7, "return_status": "0"}


class _StandInNlp:
    """The parts of a compiled NLP that ``solve`` uses, with a solver of a given speed."""

    def __init__(self, seconds: float) -> None:
        self.bounds = {}
        self.shape = None  # solved in seconds and metres: the shape is not needed
        self.lock = threading.Lock()
        self.abandoned = False
        self._solver = _SleepySolver(seconds)
        self.solutions = RecentlyUsed(0)  # remembers nothing

    def solver(self, _which, *, ipopt_wall_time):
        return self._solver


@pytest.mark.parametrize(("seconds", "abandoned"), [(0.0, False), (3.0, True)], ids=["prompt", "stuck"])
def test_a_fatrop_call_not_back_by_the_deadline_is_abandoned(seconds, abandoned):
    compiled = _StandInNlp(seconds)
    began = time.perf_counter()
    result = solve(compiled, np.zeros(3), np.zeros(0), units=ProblemUnits(1.0, 1.0), deadline=began + 0.3)
    assert time.perf_counter() - began < 1.0  # the caller is back soon after the deadline
    assert compiled.abandoned is abandoned
    if abandoned:
        assert result.solution is None
        assert [a.outcome for a in result.attempts] == [Outcome.ABANDONED]
        assert "abandoned" in str(result.attempts[0])
        assert abandoned_solver_calls() >= 1  # the console script ends at once while it runs
    else:
        assert result.solver is Solver.FATROP
        assert result.attempts[0].iterations == 7


class _OnePhase:
    """A stand-in for a shape: hashable, one phase."""

    phase_count = 1


def test_the_cache_builds_an_abandoned_nlp_afresh():
    built = []

    def build(shape):
        built.append(shape)
        return types.SimpleNamespace(abandoned=False)

    cache = SolverCache(maxsize=2)
    shape = _OnePhase()
    first, was_built = cache.get(shape, build=build)
    assert was_built
    assert cache.get(shape, build=build) == (first, False)
    first.abandoned = True  # a solver call on it never came back
    second, was_built = cache.get(shape, build=build)
    assert was_built
    assert second is not first
    assert built == [shape, shape]


def test_a_time_limit_reached_after_the_first_pass_keeps_that_pass_and_says_so(monkeypatch):
    from trajgen.methods.optimal import class_solve as optimal_method
    from trajgen.model.summary import provenance

    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    solved = []
    real_solve, real_clock = optimal_method.solve, time.perf_counter

    def solve_once_then_late(*arguments, **options):
        result = real_solve(*arguments, **options)
        solved.append(result)
        return result

    # the clock jumps a million seconds once the first pass is solved: the safety stop is reached
    late_clock = types.SimpleNamespace(perf_counter=lambda: real_clock() + (1e6 if solved else 0.0))
    monkeypatch.setattr(optimal_method, "solve", solve_once_then_late)
    monkeypatch.setattr(optimal_method, "time", late_clock)
    schedule = Optimal(homotopy="planned", cache=SolverCache()).schedule(route, LIMITS)
    assert len(solved) == 1  # no refinement pass started after the limit
    assert schedule.fallback_reason is None  # the first pass is kept, verified
    assert verify(schedule).passed
    assert schedule.info.time_limit_reached is True
    assert schedule.info.summary()["time_limit_reached"] is True
    assert provenance(schedule, "optimal")["time_limit_reached"] is True
    assert any(
        "the time limit (30 s, a safety stop) ended its refinement after pass 1" in n for n in schedule.notes
    )


def test_forgotten_solutions_are_solved_again_to_the_same_schedule(solver_calls):
    calls = solver_calls
    method = Optimal(cache=SolverCache())
    route = route_of(UNEQUAL, ("A:12", "B:8"), ("B:8", "A:12"))
    first = method.schedule(route, LIMITS)
    solved = len(calls)
    method.cache.forget_solutions()
    assert all(len(entry.solutions) == 0 for entry in method.cache.compiled())
    assert len(method.cache.compiled()) > 0  # the NLPs stay
    calls.clear()
    again = method.schedule(route, LIMITS)
    assert len(calls) == solved  # every pass solved again, none recalled
    assert again.duration == first.duration
    assert again.info.classes == first.info.classes
