"""The online executor on a track graph: plays the plan, keeps its order, lets time stretch, re-plans."""

from __future__ import annotations

import functools
import json
import math
import random

import numpy as np
import pytest

from limits import Limits, VehicleLimits
from tests.support.graph_cases import EXAMPLES
from tests.support.helpers import stop_bound
from topology import EdgePoint, TrackGraph
from trajgen.cli import main
from trajgen.errors import InputError
from trajgen.execution import Executor, VehicleState, execution_margin, schedule_for_execution
from trajgen.execution.faults import FaultError
from trajgen.execution.plant import GraphBody, GraphShape
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.execution.tracks import GraphTrack
from trajgen.scenario import GraphScenario, load_scenario
from trajgen.scenario.graph_sampling import graph_campaign_faults, graph_online_campaign

NAMES = ["h", "passing-loop", "main-line-with-sidings", "ring-with-spurs"]


@functools.cache
def plan(name: str, method: str):
    """The example ``name``'s scenario and its verified plan for execution by ``method``, once."""
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    return scenario, schedule_for_execution(scenario, method=method)


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", NAMES)
def test_an_undisturbed_run_on_a_graph_plays_its_plan_and_never_brakes(name, method):
    scenario, verified = plan(name, method)
    result, _ = simulate(scenario, verified=verified)
    assert result.reached_goal
    assert abs(result.makespan_s - result.planned_s) <= 0.01 * result.planned_s + 0.02, result.summary()
    assert result.violations == 0
    assert result.holds == 0
    assert result.emergency_brakes == 0
    assert [e.kind for e in result.events] == ["done"], result.events
    # the conflicts keep the separation and the margin; the plan keeps a second margin of clearance
    assert result.certified_separation_m >= scenario.limits.min_separation + result.position_margin - 1e-6


@pytest.mark.slow  # a stop at every moment: a campaign, as on a junction
@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", ["h", "passing-loop"])
def test_a_stop_at_any_moment_on_the_h_and_the_passing_loop_costs_at_most_its_bound(name, method):
    """Seeded stops of either vehicle, anywhere in the run, 0.5 to 10 s: the issue's bound, 0 violations."""
    scenario, verified = plan(name, method)
    rng = random.Random(f"{name}-{method}")
    for _ in range(6):
        vehicle = rng.choice(scenario.names)
        spec = (
            f"stop:{vehicle}@{rng.uniform(0.0, verified.schedule.duration):.2f}+{rng.uniform(0.5, 10.0):.2f}"
        )
        faults = parse_faults(scenario, [spec])
        result, _ = simulate(scenario, faults, verified=verified)
        assert result.reached_goal, spec
        assert result.violations == 0, spec
        assert result.emergency_brakes == 0, spec
        assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value), (
            spec,
            result.summary(),
        )


