"""The optimal method's accuracy set (``-m accuracy``), which CI also runs under the lowest casadi allowed.

Stored reference values (the makespans 0.6.0 computed to full effort on an idle machine, which
0.7 keeps to 0.01 % or betters) and braking-rule plans that once made fatrop loop forever.
"""

from __future__ import annotations

import json

import pytest

from limits import Limits
from tests.conftest import REPO
from topology import plan
from trajgen import Optimal, verify
from trajgen.execution.goals import execution_margin
from trajgen.methods.optimal import Outcome
from trajgen.methods.optimal.solve import abandoned_solver_calls
from trajgen.scenario.sampling import online_campaign, reference_sets

pytestmark = [pytest.mark.slow, pytest.mark.accuracy]

REFERENCE = json.loads((REPO / "tests" / "data" / "optimal_makespans.json").read_text(encoding="utf-8"))
CASES = [
    pytest.param(reference, name, start, goal, id=f"{reference.label}-{name.replace(' ', '-')}")
    for reference in reference_sets(6)
    for name, start, goal in reference.scenarios
]


def test_the_stored_references_cover_the_cases():
    assert sorted(REFERENCE["makespans_s"]) == sorted(f"{p.values[0].label}|{p.values[1]}" for p in CASES)


@pytest.mark.parametrize(("reference", "name", "start", "goal"), CASES)
def test_the_makespan_is_the_stored_one_or_better(reference, name, start, goal):
    stored = REFERENCE["makespans_s"][f"{reference.label}|{name}"]
    route = plan(reference.track, start, goal, min_separation=reference.limits.min_separation)
    schedule = Optimal().schedule(route, reference.limits)
    assert schedule.fallback_reason is None, schedule.notes
    assert verify(schedule).passed
    assert schedule.duration <= stored * (1 + 1e-4)


#: Braking-rule plans of the online campaign (seed 7: (legs, index)) on which fatrop 1.1.8 looped
#: forever: the first three at its default LU pivot tolerance (1e-5), the last at 1e-4. Each one's
#: other class was solved, so a plan came out, with a solver thread left spinning.
HUNG = [(3, 12), (3, 35), (4, 8), (5, 12)]


@pytest.mark.parametrize(("legs", "index"), HUNG, ids=[f"k{legs}-{index}" for legs, index in HUNG])
def test_braking_rule_plans_that_hung_fatrop_are_solved_without_the_watchdog(legs, index):
    scenario = online_campaign(40, seed=7, leg_count=legs)[index]
    separation = scenario.limits.min_separation + 2.0 * execution_margin(scenario, 0.05)
    route = plan(scenario.track, scenario.start, scenario.goal, min_separation=separation)
    before = abandoned_solver_calls()
    # a hang would show as an abandoned attempt at the time limit; none comes back that late
    schedule = Optimal(braking_rule=True, time_limit=120.0).schedule(
        route, Limits(scenario.limits.vehicles, separation)
    )
    assert all(attempt.outcome is not Outcome.ABANDONED for attempt in schedule.info.attempts)
    assert abandoned_solver_calls() == before
    assert schedule.fallback_reason is None, schedule.notes
    assert verify(schedule).passed
