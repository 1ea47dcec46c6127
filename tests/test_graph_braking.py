"""The braking check and the safety guard on a track graph: sound against dense sampling of the tubes."""

from __future__ import annotations

import numpy as np
import pytest

from limits import Limits, VehicleLimits
from tests.support.graph_cases import verified_example
from trajgen.execution import BrakingCheck, PathState
from trajgen.execution.braking_check import ServiceBraking, emergency_position
from trajgen.execution.safety_guard import SafetyGuard
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath

AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
EMERGENCY = (1.0, 1.0)


def _paths(name: str):
    scenario, verified = verified_example(name, "exact")
    track = scenario.track
    paths = tuple(GraphVehiclePath.from_path(p, track) for p in graph_paths(verified.schedule.route))
    return track, GraphMetric(track), paths


def _sampled_least_distance(metric, paths, commanded, measured, steps: int = 4000) -> float:
    """The least track distance between the two braking tubes at ``steps`` instants (a dense sample)."""
    trajectories = [ServiceBraking(AGV).trajectory(state) for state in commanded]
    horizon = max(
        *(t.duration for t in trajectories), *(abs(m.v) / e for m, e in zip(measured, EMERGENCY, strict=True))
    )
    least = np.inf
    for t in np.linspace(0.0, horizon, steps):
        sets = []
        for v in (0, 1):
            trajectory = trajectories[v]
            upper = trajectory.at_time(min(t, trajectory.duration))[0][0]
            lower = emergency_position(measured[v], EMERGENCY[v], t)
            sets.append(paths[v].sweep(min(lower, upper), max(lower, upper)))
        least = min(least, metric.set_distance(sets[0], sets[1]))
    return least


@pytest.mark.parametrize("name", ["h", "ring-with-spurs", "main-line-with-sidings"])
def test_what_the_braking_check_certifies_keeps_the_distance_at_every_sampled_instant(name):
    """Random states along both paths: a certified pair never comes closer than required when sampled."""
    _, metric, paths = _paths(name)
    check = BrakingCheck((AGV, AGV), EMERGENCY, metric)
    rng = np.random.default_rng(5)
    outcomes = []
    for _ in range(60):
        states = []
        for path in paths:
            p = float(rng.uniform(0.0, path.length)) if path.edges else 0.0
            v = float(rng.uniform(0.0, AGV.max_velocity)) if path.edges else 0.0
            states.append(PathState(p, v, 0.0))
        required = 1.5
        certified = check.clearance(paths, tuple(states), tuple(states), required)
        least = _sampled_least_distance(metric, paths, states, states)
        if certified:
            assert least >= required - 1e-9, (name, states, least)
        outcomes.append((certified, least >= required))
    # neither always yes nor always no, and rarely pessimistic where the sample has room
    assert any(c for c, _ in outcomes)
    assert not all(c for c, _ in outcomes)
    roomy = [c for c, room in outcomes if room]
    assert sum(roomy) >= 0.8 * len(roomy)


def test_the_guard_takes_a_track_graph_and_measures_its_track_distance():
    track, metric, paths = _paths("h")
    limits = Limits((AGV, AGV), 1.5)
    guard = SafetyGuard(limits, track)

    class Measured:
        def __init__(self, place):
            self.leg, self.s = place

    # the vehicles at their starts: the guard's required distance is the separation, or what they have
    first, second = paths[0].locate(0.0), paths[1].locate(0.0)
    apart = metric.distance(*first, *second)
    assert guard.required((Measured(first), Measured(second))) == pytest.approx(
        min(1.5 - 1e-6, apart - 1e-12)
    )
    at_rest = (PathState(0.0, 0.0, 0.0), PathState(0.0, 0.0, 0.0))
    assert guard.certifies(paths, at_rest, at_rest, guard.required((Measured(first), Measured(second))))
