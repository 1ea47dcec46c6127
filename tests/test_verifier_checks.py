"""Each check of the verifier, tampered with once on every case of the table, is caught and placed.

One verifier serves every track: the same tampering of a junction's plan and of a track graph's
plan fails the same check, with a message in words and details that name the schedule's arrays. It
serves any number of vehicles too: the table's cases are joined by routes of three and four vehicles
made by hand (:mod:`tests.support.fleets`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re

import numpy as np
import pytest

from limits import Limits
from tests.support.cases import CASES
from tests.support.fleets import FLEETS
from topology import plan
from trajgen import verify
from trajgen.methods import make_schedule
from trajgen.model.schedule import CubicKinematics


def _limits(schedule, **scale):
    """The schedule's limits with each named limit scaled, and its separation."""
    vehicles = tuple(
        dataclasses.replace(v, **{name: getattr(v, name) * factor for name, factor in scale.items()})
        for v in schedule.limits.vehicles
    )
    return Limits(vehicles, schedule.limits.min_separation)


def _slower(name):
    def tamper(schedule, report):
        return dataclasses.replace(schedule, limits=_limits(schedule, **{name: 0.5}))

    return tamper


def _farther(schedule, report):
    """A separation half a metre more than the closest approach the plan keeps."""
    return dataclasses.replace(schedule, limits=Limits(schedule.limits.vehicles, report.min_separation + 0.5))


def _moving_section(schedule) -> int:
    """The first section whose kinematics are piecewise cubic with a vehicle that moves."""
    for number, section in enumerate(schedule.sections):
        if type(section.kinematics) is CubicKinematics:
            return number
    raise AssertionError("no piecewise cubic section")


def _not_a_number(schedule, report):
    """A NaN in a vehicle's knot jerks of a section."""
    number = _moving_section(schedule)
    section = schedule.sections[number]
    profile = section.kinematics.vehicles[0]
    jerk = np.array(profile.jerk, dtype=float)
    jerk[0] = math.nan
    broken = copy.copy(profile)  # past the constructor, which refuses it: as a corrupted object would be
    object.__setattr__(broken, "jerk", jerk)
    kinematics = CubicKinematics((broken, *section.kinematics.vehicles[1:]))
    sections = list(schedule.sections)
    sections[number] = dataclasses.replace(section, kinematics=kinematics)
    return dataclasses.replace(schedule, sections=tuple(sections))


def _jump(schedule, report):
    """Vehicle 1's motion in the last piecewise cubic section after the first starts a centimetre on."""
    sections = list(schedule.sections)
    number = max(k for k, s in enumerate(sections) if k and type(s.kinematics) is CubicKinematics)
    section = sections[number]
    profile = section.kinematics.vehicles[0]
    initial = np.array(profile.initial, dtype=float)
    initial[:, 0] += 0.01
    broken = copy.copy(profile)
    object.__setattr__(broken, "initial", initial)
    kinematics = CubicKinematics((broken, *section.kinematics.vehicles[1:]))
    sections[number] = dataclasses.replace(section, kinematics=kinematics)
    return dataclasses.replace(schedule, sections=tuple(sections))


def _late(schedule, report):
    """The last section begins a second after the one before it ends."""
    sections = list(schedule.sections)
    sections[-1] = dataclasses.replace(sections[-1], start_time=sections[-1].start_time + 1.0)
    return dataclasses.replace(schedule, sections=tuple(sections))


#: check -> (tampering, the failure it must raise, what its details must name).
CHECKS = {
    "velocity": (
        _slower("max_velocity"),
        r"velocity reaches .* at t=.* s \(on (leg|edge) '.*\) exceeds its max_velocity",
        "sections[",
    ),
    "acceleration": (
        _slower("max_acceleration"),
        r"acceleration reaches .* exceeds its max_acceleration",
        "sections[",
    ),
    "jerk": (_slower("max_jerk"), r"jerk reaches .* exceeds its max_jerk", "sections["),
    "separation": (_farther, r"separation .* m at t=.* is below the minimum", "sections["),
    "finite": (_not_a_number, r"hold nan: expected finite numbers", "].jerk["),
    "tiling": (_late, r"starts at t=.* s: expected .* where the section before it ends", "].start_time"),
    "continuity": (
        _jump,
        r"vehicle 1 (position|axis) jumps by 0.01 .*at t=.* s \(on (leg|edge) '",
        "sections[",
    ),
}


def test_every_case_of_the_table_passes_untouched():
    for case in (*CASES, *FLEETS):
        assert case.verified().report.passed, case.name


@pytest.mark.parametrize("check", sorted(CHECKS))
@pytest.mark.parametrize("case", [*CASES, *FLEETS], ids=[case.name for case in (*CASES, *FLEETS)])
def test_each_check_catches_its_tampering_on_every_track(case, check):
    tamper, failure, arrays = CHECKS[check]
    verified = case.verified()
    report = verify(tamper(verified.schedule, verified.report))
    assert not report.passed
    found = [(text, detail) for text, detail in zip(report.failures, report.details, strict=True)]
    matching = [(text, detail) for text, detail in found if re.search(failure, text)]
    assert matching, report.failures
    text, detail = matching[0]
    assert detail.startswith(text), detail
    assert arrays in detail, detail


