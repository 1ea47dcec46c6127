"""A simulated run across a new goal: accounted against the plans driven, plotted without a break.

Issue 38, items 1 and 3: after ``goal:agv1@10=...`` the time lost was measured against the old
goal's plan, the plot's travel dropped back to 0 at the re-plan, the coordination panel kept the
old plan; and in ``simulation.png`` a legend covered a fault's label and part of a curve.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from tests.conftest import REPO
from trajgen import load_scenario
from trajgen.execution.goals import schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.model.coordination import schedule_paths
from trajgen.plots import plot_simulation
from trajgen.simulation_pipeline import format_simulation

#: a new goal for agv1 (the swap's plan would bring it to B:10) mid-run, and a slowdown before it
NEW_GOAL = ("slow:agv2@3+5=0.5", "goal:agv1@10=C:8")


@functools.cache
def _scenario(name: str):
    folder = REPO / "examples" / ("graphs" if name in ("h", "passing-loop") else "")
    scenario = load_scenario(folder / f"{name}.toml")
    return scenario, schedule_for_execution(scenario, method="exact")


@functools.cache
def _run(name: str, specs: tuple[str, ...]):
    scenario, verified = _scenario(name)
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    return scenario, result


def _first_time_reached(schedule, travel: tuple[float, float]) -> float:
    """When both vehicles of ``schedule`` have first travelled ``travel``, by sampling every 1 ms."""
    t = np.arange(0.0, schedule.duration + 1e-3, 1e-3)
    axis = schedule.state(t).axis
    along = np.concatenate([np.zeros((2, 1)), np.cumsum(np.abs(np.diff(axis, axis=1)), axis=1)], axis=1)
    return max(float(t[np.argmax(along[v] >= travel[v] - 1e-6)]) for v in (0, 1))


def test_time_lost_across_a_new_goal_is_measured_against_the_plans_driven():
    _, result = _run("swap", NEW_GOAL)
    assert result.reached_goal
    assert result.violations == 0
    assert result.replans == 1
    first, second = result.plans
    # the old plan counts up to where both vehicles stood when the run left it, found by sampling
    assert first.schedule is result.schedule.schedule
    assert first.ended_s == second.started_s
    assert first.planned_s == pytest.approx(
        _first_time_reached(first.schedule, second.travel_before), abs=2e-3
    )
    assert first.planned_s < first.schedule.duration
    # the new plan counts whole, from the re-plan
    assert second.planned_s == second.schedule.duration
    assert second.ended_s == result.makespan_s
    assert result.planned_s == pytest.approx(first.planned_s + second.planned_s, abs=1e-12)
    assert result.time_lost_s == pytest.approx(result.makespan_s - result.planned_s, abs=1e-12)
    # undisturbed after the re-plan, the new plan is driven on time; before it, the slowdown and the
    # stop for the new goal cost a few seconds (the old goal's plan was 67.5 s: lost would be < 0)
    assert abs(second.lost_s) < 0.05
    assert 0.5 < first.lost_s < 10.0
    assert 0.5 < result.time_lost_s < 10.0
    summary = result.summary()
    assert [part["planned_s"] for part in summary["plans"]] == [
        round(first.planned_s, 6),
        round(second.planned_s, 6),
    ]
    text = format_simulation(summary, min_separation=1.5)
    assert "plan 1 of 2: 0.000 to" in text
    assert "(left for a new goal)" in text


def test_a_goal_that_comes_after_both_reached_theirs_counts_the_wait_as_idle_not_lost():
    _, result = _run("swap", ("goal:agv2@75=B:5",))  # the exact plan ends at 67.5 s
    first, second = result.plans
    assert first.planned_s == first.schedule.duration
    assert first.ended_s == pytest.approx(first.schedule.duration, abs=0.05)  # when both were at rest there
    assert second.started_s == pytest.approx(75.0)
    assert result.idle_s == pytest.approx(second.started_s - first.ended_s, abs=1e-9)
    assert abs(result.time_lost_s) < 0.05  # nothing went wrong: nothing lost
    assert result.time_lost_s == pytest.approx(result.makespan_s - result.planned_s - result.idle_s)
    text = format_simulation(result.summary(), min_separation=1.5)
    assert "s at the goals waiting for a new one" in text
    assert "(at its goals, then a new goal at 75.000 s)" in text


def test_a_run_without_a_new_goal_is_one_plan_measured_whole():
    _, result = _run("swap", ("stop:agv2@20+3",))
    (only,) = result.plans
    assert only.started_s == 0.0
    assert only.ended_s == result.makespan_s
    assert result.planned_s == result.schedule.schedule.duration
    assert only.travel_before == (0.0, 0.0)


@pytest.mark.parametrize(
    ("name", "specs"),
    [("swap", NEW_GOAL), ("h", ("goal:agv1@8=C", "stop:agv2@2+2"))],
    ids=["swap", "h"],
)
def test_the_plotted_travel_continues_across_a_re_plan(name, specs):
    _, result = _run(name, specs)
    assert result.replans == 1
    travel = np.asarray(result.plot["travel"])
    # travel never runs back: the new plan's paths continue where the old ones were left
    assert np.all(np.diff(travel, axis=1) >= -1e-9)
    last = result.plans[-1]
    paths, _, _ = schedule_paths(last.schedule)
    for v in (0, 1):
        assert travel[v, -1] == pytest.approx(last.travel_before[v] + paths[v].length, abs=1e-3)
    assert max(last.travel_before) > 1.0  # the old plan had been driven some way


def test_the_plot_draws_each_plan_from_where_the_run_took_it_up_and_marks_the_re_plan():
    scenario, result = _run("swap", NEW_GOAL)
    figure = plot_simulation(result, names=scenario.names, min_separation=1.5)
    speed_axis, _, _, coordination_axis = figure.axes
    # the coordination panel holds the whole executed curve, to the run's end
    executed = next(line for line in coordination_axis.get_lines() if line.get_label() == "executed")
    x, y = executed.get_data()
    assert (x[-1], y[-1]) == pytest.approx(tuple(result.plot["travel"][:, -1]))
    assert coordination_axis.get_xlim()[1] >= x[-1]
    assert coordination_axis.get_ylim()[1] >= y[-1]
    assert any(text.get_text() == "re-plan" for text in coordination_axis.texts)
    # the planned speed after the re-plan is the new plan's, from the re-plan on
    second = result.plans[1]
    planned = next(line for line in speed_axis.get_lines() if line.get_label() == "agv2 planned")
    t, v = planned.get_data()
    after = (t > second.started_s + 1.0) & (t < second.ended_s)
    expected = second.axis_signs[1] * second.schedule.state(t[after] - second.started_s).velocity[1]
    assert np.allclose(v[after], expected, atol=1e-9)
    # the re-plan is numbered on the time panels and named in the legend
    legend = [text.get_text() for text in speed_axis.get_legend().get_texts()]
    assert "re-plan for the new goal" in legend
    assert "goal:agv1@10=C:8" in legend


def _extents(figure):
    """Window extents of every panel, legend and mark number of a drawn ``figure``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(figure).get_renderer()
    panels = [axis.get_window_extent(renderer) for axis in figure.axes]
    legends = [axis.get_legend().get_window_extent(renderer) for axis in figure.axes if axis.get_legend()]
    numbers = [
        text.get_window_extent(renderer)
        for axis in figure.axes
        for text in axis.texts
        if text.get_text().isdigit()
    ]
    return panels, legends, numbers


