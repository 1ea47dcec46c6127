"""The coordination diagram, the frontier, the stopping distance and the braking rule plans obey.

Closed-form cases on the swap of ``examples/swap.toml`` and on the H; agreement of the closed-form
stopping distance with Ruckig's braking, and of a track graph's conflicts with the tests' own track
distance; every plan of the table of cases (:mod:`tests.support.cases`) behind its frontiers;
seeded property tests of the frontier.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from ruckig import ControlInterface, InputParameter, Ruckig, Trajectory

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.cases import CASES, case
from tests.support.graph_cases import EXAMPLES
from tests.support.graph_rows import ScenarioFile
from tests.support.helpers import conf, execution_plan
from topology import YGraph, plan
from trajgen import Exact, Optimal, certify, load_scenario, make_schedule, verify
from trajgen.model.coordination import (
    CoordinationDiagram,
    earliest_rest,
    schedule_paths,
    schedule_times,
    stopping_distance,
    stopping_distances,
)
from trajgen.scenario.sampling import random_scenarios, random_track
from trajgen.verification.braking_rule import BRAKING_RULE_TOLERANCE, braking_rule_failures

SWAP = REPO / "examples" / "swap.toml"
CROSSING = REPO / "examples" / "crossing.toml"
AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)


def ruckig_stop(limits: VehicleLimits, velocity: float, acceleration: float) -> float:
    """Where Ruckig's time-optimal braking (velocity control to rest) gets farthest from 0."""
    generator, inp, trajectory = Ruckig(1), InputParameter(1), Trajectory(1)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [velocity], [acceleration]
    inp.target_velocity, inp.target_acceleration = [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration = [limits.max_velocity], [limits.max_acceleration]
    inp.max_jerk = [limits.max_jerk]
    generator.calculate(inp, trajectory)
    return trajectory.position_extrema[0].max


# -- the stopping distance ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("velocity", "acceleration", "expected"),
    [
        (1.0, 0.0, 1.0 / (2 * 0.5) + 1.0 * 0.5 / (2 * 1.0)),  # reaches A: v^2 / 2A + v A / 2J
        (0.1, 0.0, 0.1 * math.sqrt(0.1 / 1.0)),  # never reaches A: v sqrt(v / J)
        (0.0, 0.0, 0.0),
        (0.0, -0.3, 0.0),
    ],
    ids=["reaches-the-limit", "below-the-limit", "at-rest", "at-rest-braking"],
)
def test_the_stopping_distance_in_closed_form(velocity, acceleration, expected):
    assert stopping_distance(velocity, acceleration, AGV) == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_without_a_jerk_limit_the_stop_is_v_squared_over_2a():
    assert stopping_distance(1.0, 0.4, AGV, jerk_limited=False) == pytest.approx(1.0)


@settings(max_examples=200)
@given(
    top=st.tuples(st.floats(0.1, 3.0), st.floats(0.1, 2.0), st.floats(0.1, 5.0)),
    fraction=st.floats(0.0, 1.0),
    acceleration=st.floats(-1.0, 1.0),
)
def test_the_stopping_distance_is_where_ruckig_comes_to_rest(top, fraction, acceleration):
    limits = VehicleLimits(*top)
    velocity, a = fraction * limits.max_velocity, acceleration * limits.max_acceleration
    exact = ruckig_stop(limits, velocity, a)
    assert stopping_distance(velocity, a, limits) == pytest.approx(exact, abs=1e-7)
    vector = stopping_distances(np.array([velocity, velocity]), np.array([a, a]), limits)
    assert vector == pytest.approx([exact, exact], abs=1e-7)


def test_the_earliest_rest_point_counts_only_forward_speed():
    assert earliest_rest(3.0, 1.0, 2.0) == pytest.approx(3.25)
    assert earliest_rest(3.0, -1.0, 2.0) == 3.0


# -- the coordination diagram -------------------------------------------------------------------


@pytest.fixture(scope="module")
def swap_plan():
    scenario = load_scenario(SWAP)
    return scenario, Exact().schedule(scenario.route(), scenario.limits)


