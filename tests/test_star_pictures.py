"""The pictures of junctions with four to eight legs: the animation on a k-leg track and ``G_k``."""

from __future__ import annotations

import io
import itertools
import math

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from PIL import Image

from tests.support.helpers import LIMITS, animation_gif, conf
from topology import JUNCTION_INDEX, Instruction, StarGraph, YGraph, plan
from topology.cycle import retract_indexed
from trajgen import Exact, certify, load_scenario, make_schedule
from trajgen.cli import EXIT_OK, main
from trajgen.errors import InputError, UnverifiedScheduleError
from trajgen.model.summary import class_label, class_name
from trajgen.pipeline import PLOT_NAMES
from trajgen.plots import plot_configuration, png_bytes
from trajgen.plots.animation_layout import (
    FRAME_HEIGHT_PX,
    FRAME_WIDTH_PX,
    frame_geometry,
    frame_layout,
    playback,
)
from trajgen.plots.configuration_layout import ConfigurationLayout
from trajgen.plots.speed import VEHICLE_COLOURS
from trajgen.plots.star_configuration import (
    BOW,
    RULE_WORDS,
    RetractGraphLayout,
    instruction_text,
    plot_retract_graph,
    route_points,
    schedule_points,
)


def configuration_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_configuration(...)``."""
    return png_bytes(plot_configuration(*arguments, **options))


def retract_graph_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_retract_graph(...)``."""
    return png_bytes(plot_retract_graph(*arguments, **options))


NAMES = {
    4: ("N", "W", "S", "E"),
    5: ("A", "B", "C", "D", "E"),
    8: ("L1", "L2", "L3", "L4", "L5", "L6", "L7", "L8"),
}
LENGTHS = {
    4: (10.0, 10.0, 10.0, 10.0),
    5: (10.0, 8.0, 12.0, 9.0, 11.0),
    8: (10.0, 9.0, 11.0, 10.0, 12.0, 8.0, 10.0, 9.5),
}
#: A 4-way crossing drawn as a plus, the others at the default angles (90 + 360 j / k).
ANGLES = {4: (90.0, 180.0, 270.0, 0.0)}
#: Start and goal of vehicle 1 and vehicle 2: a head-on swap (4, 8 legs), a partial trip (5 legs).
QUERIES = {
    4: (("N:10", "S:10"), ("S:10", "N:10")),
    5: (("A:10", "C:6"), ("C:12", "A:3")),
    8: (("L1:10", "L5:12"), ("L5:12", "L1:10")),
}


def _track(k: int) -> StarGraph:
    angles = ANGLES.get(k)
    return StarGraph(
        dict(zip(NAMES[k], LENGTHS[k], strict=True)),
        angles_deg=None if angles is None else dict(zip(NAMES[k], angles, strict=True)),
    )


def _route(k: int):
    start, goal = QUERIES[k]
    return plan(_track(k), conf(*start), conf(*goal), min_separation=1.5)


def _toml(k: int) -> str:
    """A scenario file of the k-leg query (examples/swap.toml with k legs)."""
    names, lengths = NAMES[k], LENGTHS[k]
    angles = ANGLES.get(k, tuple((90.0 + 360.0 * j / k) % 360.0 for j in range(k)))
    legs = ", ".join(f"{n} = {length!r}" for n, length in zip(names, lengths, strict=True))
    directions = ", ".join(f"{n} = {a!r}" for n, a in zip(names, angles, strict=True))
    (start1, start2), (goal1, goal2) = QUERIES[k]
    vehicles = "".join(
        f'\n[[vehicle]]\nname = "agv{v}"\nmax_velocity = 1.0\nmax_acceleration = 0.5\nmax_jerk = 1.0\n'
        f'start = "{start}"\ngoal = "{goal}"\n'
        for v, start, goal in ((1, start1, goal1), (2, start2, goal2))
    )
    return (
        f"[track]\nlegs = {{ {legs} }}\nangles_deg = {{ {directions} }}\n\n"
        f"[safety]\nmin_separation = 1.5\n{vehicles}"
    )


@pytest.fixture(scope="module", params=[4, 5, 8], ids=lambda k: f"{k}-legs")
def timed(request):
    """(k, verified exact schedule) of the k-leg query."""
    k = request.param
    return k, certify(make_schedule(_route(k), LIMITS, method=Exact()))


def _frames(gif: bytes) -> list[np.ndarray]:
    image = Image.open(io.BytesIO(gif))
    frames = []
    for k in range(image.n_frames):
        image.seek(k)
        frames.append(np.asarray(image.convert("RGB")).astype(int))
    return frames


def _near(pixel: np.ndarray, colour: str, tolerance: int = 12) -> bool:
    return bool(np.abs(pixel - np.round(np.array(to_rgb(colour)) * 255)).max() <= tolerance)


