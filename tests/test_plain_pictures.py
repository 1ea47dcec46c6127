"""Pictures an engineer reads (issue 38, item 7): plain words, one precision, nothing cut off.

Also no smooth jerk where there is none, and the animation's cost quoted with the command that
measures it.

The words of a picture are checked as drawn: every visible text, with its box as Agg draws it at the
PNGs' resolution (tick labels outside the view are not drawn and are left out).
"""

from __future__ import annotations

import functools
import itertools
import math
import re

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.text import Text

from tests.conftest import REPO
from topology import Configuration, Position, StarGraph, YGraph, plan
from trajgen import Exact, certify, default_scenario, load_scenario, make_schedule, run
from trajgen.model.summary import DISTANCE_PLACES, ROUND_OFF_M, closest_text, format_run
from trajgen.plots import plot_configuration, plot_coordination, plot_separation, plot_speed
from trajgen.plots.figure import PNG_DPI
from trajgen.plots.speed import STEPS_LABEL, acceleration_steps
from trajgen.verification import POSITION_TOLERANCE

NAMES = ("agv1", "agv2")
LONG_NAMES = ("forklift-north", "forklift-south")
#: What the paper calls the parts of the space (docs/planner.md, docs/star.md): not for the picture.
NOTATION = re.compile(r"\b[QTP]\(|\bV[12]\(|\bG_\d|deleted point|retract|configuration space", re.IGNORECASE)


def drawn_texts(figure) -> list[tuple[Text, object]]:
    """Every text the figure shows, with its box in pixels as drawn at :data:`PNG_DPI`."""
    figure.set_dpi(PNG_DPI)
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    renderer = canvas.get_renderer()
    hidden = set()
    for axis in figure.axes:
        for ruler, view in ((axis.xaxis, axis.get_xlim()), (axis.yaxis, axis.get_ylim())):
            low, high = sorted(view)
            for tick in ruler.get_major_ticks() + ruler.get_minor_ticks():
                if not low - 1e-9 * (high - low) <= tick.get_loc() <= high + 1e-9 * (high - low):
                    hidden |= {id(tick.label1), id(tick.label2)}
    return [
        (text, text.get_window_extent(renderer))
        for text in figure.findobj(Text)
        if id(text) not in hidden and text.get_visible() and text.get_text().strip()
    ]


def overlapping(texts) -> list[tuple[str, str]]:
    return [
        (a.get_text(), b.get_text()) for (a, box_a), (b, box_b) in itertools.combinations(texts, 2)
        if box_a.overlaps(box_b)
    ]  # fmt: skip


def outside(figure, texts) -> list[str]:
    frame = figure.bbox
    return [
        text.get_text()
        for text, box in texts
        if box.x0 < frame.x0 - 0.5
        or box.y0 < frame.y0 - 0.5
        or box.x1 > frame.x1 + 0.5
        or box.y1 > frame.y1 + 0.5
    ]


# -- 1. configuration.png in plain words --------------------------------------------------------------------
def _conf(first: str, second: str) -> Configuration:
    return Configuration(Position.parse(first), Position.parse(second))


def _swap(track, a: str, b: str, lengths: dict):
    start = _conf(f"{a}:{lengths[a]:g}", f"{b}:{lengths[b]:g}")
    return plan(track, start, start.swapped(), min_separation=1.5)


LONG_Y = {"loading-dock": 12.0, "charger": 8.0, "main-line": 15.0}
LONG_STAR = {"dock": 10.0, "charger": 10.0, "main-line": 10.0, "parking": 10.0, "wash": 10.0}
SUBJECTS = {
    "swap-schedule": lambda: certify(
        make_schedule(default_scenario().route(), default_scenario().limits, method=Exact())
    ),
    "y-long-names": lambda: _swap(YGraph(LONG_Y), "loading-dock", "charger", LONG_Y),
    "crossing": lambda: load_scenario(REPO / "examples" / "crossing.toml").route(),
    "star-long-names": lambda: _swap(StarGraph(LONG_STAR), "dock", "main-line", LONG_STAR),
}
SUBJECT_NAMES = {
    "swap-schedule": NAMES,
    "y-long-names": LONG_NAMES,
    "crossing": None,
    "star-long-names": LONG_NAMES,
}


