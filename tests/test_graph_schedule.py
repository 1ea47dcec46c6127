"""Schedules on track graphs: timed, verified in closed form, written as generic CSV, checked by the rows."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.graph_rows import ScenarioFile, check_profiles
from tests.support.grid_oracle import random_case
from topology import InfeasibleError, TrackGraph, plan_graph
from trajgen import certify
from trajgen.cli import main
from trajgen.errors import InputError, OptionError, VerificationError
from trajgen.export.csv import CsvOptions, profile_chunk_pair
from trajgen.methods import make_schedule
from trajgen.methods.exact import Exact
from trajgen.methods.optimal import Optimal
from trajgen.model.graph_schedule import GraphSchedule, GraphSection
from trajgen.model.profiles import PiecewiseCubic, rest_to_rest_time, scurve_phases
from trajgen.model.schedule import CubicKinematics, TimingMethod
from trajgen.pipeline import Outputs, run
from trajgen.scenario import load_scenario
from trajgen.verification import verify

EXAMPLES = REPO / "examples" / "graphs"
FEASIBLE = ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]
AGV = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
CROSS = TrackGraph.from_edges({leg: ("J", leg.upper(), 6.0) for leg in "abcd"})


def _csv_texts(verified, options=None) -> tuple[str, str]:
    first, second = profile_chunk_pair(verified, options)
    return b"".join(first).decode("ascii"), b"".join(second).decode("ascii")


@pytest.mark.parametrize("name", FEASIBLE)
@pytest.mark.parametrize("jerk", [True, False], ids=["s-curves", "trapezoids"])
def test_every_example_graph_is_timed_verified_and_its_csv_rows_hold_the_separation_and_limits(name, jerk):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact(jerk=jerk)))
    report = verified.report
    assert report.passed
    assert report.regions_match
    assert report.min_separation >= scenario.limits.min_separation - 1e-9
    figures = check_profiles(ScenarioFile(EXAMPLES / f"{name}.toml"), _csv_texts(verified), jerk=jerk)
    assert figures["closest"] >= scenario.limits.min_separation - 1e-6
    assert figures["closest"] <= report.min_separation + 0.05  # the rows come near the verified closest
    # the exact schedule drives each vehicle at its limit somewhere: the rows show it
    assert figures["v"] > 0.99
    assert figures["a"] > 0.99


@pytest.mark.parametrize("name", FEASIBLE)
def test_the_exact_makespan_is_the_sum_of_each_moves_closed_form_s_curve(name):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    route = scenario.route()
    expected = 0.0
    for move in route.moves:
        v = scenario.limits.vehicles[move.vehicle]
        expected += rest_to_rest_time(move.length, v.max_velocity, v.max_acceleration, v.max_jerk)
    assert make_schedule(route, scenario.limits, method="exact").duration == pytest.approx(
        expected, rel=1e-12
    )


def test_the_h_takes_the_closed_form_time_of_its_three_moves():
    # moves of 7.5, 20.5 and 15.5 m at v 1, a 0.5, j 1: each D/v + v/a + a/j = D + 2.5 s
    scenario = load_scenario(EXAMPLES / "h.toml")
    assert make_schedule(scenario.route(), scenario.limits, method="exact").duration == pytest.approx(51.5)


def _crossing() -> tuple:
    route = plan_graph(CROSS, ("A", "B"), ("C", "D"), min_separation=1.5)
    return route, Limits((AGV, AGV), 1.5)


def test_the_verifier_finds_a_schedule_that_passes_a_conflict_in_the_other_order():
    route, limits = _crossing()
    assert certify(make_schedule(route, limits, method="exact")).report.regions_match
    reversed_route = dataclasses.replace(route, moves=tuple(reversed(route.moves)))
    other_order = dataclasses.replace(make_schedule(reversed_route, limits, method="exact"), route=route)
    report = verify(other_order)
    assert not report.passed
    assert not report.regions_match
    with pytest.raises(VerificationError, match="passes a conflict in another order than the route"):
        certify(other_order)


def _together(route, limits) -> GraphSchedule:
    """Both vehicles driving at once from t = 0, each its whole path in one S-curve."""
    schedule = make_schedule(route, limits, method="exact")
    moves = []
    for vehicle, path in enumerate(schedule.paths):
        v = limits.vehicles[vehicle]
        phases = [
            (d, math.nan, j)
            for d, j in scurve_phases(path.length, v.max_velocity, v.max_acceleration, v.max_jerk)
        ]
        moves.append(phases)
    duration = max(sum(d for d, _, _ in phases) for phases in moves)
    profiles = [  # the one that arrives first waits there: both motions end with the section
        PiecewiseCubic.from_phases(
            0.0, [*phases, (duration - sum(d for d, _, _ in phases), 0.0, 0.0)], end=path.length
        )
        for phases, path in zip(moves, schedule.paths, strict=True)
    ]
    return dataclasses.replace(schedule, sections=(GraphSection(0.0, CubicKinematics(tuple(profiles))),))


def test_the_verifier_finds_two_vehicles_too_close_between_samples():
    route, limits = _crossing()
    report = verify(_together(route, limits))
    assert not report.passed
    assert report.min_separation < 1.5
    with pytest.raises(VerificationError, match=r"separation .* m at t=.* is below the minimum 1.5 m"):
        certify(_together(route, limits))


def test_the_verifier_finds_a_vehicle_that_turns_back_without_stopping():
    scenario = load_scenario(EXAMPLES / "h.toml")  # agv1 parks in c and turns back
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    assert schedule.paths[0].cusps.size == 1
    merged = _together(scenario.route(), scenario.limits)  # one S-curve through the cusp
    with pytest.raises(
        VerificationError, match=r"vehicle 1 turns back at 15.5 m of travel .* m/s: expected at rest"
    ):
        certify(merged)
    del schedule


def test_the_verifier_finds_a_schedule_faster_than_the_limits():
    route, limits = _crossing()
    schedule = make_schedule(route, limits, method="exact")
    faster = dataclasses.replace(
        schedule, limits=Limits((dataclasses.replace(AGV, max_velocity=0.9), AGV), 1.5)
    )
    with pytest.raises(
        VerificationError, match=r"vehicle 1 velocity reaches 1 m/s .* exceeds its max_velocity 0.9"
    ):
        certify(faster)


def test_the_verifier_finds_a_path_that_is_not_the_routes():
    route, limits = _crossing()
    schedule = make_schedule(route, limits, method="exact")
    other = plan_graph(CROSS, ("A", "B"), ("D", "C"), min_separation=1.5)
    with pytest.raises(
        VerificationError, match=r"vehicle 1's path goal is 6 m off the route's|path is .* off move"
    ):
        certify(dataclasses.replace(schedule, route=other))


def test_a_graph_run_writes_both_csv_files_and_refuses_a_spline_dialect_without_jerk_limits(tmp_path):
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    result = run(scenario, outputs=Outputs(csv_dir=tmp_path / "csv"))
    assert result.method.name == "exact"
    assert result.verified.report.passed
    assert sorted(p.name for p in result.files) == ["agv1.csv", "agv2.csv"]
    assert result.summary()["route"]["travel_m"] == list(result.route.travel)
    with pytest.raises(OptionError, match="dialect 'logix-time-cam' interpolates a cubic spline"):
        run(scenario, method="toppra", outputs=Outputs(csv_dir=tmp_path / "t", dialect="logix-time-cam"))
    assert not (tmp_path / "t").exists()


def test_the_schedule_command_times_a_graph_and_writes_its_csv(tmp_path, capsys):
    assert main(["schedule", str(EXAMPLES / "h.toml"), "--csv", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "method: exact  duration: 51.500 s  verified: True" in out
    assert "agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D" in out
    header = (tmp_path / "agv1.csv").read_text().splitlines()[0]
    assert header == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m;x_m;y_m"


def test_a_graph_without_coordinates_has_no_xy_columns_and_millimetres_scale_every_length(tmp_path):
    track = TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    verified = certify(make_schedule(route, Limits((AGV, AGV), 1.5), method="exact"))
    metres, _ = _csv_texts(verified)
    millimetres, _ = _csv_texts(verified, CsvOptions(units="mm", delimiter=",", decimal="."))
    assert metres.splitlines()[0] == "t_s;axis_m;v_mps;a_mps2;j_mps3;edge;s_m"
    assert millimetres.splitlines()[0] == "t_s,axis_mm,v_mmps,a_mmps2,j_mmps3,edge,s_mm"
    row_m = metres.splitlines()[500].split(";")
    row_mm = millimetres.splitlines()[500].split(",")
    assert row_m[5] == row_mm[5]
    assert row_m[0] == row_mm[0]
    for k in (1, 2, 3, 4, 6):
        assert float(row_mm[k]) == pytest.approx(1000.0 * float(row_m[k]), abs=1e-5)


def test_an_edge_name_holding_the_delimiter_is_refused_naming_it():
    track = TrackGraph.from_edges({"a;1": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)})
    route = plan_graph(track, ("A", "B"), ("B", "A"), min_separation=1.5)
    verified = certify(make_schedule(route, Limits((AGV, AGV), 1.5), method="exact"))
    with pytest.raises(OptionError, match=r"edge name 'a;1' holds the CSV delimiter ';'"):
        profile_chunk_pair(verified)
    assert _csv_texts(verified, CsvOptions(delimiter=","))[0].count("a;1") > 0


def test_a_method_that_does_not_time_graphs_says_so_naming_itself():
    route, limits = _crossing()

    class Junctions(Exact):
        name = "junctions-only"
        schedule_graph = TimingMethod.schedule_graph

    with pytest.raises(InputError, match="method 'junctions-only' does not time a track graph yet"):
        make_schedule(route, limits, method=Junctions())


@pytest.mark.slow  # seeded random graphs, each timed, verified and written: a campaign
def test_seeded_random_graphs_are_timed_and_verified_with_the_rows_safe(tmp_path):
    checked = 0
    for seed in range(400):
        case = random_case(seed, loops=seed % 2 == 1)
        if case is None:
            continue
        edges, start, goal, separation = case
        track = TrackGraph.from_edges(edges)
        try:
            route = plan_graph(track, start, goal, min_separation=separation)
        except InfeasibleError:
            continue
        limits = Limits((AGV, dataclasses.replace(AGV, max_velocity=1.4, max_jerk=2.0)), separation)
        verified = certify(make_schedule(route, limits, method="exact"))
        state = verified.schedule.sample(0.05)
        gaps = track.distances(state.edge[0], state.s[0], state.edge[1], state.s[1])
        assert np.all(gaps >= separation - 1e-9), seed
        assert verified.report.min_separation <= gaps.min() + 1e-12
        checked += 1
        if checked == 60:
            break
    assert checked == 60


def _with_acceleration_step(
    schedule: GraphSchedule, section: int, interval: int, step: float
) -> GraphSchedule:
    """The schedule with vehicle 1's acceleration stepped by ``step`` at the start of one interval."""
    profile = schedule.sections[section].kinematics.vehicles[0]
    initial = np.array(profile.initial)
    initial[interval, 2] += step
    stepped = PiecewiseCubic(profile.times, initial, profile.jerk)
    other = schedule.sections[section].kinematics.vehicles[1]
    sections = list(schedule.sections)
    sections[section] = GraphSection(sections[section].start_time, CubicKinematics((stepped, other)))
    return dataclasses.replace(schedule, sections=tuple(sections))