# -- the animation on a track of k legs ---------------------------------------------------------------
def test_the_gif_of_a_k_leg_schedule_decodes_and_shows_the_start_and_the_goal(timed):
    k, verified = timed
    route = verified.schedule.route
    gif = animation_gif(verified, names=("agv1", "agv2"), max_frames=12)
    play = playback(verified.schedule.duration, max_frames=12)
    image = Image.open(io.BytesIO(gif))
    assert image.format == "GIF"
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
    assert image.n_frames == play.frame_count <= 12
    geometry = frame_geometry(verified, play.times())
    layout = frame_layout(route.graph, geometry)
    frames = _frames(gif)
    for frame, here in ((frames[0], route.start), (frames[-1], route.goal)):
        for vehicle in range(2):
            column, row = layout.track_pixel(*route.graph.xy(here[vehicle]))
            assert _near(frame[round(float(row)), round(float(column))], VEHICLE_COLOURS[vehicle]), (k, here)


@pytest.mark.parametrize("fraction", [0.0, 0.2, 0.45, 0.5, 0.8, 1.0])
def test_frame_positions_are_the_schedules_positions_on_the_k_leg_track(timed, fraction):
    _, verified = timed
    graph = verified.schedule.route.graph
    t = fraction * verified.schedule.duration
    geometry = frame_geometry(verified, [t])
    configuration = verified.schedule.configuration_at(t)
    for vehicle in range(2):
        position = configuration[vehicle]
        angle = 0.0 if position.leg is None else math.radians(graph.angles_deg[graph.index(position.leg)])
        assert geometry.x[vehicle, 0] == pytest.approx(position.s * math.cos(angle), abs=1e-9)
        assert geometry.y[vehicle, 0] == pytest.approx(position.s * math.sin(angle), abs=1e-9)
    assert geometry.distance[0] == pytest.approx(graph.separation(configuration), abs=1e-9)


def test_every_leg_is_in_the_frame_to_scale(timed):
    _, verified = timed
    graph = verified.schedule.route.graph
    geometry = frame_geometry(verified, [0.0])
    layout = frame_layout(graph, geometry)
    left, bottom, width, height = layout.track_box
    across = (layout.track_xlim[1] - layout.track_xlim[0]) / width
    up = (layout.track_ylim[1] - layout.track_ylim[0]) / height
    assert across == pytest.approx(up)  # a metre is as many pixels across as up
    for name in graph.names:
        column, row = layout.track_pixel(*graph.xy(graph.endpoint(name)))
        assert left < column < left + width
        assert FRAME_HEIGHT_PX - bottom - height < row < FRAME_HEIGHT_PX - bottom


# -- the retract graph G_k drawn as a table --------------------------------------------------------
@pytest.mark.parametrize("k", range(3, 9))
def test_the_layout_draws_k_k_plus_1_vertices_and_2k_k_minus_1_edges(k):
    graph = StarGraph({f"L{j}": 8.0 + j for j in range(k)})
    layout = RetractGraphLayout.of(graph)
    retract = graph.retract_graph
    assert layout.vertices.shape == (k * (k + 1), 2)
    assert len(layout.edges) == 2 * k * (k - 1) == len(retract.edges)
    assert len({tuple(p) for p in layout.vertices}) == k * (k + 1)  # no two vertices drawn at one place
    for v, (l1, _, l2, _) in enumerate(retract.vertices):  # the table: vehicle 1's row, vehicle 2's column
        assert tuple(layout.vertices[v]) == (l2 + 1.0, -(l1 + 1.0))
        assert (l1 == JUNCTION_INDEX) == (layout.vertices[v][1] == 0.0)
        assert (l2 == JUNCTION_INDEX) == (layout.vertices[v][0] == 0.0)
    for e, (peak, valley) in enumerate(layout.edges):
        assert layout.edges[e] == retract.edges[e]
        arc = layout.edge_curve(e)
        assert np.allclose(arc[0], layout.vertices[peak])
        assert np.allclose(arc[-1], layout.vertices[valley])
        # an edge stays in its row or column band and passes no other vertex
        chord = layout.vertices[valley] - layout.vertices[peak]
        assert 0 in chord
        inner = layout.edge_point(e, np.linspace(0.02, 0.98, 400))
        others = np.delete(layout.vertices, [peak, valley], axis=0)
        gaps = np.hypot(*(inner[:, None, :] - others[None, :, :]).transpose(2, 0, 1))
        assert gaps.min() > 0.09
        bow = np.abs(inner - layout.vertices[peak])[:, 1 if chord[1] == 0 else 0].max()
        assert 0.0 < bow <= BOW + 1e-12