def test_the_swap_has_two_conflicts_at_the_junction_each_led_by_the_vehicle_the_plan_sends_first(swap_plan):
    """Legs of 10 m, d = 1.5 m: agv2 dodges into C first, then agv1 passes to B, then agv2 to A."""
    scenario, schedule = swap_plan
    paths, times, _ = schedule_paths(schedule)
    d = scenario.limits.min_separation
    diagram = CoordinationDiagram(paths, d, schedule, times)
    assert [round(path.length, 9) for path in paths] == [20.0, 40.0]
    first, second = diagram.conflicts
    # agv2 leaves B through the junction (its travel 10) first: agv1 within d of the junction, or on B
    # (its travel beyond 10) while agv2 is still there, is in conflict with it
    assert first.leader == 1
    assert first.low == pytest.approx((10.0 - d, 0.0))
    assert first.high == pytest.approx((20.0, 10.0 + d))
    # then agv1 crosses (its travel 10) while agv2 waits at the end of C (its travel 20), before agv2
    # comes back out (its travel 30) onto A, which agv1 has left
    assert second.leader == 0
    assert second.low == pytest.approx((0.0, 30.0 - d))
    assert second.high == pytest.approx((10.0 + d, 40.0))


def test_the_frontier_in_closed_form_on_the_swap(swap_plan):
    _scenario, schedule = swap_plan
    paths, times, _ = schedule_paths(schedule)
    diagram = CoordinationDiagram(paths, 1.5, schedule, times)
    # agv1 follows at the first crossing: until agv2 can no longer stop short of the junction's
    # surroundings, agv1 stops 1.5 m before the junction
    assert diagram.frontier(0, 0.0) == pytest.approx(8.5)
    assert diagram.frontier(0, 10.0) == pytest.approx(8.5)
    # agv2's earliest rest 0.5 m into C: agv1 may come 0.5 m closer
    assert diagram.frontier(0, 10.5) == pytest.approx(9.0)
    assert diagram.frontier(0, 11.5) == math.inf  # agv2 cannot rest within 1.5 m of the junction
    # agv2 follows at the second crossing: it waits in C until agv1 is past
    assert diagram.frontier(1, 5.0) == pytest.approx(28.5)
    assert diagram.frontier(1, 11.0) == pytest.approx(29.5)
    assert diagram.frontier(1, 12.0) == math.inf


# -- the diagram of every plan of the table of cases ---------------------------------------------

#: The table's cases by name (:mod:`tests.support.cases`).
TABLE = [c.name for c in CASES]


@functools.cache
def _diagram(name: str, method: str):
    """A case's plan, its diagram, and each vehicle's travel on a fine grid of its time."""
    if name in TABLE:
        verified = case(name).verified(method)
    else:  # an example beyond the table
        from tests.support.graph_cases import verified_example

        verified = verified_example(name, method)[1]
    schedule = verified.schedule
    paths, times, _ = schedule_paths(schedule)
    diagram = CoordinationDiagram(paths, schedule.limits.min_separation, schedule, times)
    # between two of the schedule's times no vehicle turns: travel is the sum of the axis' moves
    grid = np.union1d(times, np.linspace(0.0, schedule.duration, 2001))
    axis = schedule.state(grid).axis
    travel = np.concatenate([np.zeros((2, 1)), np.cumsum(np.abs(np.diff(axis, axis=1)), axis=1)], axis=1)
    return schedule, diagram, grid, travel


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", [*TABLE, "main-line-with-sidings"])
def test_the_plan_stays_behind_each_followers_frontier_and_passes_each_conflict_on_its_leaders_side(
    name, method
):
    _, diagram, grid, travel = _diagram(name, method)
    assert diagram.conflicts  # each case has vehicles that must pass one another
    for conflict in diagram.conflicts:
        leader, follower = conflict.leader, conflict.follower
        # the leader at rest where it is now: the follower may rest anywhere up to its frontier
        bounds = np.array([conflict.bound(p) for p in travel[leader]])
        worst = int(np.argmax(travel[follower] - bounds))
        assert travel[follower, worst] <= bounds[worst] + 1e-6, (leader, grid[worst])
    for follower in (0, 1):
        frontiers = diagram.frontiers(follower, travel[1 - follower])
        assert np.all(travel[follower] <= frontiers + 1e-6)


