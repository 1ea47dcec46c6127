"""Timing methods are peers: one interface, one registry, options carried by the method objects."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import ClassVar

import pytest

from tests.support.helpers import LIMITS, route_of
from trajgen import (
    METHODS,
    Exact,
    Optimal,
    Outputs,
    Schedule,
    SolverCache,
    TimingMethod,
    Toppra,
    certify,
    default_scenario,
    make_schedule,
    run,
)
from trajgen.errors import InputError, OptionError
from trajgen.methods import MethodRegistry, MethodSource
from trajgen.methods.optimal.method import class_copies
from trajgen.methods.optimal.phases import NO_SWITCH, NlpShape, PhaseKind

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


@dataclass(frozen=True, slots=True)
class Cautious(TimingMethod):
    """A method that is not built in: exact at a fraction of the limits' speed, as a user might add."""

    name: ClassVar[str] = "cautious"
    description: ClassVar[str] = "exact, twice as long"

    @property
    def jerk_limited(self) -> bool:
        return True

    def schedule(self, route, limits):
        exact = Exact().schedule(route, limits)
        return Schedule(route, limits, self, exact.sections, jerk_limited=True, notes=("cautious",))


def test_the_registry_lists_the_methods_in_order_with_a_default():
    assert METHODS.names == ("exact", "toppra", "optimal")
    assert METHODS.default == "optimal"
    assert list(METHODS) == [Exact, Toppra, Optimal]
    assert all(cls.description in METHODS.help() for cls in METHODS)
    assert METHODS.create() == Optimal()
    assert METHODS.create(" Toppra ") == Toppra()
    options = Optimal(nodes=16)
    assert METHODS.create(options) is options


@pytest.mark.parametrize(
    ("name", "match"),
    [
        pytest.param(
            "fast", r"method 'fast' is unknown: expected one of \['exact', 'toppra', 'optimal'\]", id="fast"
        ),
        pytest.param("x" * 500, r"method 'x{30,40}\.\.\. is unknown", id="long-name-cut"),
        pytest.param(3, r"method 3 is unknown", id="number"),
    ],
)
def test_unknown_methods_are_option_errors(name, match):
    with pytest.raises(OptionError, match=match):
        make_schedule(route_of(*SWAP), LIMITS, method=name)


@pytest.mark.parametrize(
    ("build", "match"),
    [
        pytest.param(
            lambda: Exact(jerk="no"), "exact option jerk must be True or False, got 'no'", id="exact"
        ),
        pytest.param(
            lambda: Toppra(grid_points=1), "grid_points must be an integer >= 2, got 1", id="toppra"
        ),
        pytest.param(
            lambda: Toppra(grid_points=True), "grid_points must be an integer >= 2, got True", id="bool"
        ),
    ],
)
def test_method_options_are_validated(build, match):
    with pytest.raises(InputError, match=match):
        build()


def test_make_schedule_checks_its_arguments():
    with pytest.raises(InputError, match=r"route must be a topology\.Route, got str"):
        make_schedule("route", LIMITS)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"limits must be a limits\.Limits, got NoneType"):
        make_schedule(route_of(*SWAP), None)  # type: ignore[arg-type]


def test_a_new_method_plugs_into_dispatch_verification_and_the_pipeline(tmp_path):
    schedule = make_schedule(route_of(*SWAP), LIMITS, method=Cautious())
    assert schedule.method == Cautious()
    assert certify(schedule).report.passed
    registry = MethodRegistry((Exact, Cautious), default="cautious")
    assert registry.names == ("exact", "cautious")
    assert registry.create() == Cautious()
    result = run(default_scenario(), method=Cautious(), outputs=Outputs(csv_dir=tmp_path))
    assert result.summary()["method"] == "cautious"
    assert result.summary()["notes"] == ["cautious"]