@pytest.mark.parametrize(
    ("name", "method", "spec"),
    [
        # agv1 waits at its frontier for agv2 to clear J2; a jump back sets its drive closing the gap
        ("passing-loop", "exact", "jump:agv1@22.4=-0.04"),
        ("ring-with-spurs", "exact", "jump:agv1@32.07=-0.04"),
        # agv1 stops while agv2, on the plan's clock, drives a toppra plan at its frontier
        ("h", "toppra", "stop:agv1@10+5"),
    ],
    ids=["jump-while-waiting-loop", "jump-while-waiting-ring", "toppra-follower-at-its-frontier"],
)
def test_the_runs_that_overshot_a_frontier_and_deadlocked_now_reach_the_goal(name, method, spec):
    """Each ran past its frontier into the conflict and both waited for ever (holds, no goal)."""
    scenario, verified = plan(name, method)
    faults = parse_faults(scenario, [spec])
    result, _ = simulate(scenario, faults, verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    assert result.emergency_brakes == 0
    if faults[0].kind.value == "stop":
        assert result.makespan_s - result.planned_s <= stop_bound(scenario, faults[0].value)


@pytest.mark.parametrize(
    "name",
    ["h", pytest.param("main-line-with-sidings", marks=pytest.mark.slow)],  # the H in the fast set
)
def test_slowdowns_lags_and_jumps_on_a_graph_keep_the_separation_and_reach_the_goal(name):
    scenario, verified = plan(name, "exact")
    margin = execution_margin(scenario, 0.05)
    rng = random.Random(name)
    for _ in range(6):
        vehicle = rng.choice(scenario.names)
        at = rng.uniform(0.0, verified.schedule.duration)
        spec = rng.choice(
            [
                f"slow:{vehicle}@{at:.2f}+{rng.uniform(1.0, 8.0):.2f}=0.3",
                f"lag:{vehicle}@{at:.2f}=150",
                f"jump:{vehicle}@{at:.2f}={rng.choice([-1, 1]) * margin * 0.8:.4f}",
            ]
        )
        result, _ = simulate(scenario, parse_faults(scenario, [spec]), verified=verified)
        assert result.reached_goal, spec
        assert result.violations == 0, spec
        assert result.emergency_brakes == 0, spec


@pytest.mark.parametrize(
    "spec",
    ["goal:agv1@10=C", "goal:agv2@5=b:3", "goal:agv1@15=J2", "goal:agv1@12=e:6"],
)
def test_a_new_goal_on_a_graph_stops_both_replans_and_reaches_it(spec):
    """The vehicles stop, the exact planner plans from where they stand, and the new goal is reached.

    The re-planned paths continue each vehicle's own axis, also where it stands at a node and leaves
    on another edge: after the re-plan no vehicle is off its setpoints.
    """
    scenario, verified = plan("h", "toppra")
    faults = parse_faults(scenario, [spec])
    final = []

    def observe(executor, measured, command):
        final[:] = [measured, executor.goal]

    result, _ = simulate(scenario, faults, verified=verified, observer=observe)
    assert result.reached_goal, result.summary()
    assert result.replans == 1
    assert result.violations == 0
    assert result.emergency_brakes == 0
    kinds = [e.kind for e in result.events]
    assert "replan" in kinds
    after = result.events[kinds.index("replan") :]
    assert not any("off its setpoints" in e.detail for e in after), result.events
    measured, goal = final
    track = scenario.track
    wanted = track.point(faults[0].goal)
    assert goal[faults[0].vehicle] == wanted
    for state, point in zip(measured, goal, strict=True):
        assert track.distance(EdgePoint(state.leg, state.s), point) <= 0.05


def test_a_goal_too_close_to_the_other_vehicles_is_refused_and_the_run_goes_on():
    scenario, verified = plan("h", "exact")
    result, _ = simulate(scenario, parse_faults(scenario, ["goal:agv1@8=A"]), verified=verified)
    assert result.reached_goal
    assert result.replans == 0
    assert result.rejected_goals == 1
    refused = [e.detail for e in result.events if e.kind == "goal-refused"]
    assert refused
    assert "goal (A, A) leaves the vehicles 0.000 m apart: expected at least 1.600 m" in refused[0]
    assert "(separation + twice the position margin" in refused[0]  # 1.5 + 2 x 0.05


def test_a_goal_fault_off_the_graph_names_the_spec():
    scenario, _ = plan("h", "exact")
    with pytest.raises(FaultError, match=r"fault 'goal:agv1@3=zz:1': goal: .*zz"):
        parse_faults(scenario, ["goal:agv1@3=zz:1"])


def test_a_measured_state_off_the_track_graph_is_refused_naming_the_edge():
    scenario, verified = plan("h", "exact")
    executor = Executor(verified, names=scenario.names)
    ok = VehicleState(0, 6.0)
    with pytest.raises(InputError, match=r"vehicle 1 measured edge must be an edge index 0 to 4 .* got 7"):
        executor.step((VehicleState(7, 1.0), ok))
    with pytest.raises(
        InputError, match=r"vehicle 2 measured s 9\.0 m is off edge 'a': expected 0 to 6\.0 m"
    ):
        executor.step((ok, VehicleState(0, 9.0)))
    with pytest.raises(InputError, match=r"vehicle 1 measured velocity must be a finite number, got nan"):
        executor.step((VehicleState(0, 6.0, float("nan")), ok))
    track = GraphTrack(scenario.track)
    assert track.check_state(VehicleState(0, 6.0 + 5e-7), 1).s == 6.0  # round-off at the end is on it


def test_a_body_passes_a_node_onto_the_edge_it_is_steered_to():
    """Closed form: through J2 from m onto e and onto c and back onto m; a dead end stops it."""
    track = TrackGraph.from_edges(
        {"m": ("J1", "J2", 8.0), "e": ("J2", "D", 6.5), "c": ("C", "J2", 6.0), "a": ("J1", "A", 6.0)}
    )
    shape = GraphShape(track)
    m, e, c, a = (track.edge(name) for name in "meca")

    class Steer:
        def __init__(self, leg, branch):
            self.leg, self.branch = leg, branch

    body = GraphBody(m, 7.9, 1, 0.0)
    body.steer(Steer(m, e))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.orientation, body.axis) == (e, pytest.approx(0.2), 1, pytest.approx(0.3))
    body = GraphBody(m, 7.9, 1, 0.0)  # onto c, whose "to" node is J2: s counts down from its length
    body.steer(Steer(c, c))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.orientation) == (c, pytest.approx(5.8), -1)
    body.steer(Steer(m, m))  # and back through J2 onto m, driving the axis the other way
    body.move(-0.5, shape)
    assert (body.leg, body.s, body.orientation) == (m, pytest.approx(7.7), 1)
    body = GraphBody(a, 5.9, 1, 0.0)  # A is a dead end: the vehicle stops there, at rest
    body.v = 0.5
    body.steer(Steer(a, a))
    body.move(0.3, shape)
    assert (body.leg, body.s, body.axis, body.v) == (a, 6.0, pytest.approx(0.1), 0.0)