def _frontiers_by_every_edge(diagram, follower: int, earliest: np.ndarray) -> np.ndarray:
    """The frontiers from every polygon edge at once: its vertices right of ``e``, its crossings of ``e``."""
    best = np.full(earliest.shape, math.inf)
    for conflict in diagram.conflicts:
        if conflict.follower != follower:
            continue
        leader = conflict.leader
        for polygon in conflict.polygons:
            reach = max(a[leader] for a in polygon)
            for k, a in enumerate(polygon):
                b = polygon[(k + 1) % len(polygon)]
                alive = reach > earliest + 1e-9
                vertex = np.where(alive & (a[leader] >= earliest), a[1 - leader], math.inf)
                crossing = alive & ((a[leader] - earliest) * (b[leader] - earliest) < 0.0)
                with np.errstate(divide="ignore", invalid="ignore"):
                    w = (earliest - a[leader]) / (b[leader] - a[leader])
                    edge = np.where(crossing, a[1 - leader] + w * (b[1 - leader] - a[1 - leader]), math.inf)
                best = np.minimum(best, np.minimum(vertex, edge))
    return best


@pytest.mark.parametrize("name", [*TABLE, "main-line-with-sidings"])
def test_the_frontiers_read_off_each_polygons_lower_chain_agree_with_every_edge_of_it(name):
    """Agreement of two computations, at random earliest rests and at every vertex of every polygon."""
    _, diagram, _, travel = _diagram(name, "exact")
    rng = np.random.default_rng(3)
    for follower in (0, 1):
        leader = 1 - follower
        vertices = [
            a[c.leader] for c in diagram.conflicts if c.follower == follower for p in c.polygons for a in p
        ]
        earliest = np.concatenate(
            [rng.uniform(-1.0, travel[leader, -1] + 1.0, 400), np.array(vertices), np.array(vertices) + 1e-7]
        )
        chain = diagram.frontiers(follower, earliest)
        every = _frontiers_by_every_edge(diagram, follower, earliest)
        assert np.array_equal(np.isinf(chain), np.isinf(every))
        finite = np.isfinite(every)
        np.testing.assert_allclose(chain[finite], every[finite], rtol=0.0, atol=1e-9)


GRAPH_EXAMPLES = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]


@functools.cache
def _graph_diagram(name: str):
    from tests.support.graph_cases import verified_example

    scenario, verified = verified_example(name, "exact")
    schedule = verified.schedule
    diagram = CoordinationDiagram(
        schedule.paths, scenario.limits.min_separation, schedule, schedule_times(schedule)
    )
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


@pytest.mark.parametrize("name", GRAPH_EXAMPLES)
def test_a_graphs_conflicts_are_exactly_where_the_vehicles_would_be_too_close(name):
    """Agreement on a grid of the travel plane with the tests' own track distance (scenario file alone)."""
    scenario, schedule, diagram = _graph_diagram(name)
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


def test_the_hs_conflicts_are_led_in_the_routes_order():
    """agv1 goes up c (15.5 m), agv2 passes from D to A, agv1 comes back down to D."""
    _, schedule, diagram = _graph_diagram("h")
    first_move = schedule.paths[0].cusps[0]
    assert first_move == pytest.approx(15.5)
    assert len(diagram.conflicts) == 2
    up, down = sorted(diagram.conflicts, key=lambda c: c.low[0])
    assert up.leader == 0  # agv1's way up against agv2's pass: agv1 first
    assert up.high[0] <= first_move + 1e-9
    assert down.leader == 1  # agv1's way down against agv2's pass: agv2 first
    assert down.low[0] >= first_move - 1e-9


@settings(max_examples=100)
@given(st.lists(st.floats(0.0, 45.0), min_size=2, max_size=20))
def test_a_frontier_never_moves_back_as_the_leaders_earliest_rest_moves_on(earliest):
    scenario = load_scenario(SWAP)
    schedule = Exact().schedule(scenario.route(), scenario.limits)
    paths, times, _ = schedule_paths(schedule)
    diagram = CoordinationDiagram(paths, 1.5, schedule, times)
    for follower in (0, 1):
        values = [diagram.frontier(follower, e) for e in sorted(earliest)]
        assert all(b >= a for a, b in itertools.pairwise(values))
        vector = diagram.frontiers(follower, np.array(sorted(earliest)))
        assert vector.tolist() == pytest.approx(values)


