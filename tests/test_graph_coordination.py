"""The coordination diagram of a plan on a track graph: its conflicts, their leaders, the frontiers."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from tests.conftest import REPO
from tests.support.graph_cases import verified_example
from tests.support.graph_rows import ScenarioFile
from trajgen.model.coordination import CoordinationDiagram, schedule_times

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


@functools.cache
def _diagram(name: str, method: str):
    scenario, verified = verified_example(name, method)
    schedule = verified.schedule
    times = schedule_times(schedule)
    diagram = CoordinationDiagram(schedule.paths, scenario.limits.min_separation, schedule, times)
    return scenario, schedule, diagram


def _inside(polygon, x: np.ndarray, y: np.ndarray, margin: float) -> np.ndarray:
    """Points inside a convex polygon or within ``margin`` (metres) of it."""
    inside = np.ones(x.shape, dtype=bool)
    count = len(polygon)
    area = sum(
        polygon[k][0] * polygon[(k + 1) % count][1] - polygon[(k + 1) % count][0] * polygon[k][1]
        for k in range(count)
    )
    orientation = 1.0 if area > 0 else -1.0
    for k in range(count):
        (x0, y0), (x1, y1) = polygon[k], polygon[(k + 1) % count]
        length = np.hypot(x1 - x0, y1 - y0)
        if length == 0.0:
            continue
        cross = orientation * ((x1 - x0) * (y - y0) - (y1 - y0) * (x - x0)) / length
        inside &= cross >= -margin
    return inside


@pytest.mark.parametrize("name", FEASIBLE)
def test_the_conflicts_are_exactly_where_the_vehicles_would_be_too_close(name):
    """Agreement on a grid of the travel plane with the tests' own track distance (scenario file alone)."""
    scenario, schedule, diagram = _diagram(name, "exact")
    own = ScenarioFile(EXAMPLES / f"{name}.toml")
    names = [edge.name for edge in scenario.track.edges]
    p1 = np.linspace(0.0, schedule.paths[0].length, 121)
    p2 = np.linspace(0.0, schedule.paths[1].length, 121)
    x, y = (a.ravel() for a in np.meshgrid(p1, p2))
    places = [schedule.paths[v].locate(p) for v, p in enumerate((x, y))]
    distance = np.array(
        [
            own.distance((names[places[0][0][k]], places[0][1][k]), (names[places[1][0][k]], places[1][1][k]))
            for k in range(x.size)
        ]
    )
    separation = scenario.limits.min_separation
    inside = np.zeros(x.size, dtype=bool)
    for conflict in diagram.conflicts:
        for polygon in conflict.polygons:
            inside |= _inside(polygon, x, y, 1e-9)
    clear = np.abs(distance - separation) > 2e-3  # off the boundary, where sampling decides nothing
    assert np.all(inside[clear] == (distance[clear] < separation))
    assert inside.any()


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", FEASIBLE)
def test_the_plan_stays_behind_each_followers_frontier_and_passes_each_conflict_on_its_leaders_side(
    name, method
):
    _, schedule, diagram = _diagram(name, method)
    assert diagram.conflicts  # each example has vehicles that must pass one another
    t = np.linspace(0.0, schedule.duration, 2001)
    travel = schedule.travel(t)[:, 0]
    for conflict in diagram.conflicts:
        leader, follower = conflict.leader, conflict.follower
        for k in range(t.size):
            # the leader at rest where it is now: the follower may rest anywhere up to its frontier
            assert travel[follower, k] <= conflict.bound(travel[leader, k]) + 1e-6, (conflict.leader, t[k])
        # the leader is through before the follower enters: when the follower reaches the conflict's
        # far end, the leader has left every part of it
    for follower in (0, 1):
        frontiers = diagram.frontiers(follower, travel[1 - follower])
        assert np.all(travel[follower] <= frontiers + 1e-6)


def test_the_hs_conflicts_are_led_in_the_routes_order():
    """agv1 goes up c (15.5 m), agv2 passes from D to A, agv1 comes back down to D."""
    _, schedule, diagram = _diagram("h", "exact")
    first_move = schedule.paths[0].cusps[0]
    assert first_move == pytest.approx(15.5)
    assert len(diagram.conflicts) == 2
    up, down = sorted(diagram.conflicts, key=lambda c: c.low[0])
    assert up.leader == 0  # agv1's way up against agv2's pass: agv1 first
    assert up.high[0] <= first_move + 1e-9
    assert down.leader == 1  # agv1's way down against agv2's pass: agv2 first
    assert down.low[0] >= first_move - 1e-9
