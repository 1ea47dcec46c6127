"""A seeded random campaign over a wide range of scenarios: every schedule of every method verifies.

300 scenarios from :func:`trajgen.scenario.sampling.campaign_scenarios` (legs 0.5-5000 m,
independent limits, separations up to the shortest leg, swaps and random
goals): ``exact`` and ``toppra`` on every :data:`EVERY`-th, ``optimal`` (seconds
per solve) on every :data:`OPTIMAL_EVERY`-th. ``benchmarks/bench_campaign.py``
prints the same campaign's figures, every method on all 300.
"""

from __future__ import annotations

import pytest

from trajgen import METHODS, Optimal, SolverCache, certify, make_schedule
from trajgen.scenario.sampling import campaign_scenarios

SCENARIOS = campaign_scenarios(300, seed=9)
CHUNK = 10
#: ``exact`` and ``toppra`` are timed on the scenarios whose index is a multiple of this ...
EVERY = 10
#: ... and ``optimal`` on those whose index is a multiple of this.
OPTIMAL_EVERY = 60


@pytest.fixture(scope="module")
def methods():
    return [cls() if cls is not Optimal else Optimal(cache=SolverCache(maxsize=128)) for cls in METHODS]


def test_the_campaign_spans_the_whole_range():
    lengths = [length for s in SCENARIOS for length in s.track.lengths]
    assert min(lengths) < 1.0
    assert max(lengths) > 2000.0
    assert sum(s.limits.min_separation == s.track.shortest_leg for s in SCENARIOS) >= 50
    assert sum(s.goal == s.start.swapped() for s in SCENARIOS) >= 70


@pytest.mark.parametrize("chunk", range(len(SCENARIOS) // (CHUNK * EVERY)), ids=lambda k: f"chunk-{k}")
def test_every_schedule_of_every_method_verifies(methods, chunk, record_property):
    fallbacks = dict.fromkeys((m.name for m in methods), 0)
    for index in range(CHUNK * EVERY * chunk, CHUNK * EVERY * (chunk + 1), EVERY):
        scenario = SCENARIOS[index]
        route = scenario.plan()
        for method in methods:
            if method.name == "optimal" and index % OPTIMAL_EVERY:
                continue
            schedule = make_schedule(route, scenario.limits, method=method)
            certify(schedule)  # raises VerificationError, naming every failure, if one does not verify
            fallbacks[method.name] += schedule.fallback_reason is not None
    record_property("fallbacks", fallbacks)
    assert fallbacks["exact"] == 0
    assert fallbacks["toppra"] <= 2
    assert fallbacks["optimal"] <= 1  # flagged and verified; the campaign's count is in the benchmark
