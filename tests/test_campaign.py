"""A seeded random campaign over a wide range of scenarios: every schedule of every method verifies.

300 scenarios from :func:`trajgen.scenario.sampling.campaign_scenarios` (legs 0.5-5000 m,
independent limits, separations up to the shortest leg, swaps and random
goals): ``exact`` and ``toppra`` on every :data:`EVERY`-th, ``optimal`` (seconds
per solve) on every :data:`OPTIMAL_EVERY`-th. ``benchmarks/bench_campaign.py``
prints the same campaign's figures, every method on all 300.
"""

from __future__ import annotations

import pytest

from trajgen import Exact, Optimal, SolverCache, Toppra, certify, make_schedule
from trajgen.scenario.sampling import campaign_scenarios

pytestmark = pytest.mark.slow

SCENARIOS = campaign_scenarios(300, seed=9)
#: ``exact`` and ``toppra`` are timed on the scenarios whose index is a multiple of this, one test each
#: (the longest schedules take seconds to verify) ...
EVERY = 10
#: ... and ``optimal`` on those whose index is a multiple of this.
OPTIMAL_EVERY = 60


def test_the_campaign_spans_the_whole_range():
    lengths = [length for s in SCENARIOS for length in s.track.lengths]
    assert min(lengths) < 1.0
    assert max(lengths) > 2000.0
    assert sum(s.limits.min_separation == s.track.shortest_leg for s in SCENARIOS) >= 50
    assert sum(s.goal == s.start.swapped() for s in SCENARIOS) >= 70


@pytest.mark.parametrize("index", range(0, len(SCENARIOS), EVERY), ids=lambda k: f"scenario-{k}")
@pytest.mark.parametrize("method", [Exact(), Toppra()], ids=["exact", "toppra"])
def test_every_exact_and_toppra_schedule_verifies(method, index):
    scenario = SCENARIOS[index]
    schedule = make_schedule(scenario.route(), scenario.limits, method=method)
    certify(schedule)  # raises VerificationError, naming every failure, if one does not verify
    # neither falls back on these seeded scenarios (toppra may, flagged and verified, on others)
    assert schedule.fallback_reason is None


@pytest.fixture(scope="module")
def optimal():
    return Optimal(cache=SolverCache(maxsize=128))


@pytest.mark.parametrize("index", range(0, len(SCENARIOS), OPTIMAL_EVERY), ids=lambda k: f"scenario-{k}")
def test_the_optimal_schedule_verifies_and_is_no_slower_than_exact(optimal, index):
    scenario = SCENARIOS[index]
    route = scenario.route()
    schedule = certify(make_schedule(route, scenario.limits, method=optimal)).schedule
    # solved: the effort is fixed by iterations, not by the clock, so a fallback (a solver failure, or
    # one that did not come back within the time limit) on these seeded scenarios is a regression
    assert schedule.fallback_reason is None, schedule.notes
    assert schedule.duration <= Exact().schedule(route, scenario.limits).duration * (1 + 1e-9)