def test_a_plan_without_clearance_runs_between_two_conflicts_that_touch_at_a_point():
    """Separation = the shortest leg: agv2 dodges to the very end of C, exactly d from the junction.

    The two conflicts (agv1 crossing while agv2 enters C, and while agv2 leaves it) meet at a single
    point, where the distance is exactly d: two conflicts, each with its own leader, not one.
    """
    track = YGraph({"A": 10.0, "B": 10.0, "C": 1.5})
    route = plan(track, conf("A:10", "B:10"), conf("B:10", "A:10"), min_separation=1.5)
    schedule = Exact().schedule(route, Limits((AGV, AGV), 1.5))
    paths, times, _ = schedule_paths(schedule)
    diagram = CoordinationDiagram(paths, 1.5, schedule, times)
    leaders = sorted(c.leader for c in diagram.conflicts)
    assert leaders == [0, 1]


# -- the braking rule --------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("method", ["exact", "toppra", "optimal"])
@pytest.mark.parametrize("name", ["swap", "crossing"])
def test_every_methods_plan_for_execution_obeys_the_braking_rule(name, method):
    _, verified = execution_plan(name, method)
    assert verified.schedule.fallback_reason is None, verified.schedule.notes
    assert braking_rule_failures(verified.schedule) == []


@pytest.fixture(scope="module")
def optimal_swap():
    scenario = load_scenario(SWAP)
    return scenario, Optimal(braking_rule=True).schedule(scenario.route(), scenario.limits)


@pytest.mark.slow
def test_the_rule_binds_the_optimal_swap_two_centimetres_more_is_refused(optimal_swap):
    """The optimal swap brakes into its frontiers as late as the rule allows (within 1 cm)."""
    _, schedule = optimal_swap
    assert schedule.fallback_reason is None, schedule.notes
    assert braking_rule_failures(schedule) == []
    failures = braking_rule_failures(schedule, separation=1.52)
    assert sorted({f.vehicle for f in failures}) == [0, 1]
    assert all(f.excess > BRAKING_RULE_TOLERANCE for f in failures)
    assert max(f.excess for f in failures) < 0.02  # it is 1 cm or less from the rule, not more


@pytest.mark.slow
def test_verify_refuses_a_plan_that_breaks_the_rule_naming_when_and_where(optimal_swap):
    from trajgen.errors import VerificationError
    from trajgen.model.schedule import Schedule

    scenario = load_scenario(SWAP)
    # the time-optimal swap without the rule in the NLP, claimed to be a plan for execution:
    # agv2 follows agv1 through the junction closer than its service braking can keep
    unruled = Optimal().schedule(scenario.route(), scenario.limits)
    assert unruled.fallback_reason is None
    assert verify(unruled).passed  # a timed profile: safe as long as it is followed to the letter
    claimed = dataclasses.replace(unruled, method=Optimal(braking_rule=True))
    frontier = r"vehicle [12] cannot stop short of its frontier at t=\d+\.\d+ s"
    with pytest.raises(VerificationError, match=frontier):
        certify(claimed)
    # and the optimal plan with the rule, claimed for a 5 cm larger separation, is refused by name
    _, schedule = optimal_swap
    relabelled = Schedule(
        schedule.route, Limits(schedule.limits.vehicles, 1.55), schedule.method, schedule.sections, True
    )
    with pytest.raises(VerificationError, match=r"vehicle [12] cannot stop short of its frontier at t=\d"):
        certify(relabelled)