@pytest.mark.parametrize("k", [4, 8])
def test_arcs_from_one_valley_never_cross(k):
    graph = StarGraph({f"L{j}": 10.0 for j in range(k)})
    layout = RetractGraphLayout.of(graph)
    by_valley: dict[int, list[int]] = {}
    for e, (_, valley) in enumerate(layout.edges):
        by_valley.setdefault(valley, []).append(e)
    for valley, edges in by_valley.items():
        assert len(edges) == k - 1
        for a, b in itertools.combinations(edges, 2):
            # scaled copies about the valley: a ray from it meets the shorter arc nearer
            arc_a = layout.edge_point(a, np.linspace(0.0, 0.999, 300)) - layout.vertices[valley]
            arc_b = layout.edge_point(b, np.linspace(0.0, 0.999, 300)) - layout.vertices[valley]
            ratio = np.hypot(*arc_b.T) / np.hypot(*arc_a.T)
            cross = arc_a[:, 0] * arc_b[:, 1] - arc_a[:, 1] * arc_b[:, 0]
            assert np.allclose(cross, 0.0, atol=1e-9)  # same direction seen from the valley, point by point
            assert np.allclose(ratio, ratio[0])
            assert not math.isclose(ratio[0], 1.0)


def _tied_route():
    """A route where two shortest routes tie (rule 2): the start half way (perturbed) between two ways."""
    graph = StarGraph({"N": 10.0, "W": 8.0, "S": 12.0, "E": 9.0})
    retract = graph.retract_graph
    for e, (peak, valley) in enumerate(retract.edges):
        length, perturbed = retract.edge_lengths[e], retract.perturbed_lengths[e]
        for goal in range(len(retract.vertices)):
            via_peak, via_valley = retract.distances[peak][goal], retract.distances[valley][goal]
            offset = (perturbed + via_valley - via_peak) / (2.0 * perturbed / length)
            if not 0.5 < offset < length - 0.5:
                continue
            l1, s1, l2, s2 = retract.vertices[peak]
            c = (l1, s1, l2, s2 - offset) if e % 2 else (l1, s1 - offset, l2, s2)
            route = plan(graph, graph.configuration(c), retract.vertex_configurations[goal])
            if route.instruction is Instruction.TWO_TIED:
                return route
    raise AssertionError("no tie found")  # pragma: no cover


def _crossing() -> StarGraph:
    return StarGraph({"N": 10.0, "W": 8.0, "S": 12.0, "E": 9.0})


ROUTES = {
    "swap-4": lambda: _route(4),
    "partial-5": lambda: _route(5),
    "swap-8": lambda: _route(8),
    "from-a-shared-leg": lambda: plan(
        _crossing(), conf("N:3", "N:7"), conf("S:6", "E:4"), min_separation=1.5
    ),
    "to-a-shared-leg": lambda: plan(_crossing(), conf("W:2", "S:9"), conf("S:11", "S:4"), min_separation=1.5),
    "from-the-junction": lambda: plan(_crossing(), conf("O", "W:5"), conf("E:3", "N:9"), min_separation=1.5),
    "inside-to-inside": lambda: plan(_crossing(), conf("N:6", "W:2"), conf("E:7", "N:3"), min_separation=1.5),
    "other-class": lambda: plan(
        _crossing(), conf("N:10", "S:12"), conf("S:12", "N:10"), min_separation=1.5, homotopy="other"
    ),
    "two-tied": _tied_route,
    "no-motion-on-G": lambda: plan(_crossing(), conf("N:4", "S:12"), conf("N:9", "S:12")),
}


@pytest.mark.parametrize("make", ROUTES.values(), ids=ROUTES.keys())
def test_the_drawn_route_passes_the_routes_vertices_of_g_k_in_order(make):
    route = make()
    graph = route.graph
    retract = graph.retract_graph
    layout = RetractGraphLayout.of(graph)
    points = route_points(route)
    # from the start's retraction to the goal's, through the vertices the three rules chose
    origin = retract.locate(retract_indexed(route.indexed_waypoints[0], graph.lengths)[-1])
    target = retract.locate(retract_indexed(route.indexed_waypoints[-1], graph.lengths)[-1])
    assert points[0] == origin
    assert points[-1] == target
    chosen = retract.shortest(origin, target)
    if route.homotopy.value == "other":
        chosen = retract.second_shortest(origin, target, chosen)
    vertices = [p.vertex for p in points if p.vertex >= 0]
    assert vertices == list(chosen.vertices)
    assert all(p.vertex >= 0 for p in points[1:-1])
    # the drawn line: from the start's point, through each vertex in order, to the goal's
    line = layout.path(points)
    assert np.allclose(line[0], layout.point(origin))
    assert np.allclose(line[-1], layout.point(target))
    after = 0
    for v in vertices:
        hits = np.flatnonzero(np.hypot(*(line[after:] - layout.vertices[v]).T) < 1e-12)
        assert hits.size, (v, vertices)
        after += int(hits[0])
    # and along the arcs: consecutive points of the line are close (no jumps across the table)
    assert np.hypot(*np.diff(line, axis=0).T).max() < 0.4


