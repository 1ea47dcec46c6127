"""Pictures of a route on a track graph: the layout's geometry, the plot, and ``trajgen plan --plot``."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

from tests.conftest import REPO
from topology import TrackGraph, plan_graph
from trajgen.cli import main
from trajgen.errors import InputError
from trajgen.plots.graph_route import plot_graph_route
from trajgen.plots.track_layout import TrackLayout
from trajgen.scenario import load_scenario

EXAMPLES = REPO / "examples" / "graphs"


def _drawn_length(line: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(line, axis=0), axis=1).sum())


def test_nodes_are_drawn_where_the_scenario_puts_them_and_edges_as_long_as_they_are():
    scenario = load_scenario(EXAMPLES / "h.toml")
    layout = TrackLayout.of(scenario.track)
    assert layout.given
    np.testing.assert_allclose(layout.nodes, np.array(scenario.track.coordinates))
    for number, edge in enumerate(scenario.track.edges):
        assert _drawn_length(layout.edges[number]) == pytest.approx(edge.length, rel=0.02), edge.name
        start, end = scenario.track.ends(number)
        np.testing.assert_allclose(layout.edges[number][[0, -1]], layout.nodes[[start, end]], atol=1e-9)


def test_a_passing_loop_is_drawn_apart_from_the_main_and_a_point_lies_at_its_fraction_of_the_edge():
    scenario = load_scenario(EXAMPLES / "passing-loop.toml")
    track, layout = scenario.track, TrackLayout.of(scenario.track)
    main_line, loop = layout.edges[track.edge("main")], layout.edges[track.edge("loop")]
    assert np.max(np.linalg.norm(main_line - loop, axis=1)) > 2.0  # told apart at a glance
    half = layout.point(track.point("loop:5.75"))
    walked = layout.along(track.edge("loop"), 0.0, 5.75)
    assert _drawn_length(walked) == pytest.approx(_drawn_length(loop) / 2, rel=1e-6)
    np.testing.assert_allclose(walked[-1], half)


def test_without_coordinates_a_line_is_laid_out_straight_at_its_track_distances():
    track = TrackGraph.from_edges({"p": ("A", "B", 3.0), "q": ("B", "C", 4.0), "r": ("C", "D", 5.0)})
    layout = TrackLayout.of(track)
    assert not layout.given
    gaps = np.linalg.norm(layout.nodes[:, None] - layout.nodes[None], axis=2)
    np.testing.assert_allclose(gaps, track.node_distances, atol=1e-9)


@pytest.mark.parametrize("name", ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"])
def test_each_move_is_drawn_from_where_its_vehicle_is_to_where_it_goes(name):
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    route = scenario.route()
    layout = TrackLayout.of(scenario.track)
    where = [layout.point(p) for p in route.start]
    for number, move in enumerate(route.moves):
        line = layout.move(route, number)
        np.testing.assert_allclose(line[0], where[move.vehicle], atol=1e-9)
        assert _drawn_length(line) >= move.length * 0.98  # drawn edges are at least as long as straight
        where[move.vehicle] = line[-1]
    for vehicle in (0, 1):
        np.testing.assert_allclose(where[vehicle], layout.point(route.goal[vehicle]), atol=1e-9)


def test_the_plot_draws_into_the_axis_given_and_returns_its_figure():
    route = load_scenario(EXAMPLES / "h.toml").route()
    figure = Figure()
    ax = figure.subplots(1, 2)[1]
    assert plot_graph_route(route, names=("agv1", "agv2"), ax=ax) is figure
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["agv1: start A", "agv1: goal D", "agv2: start D", "agv2: goal A"]
    assert "agv1 23.5 m, agv2 20.5 m, 3 moves" in ax.get_title()
    assert isinstance(plot_graph_route(route), Figure)
    with pytest.raises(InputError, match="plot_graph_route takes a GraphRoute, got str"):
        plot_graph_route("route")


def test_plan_plot_writes_the_picture_of_a_graph_and_of_a_junction(tmp_path, capsys):
    for scenario, target in (
        (EXAMPLES / "ring-with-spurs.toml", "ring.png"),
        (REPO / "examples" / "swap.toml", "y.png"),
    ):
        assert main(["plan", str(scenario), "--plot", str(tmp_path / target)]) == 0
        image = Image.open(io.BytesIO((tmp_path / target).read_bytes()))
        assert image.format == "PNG"
        assert min(image.size) > 300
    capsys.readouterr()
    assert main(["plan", str(EXAMPLES / "h.toml"), "--plot", str(tmp_path / "h.gif")]) == 2
    assert "--plot" in capsys.readouterr().err
    assert not (tmp_path / "h.gif").exists()


def test_the_docs_show_a_picture_of_each_example():
    page = (REPO / "docs" / "graphs.md").read_text(encoding="utf-8")
    for name in ["h", "main-line-with-sidings", "passing-loop", "ring-with-spurs"]:
        assert f"images/graph-{name}.png" in page
        assert (REPO / "docs" / "images" / f"graph-{name}.png").stat().st_size > 10_000
    route = plan_graph(
        TrackGraph.from_edges({"a": ("J", "A", 6.0), "b": ("J", "B", 6.0), "c": ("J", "C", 6.0)}),
        ("A", "B"),
        ("B", "A"),
        min_separation=1.5,
    )
    assert plot_graph_route(route) is not None