@pytest.mark.parametrize(
    ("source", "match"),
    [
        pytest.param(
            MethodSource("exact", "something else", "trajgen.methods.exact", "Exact"),
            r"trajgen\.methods\.exact\.Exact is named 'exact' \('the route exactly.*registered as 'exact' "
            r"\('something else'\)",
            id="summary-drifted",
        ),
        pytest.param(
            MethodSource(
                "fast",
                "the route exactly, one straight piece at a time, jerk-limited S-curves",
                "trajgen.methods.exact",
                "Exact",
            ),
            r"is named 'exact' .*registered as 'fast'",
            id="name-drifted",
        ),
    ],
)
def test_a_registered_source_whose_class_has_drifted_is_refused_when_loaded(source, match):
    registry = MethodRegistry((source,), default=source.name)
    assert registry.names == (source.name,)  # naming needs no import
    with pytest.raises(RuntimeError, match=match):
        registry.create()


def test_the_built_in_sources_name_and_summarize_their_classes():
    assert [(cls.name, cls.description) for cls in METHODS] == [
        (name, line.split(": ", 1)[1].removesuffix(" (default)"))
        for name, line in zip(METHODS.names, METHODS.help().splitlines(), strict=True)
    ]


def test_a_registry_refuses_duplicates_and_an_unknown_default():
    with pytest.raises(ValueError, match="registered twice"):
        MethodRegistry((Exact, Exact), default="exact")
    with pytest.raises(ValueError, match="default method 'optimal' is not among"):
        MethodRegistry((Exact,), default="optimal")


def _shape(nodes: int) -> NlpShape:
    return NlpShape(
        kinds=(PhaseKind((False, False), 0, NO_SWITCH),),
        nodes=nodes,
        segments=1,
        max_iterations=10,
        fatrop_iterations=10,
    )


def test_the_solver_cache_is_bounded_least_recently_used_first():
    cache = SolverCache(maxsize=2)
    built = []

    def build(shape):
        built.append(shape.nodes)
        return object()

    first, _ = cache.get(_shape(1), build=build)
    cache.get(_shape(2), build=build)
    assert cache.get(_shape(1), build=build) == (first, False)  # 1 is now the most recent
    cache.get(_shape(3), build=build)  # evicts 2
    assert len(cache) == 2
    assert _shape(2) not in cache
    assert _shape(1) in cache
    assert built == [1, 2, 3]
    with pytest.raises(ValueError, match="maxsize must be an integer >= 1, got 0"):
        SolverCache(maxsize=0)


def test_the_solver_cache_builds_a_shape_once_across_threads():
    cache = SolverCache()
    calls = []

    def slow_build(shape):
        calls.append(shape)
        time.sleep(0.05)
        return object()

    results = []
    threads = [
        threading.Thread(target=lambda: results.append(cache.get(_shape(4), build=slow_build)))
        for _ in range(8)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(calls) == 1
    assert len({id(entry) for entry, _ in results}) == 1
    assert sorted(built for _, built in results) == [False] * 7 + [True]


def test_warm_up_builds_the_shape_ahead_of_the_first_query():
    method = Optimal(cache=SolverCache(maxsize=4))
    route = route_of(*SWAP)
    assert method.warm_up(route) is True
    assert method.warm_up(route) is False
    assert method.schedule(route, LIMITS).info.built is False


def test_classes_of_different_shapes_share_the_first_copy_and_only_a_shape_needed_twice_gets_a_second():
    one, other = _shape(4), _shape(6)
    assert [s.slot for s in class_copies([one, other])] == [0, 0]
    assert [s.slot for s in class_copies([one, one])] == [0, 1]
    assert [s.slot for s in class_copies([one, other, one])] == [0, 0, 1]
    cache = SolverCache(maxsize=8)
    method = Optimal(cache=cache)
    route = route_of(*SWAP)
    method.warm_up(route)
    shapes = [method.shape(r) for r in method.class_routes(route)]
    assert shapes[0] != shapes[1]
    assert len(cache) == 2
    assert all(shape in cache for shape in shapes)


def test_a_new_time_limit_solves_on_the_nlp_already_built():
    cache = SolverCache(maxsize=4)
    route = route_of(*SWAP)
    assert Optimal(cache=cache, time_limit=2.0).warm_up(route) is True
    schedule = Optimal(cache=cache, time_limit=7.5).schedule(route, LIMITS)
    assert schedule.info.built is False
    assert len(cache) == 2