@functools.cache
def configuration(key: str):
    """The configuration picture of a subject and its drawn texts, made once per process."""
    figure = plot_configuration(SUBJECTS[key](), names=SUBJECT_NAMES[key])
    return figure, drawn_texts(figure)


@pytest.mark.parametrize("key", list(SUBJECTS))
def test_no_two_words_of_the_configuration_picture_overlap(key):
    figure, texts = configuration(key)
    assert len(texts) > 20  # the labels of the drawing, the legend, the title and the note
    assert overlapping(texts) == []
    assert outside(figure, texts) == []


@pytest.mark.parametrize("key", list(SUBJECTS))
def test_the_configuration_picture_speaks_of_the_vehicles_not_of_the_papers_notation(key):
    _, texts = configuration(key)
    words = [text.get_text() for text, _ in texts]
    assert [w for w in words if NOTATION.search(w)] == []
    everything = "\n".join(words)
    first, second = SUBJECT_NAMES[key] or ("vehicle 1", "vehicle 2")
    assert f"each point is (position of {first}" in everything
    assert f"position of {second}" in everything
    assert "docs/planner.md" in everything or "docs/star.md" in everything  # where the notation went
    if key in ("swap-schedule", "y-long-names"):  # a Y: the way round the centre, both at O never allowed
        assert "the route goes counterclockwise round the centre" in everything
        assert "both at O:\nnever allowed" in words
        assert f"{first} on " in everything  # the areas say where each vehicle is
    else:  # four or more legs: the places where they wait, named as pairs of where each is
        assert "(O, " in everything
        assert "rule 1" in everything


def test_the_docs_map_the_plain_words_to_the_papers_notation():
    planner = " ".join((REPO / "docs" / "planner.md").read_text(encoding="utf-8").split())
    star = " ".join((REPO / "docs" / "star.md").read_text(encoding="utf-8").split())
    assert "## Reading `configuration.png`" in planner
    for plain, notation in (
        ("agv1 on A, agv2 on B", "`Q(A,B)`"),
        ("both on A, agv2 nearer O", "`T(A,2)`"),
        ("(A, B)", "`P(A,B)`"),
        ("(O, B)", "`V1(B)`"),
        ("both at O: never allowed", "deleted point"),
        ("the rim", "boundary circle"),
        ("moved out to the rim", "retraction"),
    ):
        assert plain in planner, plain
        assert notation in planner, notation
    assert "## Reading `configuration.png`" in star
    for plain, notation in (("(N, S)", "`P(N,S)`"), ("(O, S)", "`V1(S)`"), ("lines", "`G_k`")):
        assert plain in star, plain
        assert notation in star, notation


# -- 2. one precision for the closest approach --------------------------------------------------------------
@pytest.mark.parametrize(
    ("metres", "text"),
    [
        pytest.param(1.5000009912539198, "1.5000 m", id="the-demo-swap"),
        pytest.param(1.49996, "1.4999 m", id="below-the-minimum-stays-below"),
        pytest.param(1.4999999999, "1.5000 m", id="round-off-of-a-kept-minimum"),
        pytest.param(10.0, "10.0000 m", id="exact"),
        pytest.param(-4e-5, "-0.0001 m", id="a-negative-margin"),
        pytest.param(4e-11, "0.0000 m", id="no-minus-zero"),
        pytest.param(float("nan"), "nan m", id="not-computed"),
    ],
)
def test_a_closest_approach_is_written_rounded_down(metres, text):
    assert closest_text(metres) == text


