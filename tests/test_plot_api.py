"""Every plot draws where it is told and returns the Figure; bytes are made at the edges alone.

Each plot function of :mod:`trajgen.plots` takes an ``ax`` (one axis) or a ``figure`` (a Figure or
SubFigure) and returns the Figure that holds the drawing; without one it makes its own. The 0.6
renderers (bytes) are shims for one release: they warn and return the PNG of the plot.
"""

from __future__ import annotations

import ast
import warnings

import numpy as np
import pytest
from matplotlib.figure import Figure

from tests.conftest import REPO
from tests.support.helpers import animation_gif
from trajgen import Exact, certify, default_scenario, make_schedule
from trajgen.execution.simulation import parse_faults, simulate
from trajgen.plots import (
    animate,
    plot_configuration,
    plot_coordination,
    plot_live_run,
    plot_separation,
    plot_simulation,
    plot_speed,
    png_bytes,
    render_animation,
    render_configuration,
    render_coordination,
    render_live_run,
    render_separation,
    render_simulation,
    render_speed,
)

NAMES = ("agv1", "agv2")


@pytest.fixture(scope="module")
def subjects():
    scenario = default_scenario()
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=Exact()))
    result, _ = simulate(scenario, parse_faults(scenario, ["stop:agv1@3+2"]), method="exact")
    run = {
        "states": {name: [(float(t), 0.5 * t, True) for t in np.linspace(0.0, 10.0, 20)] for name in NAMES},
        "orders": {name: [(0.0, 4.0)] for name in NAMES},
        "events": [],
        "end": {"t": 10.0, "event": "end", "outcome": "goals-reached", "makespan_s": 10.0},
    }
    return scenario, verified, result, run


PLOTS = {  # name -> (how to call it with its subjects, the keyword of its drawing area)
    "speed": (lambda s, area: plot_speed(s[1], names=NAMES, figure=area), "figure"),
    "separation": (lambda s, area: plot_separation(s[1], ax=area), "ax"),
    "coordination": (lambda s, area: plot_coordination({"exact": s[1]}, figure=area), "figure"),
    "configuration": (lambda s, area: plot_configuration(s[1], names=NAMES, figure=area), "figure"),
    "simulation": (
        lambda s, area: plot_simulation(s[2], names=NAMES, min_separation=1.5, figure=area),
        "figure",
    ),
    "live_run": (lambda s, area: plot_live_run(s[3], names=NAMES, figure=area), "figure"),
}


@pytest.mark.parametrize("name", list(PLOTS))
def test_a_plot_draws_into_the_area_given_and_returns_its_figure(name, subjects):
    call, kind = PLOTS[name]
    root = Figure(figsize=(20, 10))
    left, right = root.subfigures(1, 2)
    other = left.subplots()  # the caller's own axis beside the plot, left as it is
    area = right.subplots() if kind == "ax" else right
    returned = call(subjects, area)
    assert returned is root
    drawn = area.axes if kind == "figure" else [area]
    assert drawn
    assert all(axis.has_data() or axis.patches or axis.texts or axis.lines for axis in drawn)
    assert not other.has_data()
    assert len(root.axes) == 1 + len(drawn)


@pytest.mark.parametrize("name", list(PLOTS))
def test_a_plot_without_an_area_makes_its_own_figure(name, subjects):
    call, _ = PLOTS[name]
    figure = call(subjects, None)
    assert isinstance(figure, Figure)
    assert figure.axes
    assert png_bytes(figure).startswith(b"\x89PNG")


SHIMS = {
    "render_speed": (lambda s: render_speed(s[1], names=NAMES), lambda s: plot_speed(s[1], names=NAMES)),
    "render_separation": (lambda s: render_separation(s[1]), lambda s: plot_separation(s[1])),
    "render_coordination": (
        lambda s: render_coordination({"exact": s[1]}),
        lambda s: plot_coordination({"exact": s[1]}),
    ),
    "render_configuration": (
        lambda s: render_configuration(s[1], names=NAMES),
        lambda s: plot_configuration(s[1], names=NAMES),
    ),
    "render_simulation": (
        lambda s: render_simulation(s[2], names=NAMES, min_separation=1.5),
        lambda s: plot_simulation(s[2], names=NAMES, min_separation=1.5),
    ),
    "render_live_run": (
        lambda s: render_live_run(s[3], names=NAMES),
        lambda s: plot_live_run(s[3], names=NAMES),
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SHIMS))
def test_a_renderer_of_0_6_warns_and_returns_the_png_of_its_plot(name, subjects):
    old, new = SHIMS[name]
    with pytest.warns(
        DeprecationWarning, match=f"trajgen.plots.{name} is deprecated: use trajgen.plots.plot_"
    ):
        png = old(subjects)
    assert png == png_bytes(new(subjects))


def test_the_animation_is_frames_drawn_when_asked_and_its_old_renderer_is_its_gif(subjects):
    verified = subjects[1]
    animation = animate(verified, names=NAMES, max_frames=6)
    assert 2 <= animation.frame_count == len(animation.delays_ms) <= 6
    frames = list(animation.frames())
    assert len(frames) == animation.frame_count
    assert frames[0].shape[2] == 3
    assert isinstance(animation.figure, Figure)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gif = render_animation(verified, names=NAMES, max_frames=6)
    assert [w.category for w in caught] == [DeprecationWarning]
    assert gif == animation_gif(verified, names=NAMES, max_frames=6)


def test_no_plot_module_makes_bytes():
    """PNG and GIF bytes are made at the edges: only figure.py, gif.py and the shims define them."""
    allowed = {"figure.py", "gif.py", "deprecated.py", "__init__.py"}
    offending = []
    for source in sorted((REPO / "trajgen" / "plots").glob("*.py")):
        if source.name in allowed:
            continue
        for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Name) and node.id in {"png_bytes", "gif_bytes"}:
                offending.append(f"{source.name}:{node.lineno} uses {node.id}")
    assert offending == []