def test_simulate_on_the_h_writes_a_trace_whose_rows_keep_the_separation(tmp_path):
    """``trajgen simulate`` on a graph: the trace's rows, read back and measured by the track alone."""
    code = main(
        [
            "simulate",
            str(EXAMPLES / "h.toml"),
            "--method",
            "exact",
            "--fault",
            "stop:agv1@10+5",
            "--trace",
            str(tmp_path / "trace"),
            "--json",
        ]
    )
    assert code == 0
    scenario = load_scenario(EXAMPLES / "h.toml")
    track = scenario.track
    rows = []
    for name in scenario.names:
        lines = (tmp_path / "trace" / f"{name}.csv").read_text().splitlines()
        assert lines[0] == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m;x_m;y_m"
        fields = [line.split(";") for line in lines[1:]]
        edges = np.array([track.edge(f[5]) for f in fields])
        s = np.array([float(f[6]) for f in fields])
        rows.append((edges, s))
    assert rows[0][0].size == rows[1][0].size > 1000
    apart = track.distances(rows[0][0], rows[0][1], rows[1][0], rows[1][1])
    assert apart.min() >= scenario.limits.min_separation - 1e-6
    start = [
        track.distance(EdgePoint(int(r[0][0]), r[1][0]), p) for r, p in zip(rows, scenario.start, strict=True)
    ]
    goal = [
        track.distance(EdgePoint(int(r[0][-1]), r[1][-1]), p)
        for r, p in zip(rows, scenario.goal, strict=True)
    ]
    assert max(start) <= 1e-9
    assert max(goal) <= 0.01