@pytest.mark.parametrize("seed", range(3))
def test_a_written_closest_approach_is_never_above_its_value(seed):
    values = np.random.default_rng(seed).uniform(0.0, 30.0, 2000)
    values = np.concatenate(
        [values, np.round(values, DISTANCE_PLACES), np.round(values, DISTANCE_PLACES) - 1e-7]
    )
    for value in values:
        shown = float(closest_text(float(value)).removesuffix(" m"))
        assert shown <= value + ROUND_OFF_M
        assert value - shown < 10.0**-DISTANCE_PLACES + ROUND_OFF_M
    assert ROUND_OFF_M == POSITION_TOLERANCE  # what the verifier forgives, and no more


@pytest.fixture(scope="module")
def demo():
    """The demo swap run as ``trajgen schedule`` runs it (optimal: 1.5000009912 m at its closest)."""
    return run(default_scenario())


def test_the_separation_plot_names_the_closest_approach_as_the_summary_does(demo):
    report = demo.verified.report
    assert report.min_separation != round(report.min_separation, DISTANCE_PLACES)  # not a round number
    (axis,) = plot_separation(demo.verified).axes
    (closest,) = [t.get_text() for t in axis.get_legend().get_texts() if t.get_text().startswith("closest")]
    figure = closest_text(report.min_separation)
    assert closest.startswith(f"closest {figure} at ")
    assert f"worst margins: separation {figure} " in format_run(demo.summary())
    # the marker is where the track distance is smallest, within a sample of the plot
    (marker,) = [line for line in axis.get_lines() if line.get_marker() == "v"]
    (curve,) = [line for line in axis.get_lines() if line.get_label() == "track distance"]
    assert marker.get_ydata()[0] == pytest.approx(report.min_separation, abs=1e-6)
    assert marker.get_xdata()[0] == pytest.approx(curve.get_xdata()[np.argmin(curve.get_ydata())], abs=0.011)
    assert f"at {marker.get_xdata()[0]:.2f} s" in closest


# -- 3. nothing of the coordination plot is cut off -------------------------------------------------------
@functools.cache
def by_method(name: str) -> dict:
    """Every method's verified schedule of a built-in scenario (optimal drives other paths: two panels)."""
    from trajgen.methods import METHODS

    scenario = load_scenario(REPO / "examples" / f"{name}.toml")
    route = scenario.route()
    return {cls.name: certify(make_schedule(route, scenario.limits, method=cls())) for cls in METHODS}


@pytest.mark.parametrize("name", ["swap", "crossing", "h", "long-method-names"])
def test_every_word_of_the_coordination_plot_lies_inside_the_figure(name, demo):
    if name == "h":  # a track graph, timed by exact
        scenario = load_scenario(REPO / "examples" / "graphs" / "h.toml")
        compared = {"exact": run(scenario, method="exact").verified}
    elif name == "long-method-names":  # the same paths under three names: one long title
        exact = by_method("swap")["exact"]
        compared = {"exact": exact, "exact, as planned for the night shift": exact, "toppra": exact}
        compared |= {"optimal": demo.verified}
    else:
        compared = by_method(name)
    figure = plot_coordination(compared)
    texts = drawn_texts(figure)
    assert len(figure.axes) == (1 if name == "h" else 2)
    assert {axis.get_title() for axis in figure.axes} <= {text.get_text() for text, _ in texts}
    assert outside(figure, texts) == []
    titles = {axis.get_title() for axis in figure.axes}
    assert overlapping([(text, box) for text, box in texts if text.get_text() in titles]) == []