def test_a_point_inside_an_edge_is_drawn_its_share_of_the_way_along():
    route = ROUTES["partial-5"]()
    layout = RetractGraphLayout.of(route.graph)
    start = route_points(route)[0]  # vehicle 1 at the end of A, vehicle 2 at C:6 of 12 m
    assert start.vertex < 0
    assert start.offset == pytest.approx(6.0)
    peak, valley = (layout.vertices[v] for v in layout.edges[start.edge])
    drawn = layout.point(start)
    assert drawn[0] == pytest.approx(0.5 * (peak[0] + valley[0]))  # half way along the row


@pytest.mark.parametrize("k", [4, 8])
def test_the_schedules_path_retracts_onto_the_routes_edges(k):
    verified = certify(make_schedule(_route(k), LIMITS, method=Exact()))
    route = verified.schedule.route
    layout = RetractGraphLayout.of(route.graph)
    points = route_points(route)

    def edges_of(p):
        return {p.edge} if p.vertex < 0 else {e for e, pair in enumerate(layout.edges) if p.vertex in pair}

    used = set()
    for a, b in itertools.pairwise(points):
        used |= edges_of(a) & edges_of(b)
    retracted = schedule_points(verified, count=500)
    assert len(retracted) == 500
    for p in retracted:
        if p.vertex < 0:
            assert p.edge in used
        else:
            assert any(p.vertex in layout.edges[e] for e in used)


def test_the_titles_name_the_class_and_the_rule_that_chose_the_route():
    y_route = plan(YGraph({"A": 10.0, "B": 10.0, "C": 10.0}), conf("A:10", "B:10"), conf("B:10", "A:10"))
    assert class_name(y_route) == y_route.way_round.value == "counterclockwise"  # the animation's, as before
    shortest, tied, other = _route(4), _tied_route(), ROUTES["other-class"]()
    assert set(RULE_WORDS) == set(Instruction.of_track(shortest.graph))
    assert shortest.instruction is Instruction.SHORTEST
    assert instruction_text(shortest) == f"the planner's instruction: {RULE_WORDS[Instruction.SHORTEST]}"
    assert "rule 1" in instruction_text(shortest)
    assert tied.instruction is Instruction.TWO_TIED
    assert "rule 2, two shortest routes tie" in instruction_text(tied)
    assert instruction_text(other).endswith("this route is the next shortest")
    for route in (shortest, tied, other):  # no circle to go round on G_k
        for text in (class_name(route), class_label(route), instruction_text(route)):
            assert "G_4" in text or "rule" in text
            assert "circle" not in text
            assert "clockwise" not in text


@pytest.mark.parametrize("k", [4, 8])
def test_render_configuration_of_a_k_leg_route_and_schedule(k):
    route = _route(k)
    verified = certify(make_schedule(route, LIMITS, method=Exact()))
    for subject in (route, verified):
        png = configuration_png(subject, names=("agv1", "agv2"))
        assert png == retract_graph_png(subject, names=("agv1", "agv2"))
        image = Image.open(io.BytesIO(png))
        assert image.format == "PNG"
        assert image.size[0] > 800
        assert image.size[1] > 900
    with pytest.raises(UnverifiedScheduleError, match="plot_configuration takes a VerifiedSchedule"):
        configuration_png(verified.schedule)
    with pytest.raises(InputError, match="names must be two strings"):
        configuration_png(route, names=("only one",))
    with pytest.raises(InputError, match=r"needs a YGraph .*retract graph"):
        ConfigurationLayout.of(route.graph)


# -- the command line -------------------------------------------------------------------------------------
@pytest.mark.parametrize("k", [4, 8])
def test_schedule_plot_and_animate_on_k_legs(tmp_path, capsys, k):
    scenario = tmp_path / f"legs{k}.toml"
    scenario.write_text(_toml(k), encoding="utf-8")
    assert load_scenario(scenario).track.leg_count == k
    plots = tmp_path / "plots"
    assert main(["schedule", str(scenario), "--method", "exact", "--plot", str(plots)]) == EXIT_OK
    assert sorted(p.name for p in plots.iterdir()) == sorted(PLOT_NAMES)
    for name in PLOT_NAMES:
        Image.open(plots / name).verify()
    out = tmp_path / "movie.gif"
    argv = [
        "animate",
        str(scenario),
        "--out",
        str(out),
        "--method",
        "exact",
        "--max-frames",
        "10",
        "--fps",
        "5",
    ]
    assert main(argv) == EXIT_OK
    capsys.readouterr()
    image = Image.open(out)
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
    assert 2 <= image.n_frames <= 10