@pytest.mark.parametrize(
    ("name", "specs"),
    [
        ("swap", NEW_GOAL),
        ("swap", ("slow:agv1@3+8=0.4", "stop:agv2@5+2", "jump:agv1@12=0.03", "stop:agv1@20+1")),
        ("crossing", ("stop:agv1@1+1", "stop:agv2@1.5+1", "slow:agv1@2+3=0.3", "jump:agv2@4=-0.02")),
        # a goal that comes after both reached theirs: its re-plan in the same cycle, numbered apart
        ("swap", ("stop:agv1@5+1", "stop:agv2@5.2+1", "goal:agv2@40=B:5", "slow:agv1@45+2=0.5")),
        ("h", ("goal:agv1@8=C", "stop:agv2@2+2")),
    ],
    ids=["new-goal", "four-faults", "faults-close-together", "goal-after-the-goals", "graph-new-goal"],
)
def test_no_legend_or_mark_hides_a_curve_of_simulation_png(name, specs):
    scenario, result = _run(name, specs)
    figure = plot_simulation(result, names=scenario.names, min_separation=scenario.limits.min_separation)
    panels, legends, numbers = _extents(figure)
    whole = figure.bbox
    assert len(legends) == 4
    assert len(numbers) == 3 * len(result.faults + tuple(result.plans[1:]))
    for box in legends + numbers:
        # beside or above the panels, never over their data, and inside the picture
        assert not any(box.overlaps(panel) for panel in panels), (box, panels)
        assert whole.contains(box.x0, box.y0)
        assert whole.contains(box.x1, box.y1)
    for k, box in enumerate(legends):
        assert not any(box.overlaps(other) for other in legends[k + 1 :] + numbers)
    for k, box in enumerate(numbers):  # marks close together are numbered one above the other
        assert not any(box.overlaps(other) for other in numbers[k + 1 :]), (k, box)