# -- 4. a jerk that is not limited is drawn as the steps of the acceleration ---------------------------------
@pytest.mark.parametrize("name", ["swap", "h"])
def test_a_schedule_that_does_not_limit_jerk_marks_its_acceleration_steps(name):
    if name == "h":  # a track graph: the steps along each vehicle's axis, as the acceleration is plotted
        verified = run(load_scenario(REPO / "examples" / "graphs" / "h.toml"), method="toppra").verified
    else:
        verified = by_method("swap")["toppra"]
    schedule = verified.schedule
    assert not schedule.jerk_limited
    jerk = plot_speed(verified, names=NAMES).axes[2]
    assert [t.get_text() for t in jerk.get_legend().get_texts()] == [f"{n}: {STEPS_LABEL}" for n in NAMES]
    assert "jerk not limited" in jerk.get_title()
    # no curve: markers, stems and the zero line only
    assert all(line.get_linestyle() == "None" or len(line.get_xdata()) <= 2 for line in jerk.get_lines())
    assert len([c for c in jerk.collections if isinstance(c, LineCollection)]) == 2
    times, steps = acceleration_steps(schedule)
    assert times.size > 10
    for vehicle, markers in enumerate(line for line in jerk.get_lines() if line.get_linestyle() == "None"):
        shown = steps[vehicle] != 0.0
        np.testing.assert_array_equal(markers.get_xdata(), times[shown])
        np.testing.assert_array_equal(markers.get_ydata(), steps[vehicle, shown])
    # each step is the jump of the acceleration there (from rest at the start, to rest at the goal)
    inside = times < schedule.duration
    before = schedule.state(np.maximum(times[inside] - 1e-7, 0.0)).acceleration
    after = schedule.state(times[inside] + 1e-7).acceleration
    jumps = np.where(times[inside] > 0.0, after - before, after)
    np.testing.assert_allclose(steps[:, inside], np.where(steps[:, inside] != 0.0, jumps, 0.0), atol=1e-5)
    assert np.abs(jumps[steps[:, inside] == 0.0]).max(initial=0.0) < 1e-5
    last = -schedule.state(np.array([schedule.duration - 1e-7])).acceleration
    np.testing.assert_allclose(steps[:, ~inside], last, atol=1e-5)
    # and every jump of the sampled acceleration lies at a marked step
    sampled = schedule.sample(0.01)
    for vehicle in range(2):
        jumped = sampled.t[1:][np.abs(np.diff(sampled.acceleration[vehicle])) > 0.05]
        marked = times[steps[vehicle] != 0.0]
        assert all(np.min(np.abs(marked - t)) <= 0.0101 for t in jumped)


@pytest.mark.parametrize("method", ["exact", "optimal"])
def test_a_jerk_limited_schedule_shows_its_jerk_curve(method, demo):
    verified = by_method("swap")["exact"] if method == "exact" else demo.verified
    jerk = plot_speed(verified, names=NAMES).axes[2]
    state = verified.schedule.sample(0.01)
    curves = [line for line in jerk.get_lines() if len(line.get_xdata()) == state.t.size]
    assert len(curves) == 2
    for vehicle, curve in enumerate(curves):
        np.testing.assert_array_equal(curve.get_ydata(), state.jerk[vehicle])
    assert acceleration_steps(verified.schedule)[0].size == 0
    assert all(STEPS_LABEL not in t.get_text() for t in jerk.get_legend().get_texts())
    assert any("limit ±1 m/s³" in t.get_text() for t in jerk.get_legend().get_texts())


# -- 5. the animation's cost, quoted with the command that measures it ------------------------------------
def test_the_animation_time_in_the_docs_names_the_benchmark_that_measures_it():
    page = " ".join((REPO / "docs" / "plots.md").read_text(encoding="utf-8").split())
    command = "python benchmarks/bench_animation.py"
    assert command in page
    assert (REPO / "benchmarks" / "bench_animation.py").is_file()
    quoted = re.search(r"(\d+(?:\.\d+)?) s for 277 frames \((\d+(?:\.\d+)?) frames per second\)", page)
    assert quoted is not None, "docs/plots.md quotes the benchmark's line for the demo swap"
    seconds, rate = float(quoted.group(1)), float(quoted.group(2))
    assert math.isclose(277 / seconds, rate, rel_tol=0.02)  # the two figures of one measurement
    assert "about 10 s" not in page  # the figure before the benchmark, which nothing measured
