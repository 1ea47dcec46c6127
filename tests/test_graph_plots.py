"""Plots of schedules on track graphs: the too-close region of the graph metric, the files, the animation."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import numpy as np
import pytest
from matplotlib.path import Path as PolygonPath

from tests.conftest import REPO
from trajgen import certify
from trajgen.cli import main
from trajgen.methods import make_schedule
from trajgen.model.graph_cells import too_close_polygons
from trajgen.pipeline import PLOT_NAMES, Outputs, run
from trajgen.plots import animate, plot_coordination, plot_separation
from trajgen.plots.animation_layout import frame_geometry
from trajgen.plots.track_layout import TrackLayout
from trajgen.scenario import load_scenario

EXAMPLES = REPO / "examples" / "graphs"


@pytest.mark.parametrize("name", ["h", "passing-loop", "ring-with-spurs", "main-line-with-sidings"])
def test_the_too_close_polygons_are_exactly_where_the_track_distance_is_below_the_separation(name):
    """Agreement of two computations: the clipped polygons against the track's own distances."""
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    schedule = make_schedule(scenario.route(), scenario.limits, method="exact")
    paths, track, d = schedule.paths, scenario.track, scenario.limits.min_separation
    polygons = [PolygonPath(np.array(part.polygon)) for part in too_close_polygons(track, paths, d)]
    assert polygons
    rng = np.random.default_rng(7)
    points = rng.uniform([0.0, 0.0], [paths[0].length, paths[1].length], size=(4000, 2))
    inside = np.zeros(len(points), dtype=bool)
    for polygon in polygons:
        inside |= polygon.contains_points(points)
    edge_1, s_1 = paths[0].locate(points[:, 0])
    edge_2, s_2 = paths[1].locate(points[:, 1])
    distance = track.distances(edge_1, s_1, edge_2, s_2)
    clear = np.abs(distance - d) > 1e-6  # on the boundary either answer is right
    assert np.array_equal(inside[clear], (distance < d)[clear])


def test_every_graph_schedules_curve_stays_out_of_the_shaded_region_and_the_figure_compares_them():
    scenario = load_scenario(EXAMPLES / "h.toml")
    route = scenario.route()
    verified = {m: certify(make_schedule(route, scenario.limits, method=m)) for m in ("exact", "toppra")}
    figure = plot_coordination(verified)
    axis = figure.axes[0]
    assert len(axis.patches) == len(too_close_polygons(scenario.track, verified["exact"].schedule.paths, 1.5))
    for name, v in verified.items():
        travel = v.schedule.travel(np.linspace(0.0, v.schedule.duration, 2000))[:, 0]
        for patch in axis.patches:
            polygon = patch.get_path().transformed(patch.get_patch_transform())
            assert not polygon.contains_points(travel.T, radius=-1e-6).any(), name
    labels = [line.get_label() for line in axis.get_lines()]
    assert any(label.startswith("exact (51.5 s)") for label in labels)
    separation = plot_separation(verified["toppra"]).axes[0]
    closest = min(float(np.min(line.get_ydata())) for line in separation.get_lines()[:1])
    assert closest == pytest.approx(verified["toppra"].report.min_separation, abs=0.02)


def test_a_graph_run_with_plots_writes_the_four_pictures_and_its_layout(tmp_path):
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    result = run(scenario, method="toppra", outputs=Outputs(plot_dir=tmp_path, compare=("exact",)))
    assert sorted(p.name for p in result.files) == sorted(PLOT_NAMES)
    for name in PLOT_NAMES:
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_animation_of_a_graph_schedule_puts_the_vehicles_where_the_layout_draws_their_positions(tmp_path):
    scenario = load_scenario(EXAMPLES / "h.toml")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method="exact"))
    layout = TrackLayout.of(scenario.track)
    geometry = frame_geometry(verified, [0.0, verified.schedule.duration])
    for vehicle in range(2):
        start = layout.point(scenario.start[vehicle])
        goal = layout.point(scenario.goal[vehicle])
        assert np.allclose([geometry.x[vehicle, 0], geometry.y[vehicle, 0]], start, atol=1e-9)
        assert np.allclose([geometry.x[vehicle, -1], geometry.y[vehicle, -1]], goal, atol=1e-9)
    animation = animate(verified, names=scenario.names, max_frames=20)
    frames = list(animation.frames())
    assert len(frames) == animation.frame_count
    assert frames[0].shape == (600, 640, 3)
    assert (
        main(["animate", str(EXAMPLES / "h.toml"), "--out", str(tmp_path / "h.gif"), "--max-frames", "20"])
        == 0
    )
    assert (tmp_path / "h.gif").read_bytes()[:6] == b"GIF89a"