@pytest.mark.parametrize("case", FLEETS, ids=[case.name for case in FLEETS])
def test_a_fleets_last_vehicle_too_fast_for_its_own_limit_is_named_with_its_arrays(case):
    schedule = case.verified().schedule
    last = schedule.count - 1
    vehicles = list(schedule.limits.vehicles)
    vehicles[last] = dataclasses.replace(vehicles[last], max_velocity=0.5 * vehicles[last].max_velocity)
    report = verify(
        dataclasses.replace(schedule, limits=Limits(tuple(vehicles), schedule.limits.min_separation))
    )
    assert not report.passed
    assert all(text.startswith(f"vehicle {last + 1} velocity reaches") for text in report.failures), (
        report.failures
    )
    assert f"vehicles[{last}]" in report.details[0]
    assert f"paths[{last}]" in report.details[0]


@pytest.mark.parametrize("case", FLEETS, ids=[case.name for case in FLEETS])
def test_a_fleets_closest_pair_is_named_when_the_separation_is_raised(case):
    verified = case.verified()
    schedule = verified.schedule
    report = verify(dataclasses.replace(schedule, limits=Limits(schedule.limits.vehicles, 2.5)))
    assert not report.passed
    found = [text for text in report.failures if text.startswith("separation 2 m")]
    assert found, report.failures
    assert re.search(r"\(vehicle (\d) on '.*', vehicle (\d) on '.*'\)", found[0]), found[0]


#: Cases whose optimal plan, made without the braking rule, breaks it: relabelled as a plan for execution,
#: the verifier must refuse it. On the passing loop and the ring the vehicles' optimal plans obey it
#: untouched (checked too).
BREAKS_THE_RULE = {"y": True, "4-leg": True, "8-leg": True, "h": True, "passing-loop": False, "ring": False}


@pytest.mark.parametrize(
    "case",
    [
        pytest.param(case, id=case.name, marks=pytest.mark.slow if case.name == "h" else ())
        for case in CASES  # the H's optimal plan takes seconds
    ],
)
def test_the_braking_rule_is_checked_on_every_track_for_a_plan_for_execution(case):
    planned = case.verified("optimal").schedule
    assert not planned.method.plans_for_execution
    report = verify(dataclasses.replace(planned, method=planned.method.for_execution()))
    assert report.passed != BREAKS_THE_RULE[case.name], report.failures
    if not report.passed:
        assert re.search(r"cannot stop short of its frontier at t=.* \(the braking rule", report.failures[0])
        assert "sections[" in report.details[0]


def _in_another_class(case):
    """The case's plan relabelled with a route of the other class (the order of passing reversed).

    On a junction, the planner's route of the other class; on a track graph, the route's moves with
    each vehicle's own in order, the vehicle that moved first now moving after the other.
    """
    scenario, schedule = case.scenario(), case.verified().schedule
    route = schedule.route
    if hasattr(route, "moves"):
        moves = tuple(sorted(route.moves, key=lambda move: move.vehicle == route.moves[0].vehicle))
        timed = make_schedule(dataclasses.replace(route, moves=moves), scenario.limits, method="exact")
        return dataclasses.replace(timed, route=route)
    other = plan(
        scenario.track, scenario.start, scenario.goal, min_separation=route.min_separation, homotopy="other"
    )
    return dataclasses.replace(schedule, route=other)


@pytest.mark.parametrize("case", CASES, ids=[case.name for case in CASES])
def test_the_class_check_catches_a_plan_of_another_class_on_every_track(case):
    report = verify(_in_another_class(case))
    assert not report.passed
    assert not report.regions_match
    found = [
        (text, detail)
        for text, detail in zip(report.failures, report.details, strict=True)
        if re.search(r"another class than (the|their) route's", text)
    ]
    assert found, report.failures
    assert "sections[" in found[0][1]


def _without_last_vehicle(schedule, *, paths: bool = True):
    """The schedule with its last vehicle's motion left out of every section (and its path, if asked)."""
    sections = tuple(
        dataclasses.replace(section, kinematics=CubicKinematics(section.kinematics.vehicles[:-1]))
        for section in schedule.sections
    )
    return dataclasses.replace(
        schedule, sections=sections, paths=schedule.paths[:-1] if paths else schedule.paths
    )


@pytest.mark.parametrize("case", FLEETS, ids=[case.name for case in FLEETS])
def test_a_schedule_that_leaves_out_a_vehicle_its_route_moves_is_refused(case):
    schedule = case.verified().schedule
    count = schedule.count
    report = verify(_without_last_vehicle(schedule))
    assert not report.passed
    assert report.failures[0] == (
        f"the schedule has {count - 1} path(s), its route moves {count} vehicle(s): expected one per vehicle"
    )
    report = verify(_without_last_vehicle(schedule, paths=False))
    assert not report.passed
    assert f"section 1 moves {count - 1} vehicle(s), the route {count}" in report.failures[0]
    assert report.details[0].endswith("sections[0].kinematics")