def test_simulate_json_on_a_graph_reports_the_run(capsys):
    code = main(["simulate", str(EXAMPLES / "passing-loop.toml"), "--method", "exact", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["reached_goal"] is True
    assert summary["separation_violations"] == 0
    assert summary["emergency_brakes"] == 0


def test_the_margin_on_a_graph_shrinks_to_what_the_start_and_goal_leave():
    track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    agv = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    scenario = GraphScenario(track, Limits((agv, agv), 1.5), ("agv1", "agv2"), ("a:1.56", "b:0"), ("A", "B"))
    # the start leaves 1.56 m: 0.03 m each side of the separation
    assert execution_margin(scenario, 0.05) == pytest.approx(0.03)
    result, _ = simulate(scenario, method="exact")
    assert result.reached_goal
    assert result.violations == 0


@pytest.mark.slow  # simulations of seeded random tracks with faults
@pytest.mark.parametrize("method", ["exact", "toppra"])
def test_seeded_random_track_graphs_with_faults_reach_their_goals_without_a_violation(method):
    """Trees and graphs with loops, random limits, one to three faults each (the bench's campaign)."""
    for k, scenario in enumerate(graph_online_campaign(8, seed=23)):
        verified = schedule_for_execution(scenario, method=method)
        margin = execution_margin(scenario, 0.05)
        specs = graph_campaign_faults(scenario, verified.schedule.duration, seed=k, margin=margin)
        result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
        assert result.reached_goal, (k, specs)
        assert result.violations == 0, (k, specs, result.summary())
        assert result.emergency_brakes == 0, (k, specs)


def test_the_campaign_draws_trees_and_loops_whose_start_and_goal_keep_the_separation():
    scenarios = graph_online_campaign(6, seed=5)
    assert scenarios == graph_online_campaign(6, seed=5)  # seeded: the same draw
    for k, scenario in enumerate(scenarios):
        track = scenario.track
        cycle = track.edge_count - len(track.nodes) + 1  # independent loops of a connected graph
        assert (cycle > 0) == (k % 2 == 1), k
        for pair in (scenario.start, scenario.goal):
            assert track.distance(*pair) >= scenario.limits.min_separation
        scenario.route()  # a route exists


def test_a_throttled_drive_brakes_down_to_its_cap_no_harder_than_its_max_acceleration():
    """A slow fault caps agv1 at 0.2 m/s while it drives at 1 m/s: it slows at most at 0.5 m/s².

    A drive dropping to its cap within one cycle (80 m/s² here) made the braking check assume the
    worst of it and brake both hard (a campaign run on a random graph: 5 emergency-brake cycles); a
    drive slowing at its emergency deceleration still stepped its speed beyond what it can (issue 38).
    """
    scenario, verified = plan("h", "exact")
    vehicle = scenario.limits.vehicles[0]
    accelerations, speeds = [], []

    def observe(executor, measured, command):
        accelerations.append(measured[0].acceleration)
        speeds.append(abs(measured[0].velocity))

    result, _ = simulate(
        scenario, parse_faults(scenario, ["slow:agv1@3=0.2"]), verified=verified, observer=observe
    )
    assert result.reached_goal
    assert result.violations == 0
    assert result.emergency_brakes == 0
    assert max(speeds[290:310]) > 0.9  # it was at speed when the cap came
    assert min(accelerations) >= -vehicle.max_acceleration - 1e-9
    assert np.max(np.abs(np.diff(speeds))) <= vehicle.max_acceleration * 0.01 * (1 + 1e-6)
    settled = 300 + math.ceil((max(speeds[290:310]) - 0.2) / vehicle.max_acceleration / 0.01) + 2
    assert max(speeds[settled:]) <= 0.2 + 1e-9  # and then kept to the cap


def test_a_vehicle_that_stays_put_through_a_re_plan_drives_its_next_move_the_right_way():
    """A plan in which a vehicle does not move keeps the way its axis runs.

    agv1's axis runs against ``s`` (it starts by driving towards J); a new goal for agv2 leaves it
    where it stands; its own next goal must then be driven towards A (it drove towards J).
    """
    track = TrackGraph.from_edges({"a": ("J", "A", 10.0), "b": ("J", "B", 10.0), "c": ("J", "C", 10.0)})
    drive = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits((drive, drive), 1.5)
    scenario = GraphScenario(track, limits, ("agv1", "agv2"), ("a:8", "b:5"), ("a:3", "b:5"))
    verified = schedule_for_execution(scenario, method="exact")
    final = []

    def observe(executor, measured, command):
        final[:] = measured

    faults = parse_faults(scenario, ["goal:agv2@12=b:8", "goal:agv1@30=a:9"])
    result, _ = simulate(scenario, faults, verified=verified, observer=observe)
    assert result.reached_goal, result.summary()
    assert result.replans == 2
    assert not any("off its setpoints" in e.detail for e in result.events), result.events
    assert (final[0].leg, final[1].leg) == (0, 1)
    assert final[0].s == pytest.approx(9.0, abs=0.05)
    assert final[1].s == pytest.approx(8.0, abs=0.05)


@pytest.mark.parametrize(
    ("seed", "k", "specs", "emergency"),
    [
        # a jump back leaves the drive closing the gap faster than planned: restarted at that
        # speed, it could not stop at its reversal and waited there for ever
        (9, 7, ("jump:agv1@6.476=-0.04289",), False),
        (9, 7, ("jump:agv1@6.476=-0.04289", "slow:agv2@2.121=0.4481"), False),
        # a lagging drive braked hard stops short of its setpoint; the check took it anywhere up to
        # the setpoint, too close to the other, and braked both, at rest, for ever
        (12, 3, ("lag:agv1@4.143=174", "slow:agv1@4.814=1.1585"), True),
    ],
    ids=["jump", "jump-slow", "lag-slow"],
)
def test_campaign_runs_that_never_reached_the_goal_with_toppra_now_do(seed, k, specs, emergency):
    scenario = graph_online_campaign(k + 1, seed=seed)[k]
    verified = schedule_for_execution(scenario, method="toppra")
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal, result.summary()
    assert result.violations == 0
    if not emergency:
        assert result.emergency_brakes == 0
    else:  # the lag hides the drive from its setpoints: braking hard is right, but only until at rest
        assert result.emergency_brakes < 100