#: Campaign scenario 20 (seed 9): 3.8 km, 367 m and a shortest leg of 111 m that is the separation; a
#: slow, soft vehicle (0.23 m/s, 0.079 m/s³) waits for hours while the other drives kilometres.
LONG_WAIT = (
    (366.97565449866704, 111.01040734381074, 3817.274258034254),
    ("C:2714", "C:3529.01"),
    Limits(
        (
            VehicleLimits(
                max_velocity=1.0314118746610161, max_acceleration=0.23799801114673097, max_jerk=3.4597
            ),
            VehicleLimits(
                max_velocity=0.22880728599774738, max_acceleration=0.3091416882898401, max_jerk=0.079
            ),
        ),
        111.01040734381074,
    ),
)


def test_the_rule_check_costs_about_the_same_on_a_schedule_a_hundred_times_longer(monkeypatch):
    """Long rests and cruises are certified at once: the cost grows with the pieces, not the duration.

    The check halves a step where the margin is thinner than what the follower's stop point can
    gain over it. Bounded from the limits alone, a vehicle waiting for hours could gain metres: the
    kilometre version of campaign scenario 20 (39,870 s) took 786,000 margins (12 s), 24 times the
    metre version's. Resting or cruising through a step, a vehicle gains its speed times the step.
    """
    counted = []
    frontiers = CoordinationDiagram.frontiers

    def counting(self, follower, earliest):
        counted.append(np.size(earliest))
        return frontiers(self, follower, earliest)

    monkeypatch.setattr(CoordinationDiagram, "frontiers", counting)
    legs, (first, second), limits = LONG_WAIT
    costs, durations = [], []
    for scale in (0.01, 1.0):
        track = YGraph(dict(zip("ABC", (length * scale for length in legs), strict=True)))
        places = [f"{p[0]}:{float(p[2:]) * scale:.6f}" for p in (first, second)]
        separation = limits.min_separation * scale
        route = plan(track, conf(*places), conf(*reversed(places)), min_separation=separation)
        schedule = Exact().schedule(route, Limits(limits.vehicles, separation))
        counted.clear()
        assert braking_rule_failures(schedule) == []
        costs.append(sum(counted))
        durations.append(schedule.duration)
    assert durations[1] > 90.0 * durations[0]
    assert costs[1] < 5.0 * costs[0], costs
    assert costs[1] < 30_000, costs


@pytest.mark.parametrize("legs", [3, 4, 6, 8])
def test_a_junctions_path_through_its_places_is_where_its_schedule_is_at_every_instant(legs):
    """Agreement of two computations on seeded random junctions: a path and the schedule's state.

    The path is built from the places at the plan's instants; the state is read between them.
    """
    rng = random.Random(f"paths-{legs}")
    track = random_track(rng, leg_count=legs, lengths=(2.0, 20.0))
    for scenario in random_scenarios(6, seed=legs, track=track, limits=Limits((AGV, AGV), 1.5)):
        for method in ("exact", "toppra"):
            schedule = make_schedule(scenario.route(), scenario.limits, method=method)
            paths, times, travel = schedule_paths(schedule)
            for v, path in enumerate(paths):
                assert path.length == pytest.approx(travel[v, -1], abs=1e-9)
            # halfway between the instants, where no vehicle turns: travel from the axis, place from the path
            middle = 0.5 * (times[:-1] + times[1:])
            state = schedule.state(middle)
            moved = np.abs(state.axis - schedule.state(times[:-1]).axis)
            for v, path in enumerate(paths):
                edge, s = path.locate(travel[v, :-1] + moved[v])
                apart = schedule.track.distances(edge, s, state.edge[v], state.s[v])
                assert np.max(apart) <= 1e-9, (scenario.start, scenario.goal, method, v)


def test_a_path_through_places_on_edges_that_share_no_node_is_refused():
    from topology import TrackGraph
    from trajgen.model.graph_paths import path_through

    track = TrackGraph.from_edges({"a": ("A", "J", 5.0), "b": ("J", "K", 5.0), "c": ("K", "C", 5.0)})
    path = path_through(track, [0, 1, 2], [1.0, 2.5, 4.0])
    assert path.length == pytest.approx(4.0 + 5.0 + 4.0)
    assert path.edges.tolist() == [0, 1, 2]
    with pytest.raises(
        ValueError, match=r"places on edges 0 and 2 share no node: expected a path along the track"
    ):
        path_through(track, [0, 2], [1.0, 4.0])
