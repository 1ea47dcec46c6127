"""The braking check and the safety guard on a track graph: sound against dense sampling of the tubes."""

from __future__ import annotations

import numpy as np
import pytest

from limits import Limits, VehicleLimits
from tests.support.graph_cases import CONVOY, verified_example
from trajgen.execution import BrakingCheck, PathState
from trajgen.execution.braking_check import ServiceBraking, emergency_position
from trajgen.execution.safety_guard import SafetyGuard
from trajgen.model.graph_paths import graph_paths
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.scenario import load_scenario

AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
EMERGENCY = (1.0, 1.0)


def _paths(name: str):
    scenario, verified = verified_example(name, "exact")
    track = scenario.track
    paths = tuple(GraphVehiclePath.from_path(p, track) for p in graph_paths(verified.schedule.route))
    return track, GraphMetric(track), paths


@pytest.mark.slow  # a sampled campaign over every example's plan
@pytest.mark.parametrize("name", ["h", "ring-with-spurs", "main-line-with-sidings"])
def test_what_the_braking_check_certifies_keeps_the_distance_at_every_sampled_instant(name):
    """Random states along both paths: a certified pair never comes closer than required when sampled."""
    track, metric, paths = _paths(name)
    graph_path_pair = graph_paths(verified_example(name, "exact")[1].schedule.route)
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
        least = _least_distance_of_places(track, graph_path_pair, states, states, steps=300, samples=3)
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


def _beyond(track, edge: int, s: float) -> list[tuple[int, float]]:
    """Every place ``s`` metres along ``edge`` can be, ``s`` possibly beyond the edge's ends.

    Past an end node the vehicle is on one of the node's edges (any: the track does not say which),
    as far from the node as it ran past it. Written from the track alone, not from the sweep.
    """
    length = track.length(edge)
    if 0.0 <= s <= length:
        return [(edge, s)]
    node, past = (track.ends(edge)[0], -s) if s < 0.0 else (track.ends(edge)[1], s - length)
    places = []
    for other in range(track.edge_count):
        u, v = track.ends(other)
        reach = min(past, track.length(other))
        if u == node:
            places.append((other, reach))
        if v == node:
            places.append((other, track.length(other) - reach))
    return places


def _places(track, path, p: float) -> list[tuple[int, float]]:
    """Where a vehicle whose path is ``path`` (a GraphPath) can be at travel ``p``."""
    if path.edges.size == 0:
        edge, s = path.home.edge, path.home.s
        return _beyond(track, edge, s - abs(p)) + _beyond(track, edge, s + abs(p))
    if 0.0 <= p <= path.length:
        edges, s = path.locate(p)
        return [(int(edges[0]), float(s[0]))]
    if p < 0.0:
        return _beyond(track, int(path.edges[0]), float(path.s_from[0] + path.directions[0] * p))
    return _beyond(track, int(path.edges[-1]), float(path.s_to[-1] + path.directions[-1] * (p - path.length)))


def _least_distance_of_places(track, graph_path_pair, commanded, measured, steps: int, samples: int) -> float:
    """The least track distance between the places the two braking vehicles can be (a dense sample).

    At ``steps`` instants and ``samples`` travel values across each vehicle's range there.
    """
    trajectories = [ServiceBraking(AGV).trajectory(state) for state in commanded]
    horizon = max(
        *(t.duration for t in trajectories), *(abs(m.v) / e for m, e in zip(measured, EMERGENCY, strict=True))
    )
    least = np.inf
    for t in np.linspace(0.0, horizon, steps):
        places = []
        for v in (0, 1):
            trajectory = trajectories[v]
            upper = trajectory.at_time(min(t, trajectory.duration))[0][0]
            lower = emergency_position(measured[v], EMERGENCY[v], t)
            places.append(
                [q for p in np.linspace(lower, upper, samples) for q in _places(track, graph_path_pair[v], p)]
            )
        first = np.array([(e, s) for e, s in places[0] for _ in places[1]])
        second = np.array([(e, s) for _ in places[0] for e, s in places[1]])
        apart = track.distances(first[:, 0].astype(int), first[:, 1], second[:, 0].astype(int), second[:, 1])
        least = min(least, float(apart.min()))
    return least


def test_a_stop_that_runs_past_a_goal_at_a_track_node_is_not_certified(tmp_path):
    """A vehicle 1 cm before its goal at a track node at 0.5 m/s runs past it: not certified.

    agv1 parks at node J exactly the separation behind agv2 (at e:1.5); its emergency stop runs
    11.5 cm past J onto e, 1.385 m from agv2. The sweep stops at J (the end of agv1's edge w);
    what runs past J is the path's overrun, taken off the distance. Arriving at rest, the same
    plan is certified.
    """
    text = CONVOY.replace('goal = "e:5.5"', 'goal = "J"').replace('goal = "e:7"', 'goal = "e:1.5"')
    scenario_file = tmp_path / "convoy_at_node.toml"
    scenario_file.write_text(text)
    route = load_scenario(scenario_file).route()
    track = route.track
    graph_path_pair = graph_paths(route)
    paths = tuple(GraphVehiclePath.from_path(p, track) for p in graph_path_pair)
    check = BrakingCheck((AGV, AGV), EMERGENCY, GraphMetric(track))
    ends = (PathState(paths[0].length, 0.0, 0.0), PathState(paths[1].length, 0.0, 0.0))
    required = 1.5 - 1e-6
    assert paths[0].overrun(paths[0].length, paths[0].length + 0.115) == pytest.approx(0.115)
    running_on = (PathState(paths[0].length - 0.01, 0.5, 0.0), ends[1])
    truth = _least_distance_of_places(track, graph_path_pair, ends, running_on, steps=400, samples=5)
    assert truth == pytest.approx(1.385, abs=1e-3)
    assert not check.clearance(paths, ends, running_on, required)
    assert check.clearance(paths, ends, ends, required)


def test_a_vehicle_that_should_stay_put_and_moves_is_not_certified_by_its_home_point():
    """A path with no segments sweeps its home point; travel away from it is overrun, any way."""
    _, metric, _ = _paths("h")
    still = GraphVehiclePath((), (), (), (), (), (0.0,), 0.0, (), (0, 3.0), metric.lengths)
    assert still.sweep(-0.5, 0.25) == ((0, 3.0, 3.0),)
    assert still.overrun(-0.5, 0.25) == 0.5
    assert still.overrun(0.0, 0.0) == 0.0