def test_the_verifier_finds_an_acceleration_step_and_allows_a_sign_change_only_where_the_path_turns_back():
    scenario = load_scenario(EXAMPLES / "h.toml")
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    # mid-move (the cruise of the first move): a step of 0.2 m/s^2 is a jump
    with pytest.raises(VerificationError, match=r"vehicle 1 acceleration jumps by 0.2"):
        certify(_with_acceleration_step(schedule, 0, 3, 0.2))


@pytest.mark.slow
def test_the_optimal_h_reverses_smoothly_at_the_cusp_and_verifies():
    """agv1 turns back in c at full deceleration.

    Its travel's acceleration goes -0.5 -> +0.5 m/s^2 there, the acceleration along its axis is
    continuous; the verifier allows that sign change at the cusp only.
    """
    scenario = load_scenario(EXAMPLES / "h.toml")
    optimal = make_schedule(scenario.route(), scenario.limits, method=Optimal(homotopy="planned"))
    assert optimal.fallback_reason is None
    assert certify(optimal).report.passed
    t = np.linspace(0.0, optimal.duration, 400_001)
    travel = optimal.travel(t)[0]
    k = int(np.argmin(np.abs(travel[0] - optimal.paths[0].cusps[0]) + 10.0 * np.abs(travel[1])))
    assert travel[2, k - 2] < -0.4
    assert travel[2, k + 2] > 0.4
    state = optimal.state(t[k - 2 : k + 3])
    assert np.ptp(state.acceleration[0]) < 0.01  # along the axis: no step
