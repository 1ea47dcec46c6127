"""The pictures people look at: the animation (GIF), the layout and the configuration space drawn (PNG).

On junctions of 3 to 8 legs: the configuration space of a Y is drawn flat (its regions and
boundary circle), that of a star of 4 to 8 legs as its retract graph ``G_k`` in a table. A test
of a picture every junction has is parametrized over the number of legs (``legs3`` the demo swap,
``legs4`` ... ``legs8`` a query on a star of that many legs). The layout (``layout.png``) runs over
the table of cases (:mod:`tests.support.cases`); track graphs add the too-close region against the
track's own distances, the layout's geometry and the route plot (``trajgen plan --plot``).
"""

from __future__ import annotations

import functools
import io
import itertools
import math
import re

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.path import Path as PolygonPath
from PIL import Image

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from tests.support.cases import case
from tests.support.fleets import FLEETS, SEPARATION, one_at_a_time
from tests.support.graph_cases import EXAMPLES
from tests.support.helpers import LIMITS, animation_gif, conf, legs_cases, legs_id, route_of
from topology import JUNCTION_INDEX, EdgePoint, Instruction, StarGraph, TrackGraph, YGraph, plan, plan_graph
from topology.cycle import retract_indexed
from topology.indexed import segment_region_key
from trajgen import Exact, certify, default_scenario, load_scenario, make_schedule
from trajgen.cli import EXIT_BAD_INPUT, EXIT_OK, main
from trajgen.errors import InputError, OptionError, UnverifiedScheduleError
from trajgen.model.graph_cells import too_close_polygons
from trajgen.model.summary import class_label, class_name
from trajgen.pipeline import JUNCTION_PLOT_NAMES, PLOT_NAMES, Outputs, run
from trajgen.plots import animate, plot_configuration, plot_coordination, plot_separation, png_bytes
from trajgen.plots.animation_layout import (
    DEFAULT_MAX_FRAMES,
    END_HOLD_MS,
    FRAME_HEIGHT_PX,
    FRAME_WIDTH_PX,
    clock_text,
    distance_text,
    frame_geometry,
    frame_layout,
    playback,
    speed_text,
)
from trajgen.plots.configuration_layout import ConfigurationLayout, route_samples, schedule_samples
from trajgen.plots.gif import gif_bytes
from trajgen.plots.graph_route import plot_graph_route
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
from trajgen.plots.track_layout import TrackLayout


def configuration_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_configuration(...)``."""
    return png_bytes(plot_configuration(*arguments, **options))


def retract_graph_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_retract_graph(...)``."""
    return png_bytes(plot_retract_graph(*arguments, **options))


SWAP = str(REPO / "examples" / "swap.toml")

# -- the queries: the demo swap, and queries on stars of 4, 5 and 8 legs ---------------------------------

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


def scenario_file(tmp_path, legs: int) -> str:
    """The scenario file of the query of ``legs`` legs: examples/swap.toml, or the k-leg query's."""
    if legs == 3:
        return SWAP
    path = tmp_path / f"legs{legs}.toml"
    path.write_text(_toml(legs), encoding="utf-8")
    assert load_scenario(path).track.leg_count == legs
    return str(path)


@functools.cache
def timed(legs: int):
    """The verified exact schedule of the query of ``legs`` legs: the demo swap, or the k-leg query."""
    if legs == 3:
        return case("y").verified("exact")
    return certify(make_schedule(_route(legs), LIMITS, method=Exact()))


#: Frames of the animations checked pixel by pixel: the demo swap's 80, a k-leg query's 12.
MAX_FRAMES = {3: 80, 4: 12, 5: 12, 8: 12}


@functools.cache
def animation(legs: int) -> bytes:
    """The GIF of :func:`timed`'s schedule of ``legs`` legs, at most :data:`MAX_FRAMES` frames."""
    return animation_gif(timed(legs), names=("agv1", "agv2"), max_frames=MAX_FRAMES[legs])


# -- helpers -----------------------------------------------------------------
def _frames(gif: bytes) -> list[np.ndarray]:
    image = Image.open(io.BytesIO(gif))
    frames = []
    for k in range(image.n_frames):
        image.seek(k)
        frames.append(np.asarray(image.convert("RGB")).astype(int))
    return frames


def _rgb(colour: str) -> np.ndarray:
    return np.round(np.array(to_rgb(colour)) * 255).astype(int)


def _pixel(frame: np.ndarray, column: float, row: float) -> np.ndarray:
    return frame[round(float(row)), round(float(column))]


def _near(pixel: np.ndarray, colour: str, tolerance: int = 12) -> bool:
    return bool(np.abs(pixel - _rgb(colour)).max() <= tolerance)


def _segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    along = np.clip((point - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return float(np.hypot(*(point - a - along * (b - a))))


def _distance_to_outline(point: np.ndarray, polygon: np.ndarray) -> float:
    return min(
        _segment_distance(point, a, b) for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True)
    )


def _inside(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Even-odd rule."""
    inside = False
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        if (a[1] > point[1]) != (b[1] > point[1]):
            cross = a[0] + (point[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            inside ^= bool(point[0] < cross)
    return inside


def _in_region(point: np.ndarray, polygon: np.ndarray) -> bool:
    return _inside(point, polygon) or _distance_to_outline(point, polygon) < 1e-9


# -- the swap of examples/swap.toml, timed by exact (fast), rendered once -------------------------
@pytest.fixture(scope="module")
def swap():
    return case("y").scenario(), case("y").verified("exact")


@pytest.fixture(scope="module")
def swap_gif():
    return animation(3)


# -- playback ----------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("duration", "fps", "max_frames", "speedup", "frames"),
    [
        pytest.param(0.0, 10, 300, 1.0, 1, id="zero-duration"),
        pytest.param(27.5, 10, 300, 1.0, 276, id="swap-real-time"),
        pytest.param(100.0, 10, 300, 4.0, 251, id="100s-x4"),
        pytest.param(67.5, 10, 80, 1.0 * 10, 69, id="exact-swap-x10"),
        pytest.param(86_400.0, 10, 300, 3000.0, 289, id="a-day-x3000"),
        pytest.param(10.0, 25, 2, 300.0, 2, id="two-frames"),
    ],
)
def test_playback_caps_the_frames_with_a_round_speedup(duration, fps, max_frames, speedup, frames):
    play = playback(duration, fps=fps, max_frames=max_frames)
    assert play.speedup == speedup
    assert play.frame_count == frames <= max_frames
    times = play.times()
    assert times.shape == (frames,)
    assert times[0] == 0.0
    assert times[-1] == duration
    assert np.allclose(np.diff(times)[:-1], play.step)  # the last step ends at the goal
    assert np.all(np.diff(times) > 0.0)
    assert play.label == ("real time" if speedup == 1.0 else f"×{speedup:g} speed")


@pytest.mark.parametrize(
    ("options", "match"),
    [
        pytest.param({"fps": 0}, "fps .* from 1 to 50, got 0", id="fps-0"),
        pytest.param({"fps": 51}, "fps .* got 51", id="fps-51"),
        pytest.param({"fps": 2.5}, "fps .* got 2.5", id="fps-float"),
        pytest.param({"fps": True}, "fps .* got True", id="fps-bool"),
        pytest.param({"max_frames": 1}, "max_frames must be an integer from 2 to 3000, got 1", id="frames-1"),
        pytest.param({"max_frames": 3001}, "max_frames .* got 3001", id="frames-3001"),
    ],
)
def test_playback_refuses_bad_options(options, match):
    with pytest.raises(OptionError, match=match):
        playback(10.0, **options)


# -- the animation's geometry and its pixels -----------------------------------------------------------
def test_the_gif_decodes_with_its_frames_size_and_delays(swap, swap_gif):
    _, verified = swap
    play = playback(verified.schedule.duration, max_frames=80)
    image = Image.open(io.BytesIO(swap_gif))
    assert image.format == "GIF"
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
    assert image.n_frames == play.frame_count <= 80
    assert play.label == "×10 speed"
    delays = []
    for k in range(image.n_frames):
        image.seek(k)
        delays.append(image.info["duration"])
    assert delays[:-1] == [play.delay_ms] * (image.n_frames - 1)
    assert delays[-1] == END_HOLD_MS


@pytest.mark.parametrize("legs", legs_cases(sorted(MAX_FRAMES), slow={4, 5, 8}))
def test_the_first_frame_shows_the_start_and_the_last_the_goal(legs):
    verified = timed(legs)
    route = verified.schedule.route
    graph = route.graph
    gif = animation(legs)
    play = playback(verified.schedule.duration, max_frames=MAX_FRAMES[legs])
    image = Image.open(io.BytesIO(gif))
    assert image.format == "GIF"
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
    assert image.n_frames == play.frame_count <= MAX_FRAMES[legs]
    layout = frame_layout(verified.schedule.track, frame_geometry(verified, play.times()))
    frames = _frames(gif)
    swap = route.goal == route.start.swapped()
    for frame, here, there in ((frames[0], route.start, route.goal), (frames[-1], route.goal, route.start)):
        for vehicle in range(2):
            column, row = layout.track_pixel(*graph.xy(here[vehicle]))
            assert _near(_pixel(frame, column, row), VEHICLE_COLOURS[vehicle]), here
            if swap:  # where this vehicle is at the other end the other vehicle is now
                column, row = layout.track_pixel(*graph.xy(there[vehicle]))
                assert _near(_pixel(frame, column, row), VEHICLE_COLOURS[1 - vehicle]), there


#: Moments checked, as fractions of the schedule's duration: of the demo swap's 67.5 s at 0, 5, 21.7,
#: 33.75, 50 and 67.5 s; of a k-leg query's at 0, 20, 45, 50, 80 and 100 %.
MOMENTS = {
    3: (0.0, 5.0 / 67.5, 21.7 / 67.5, 33.75 / 67.5, 50.0 / 67.5, 1.0),
    **dict.fromkeys((4, 5, 8), (0.0, 0.2, 0.45, 0.5, 0.8, 1.0)),
}


@pytest.mark.parametrize(
    ("legs", "fraction"),
    [
        pytest.param(
            legs,
            fraction,
            id=f"legs{legs}-{fraction:.0%}",
            marks=pytest.mark.slow if legs in (4, 5, 8) else (),
        )
        for legs, fractions in MOMENTS.items()
        for fraction in fractions
    ],
)
def test_frame_positions_are_the_schedules_positions(legs, fraction):
    verified = timed(legs)
    graph = verified.schedule.route.graph
    t = fraction * verified.schedule.duration
    geometry = frame_geometry(verified, [t])
    configuration = verified.schedule.configuration_at(t)
    for vehicle in range(2):
        position = configuration[vehicle]
        x, y = graph.xy(position)
        assert geometry.x[vehicle, 0] == pytest.approx(x, abs=1e-9)
        assert geometry.y[vehicle, 0] == pytest.approx(y, abs=1e-9)
        # and by the leg's angle, independently of the track's layout
        angle = 0.0 if position.leg is None else math.radians(graph.angles_deg[graph.index(position.leg)])
        assert geometry.x[vehicle, 0] == pytest.approx(position.s * math.cos(angle), abs=1e-9)
        assert geometry.y[vehicle, 0] == pytest.approx(position.s * math.sin(angle), abs=1e-9)
    assert geometry.distance[0] == pytest.approx(graph.separation(configuration), abs=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("legs", [4, 5, 8], ids=legs_id)
def test_every_leg_is_in_the_frame_to_scale(legs):
    verified = timed(legs)
    graph = verified.schedule.route.graph
    geometry = frame_geometry(verified, [0.0])
    layout = frame_layout(verified.schedule.track, geometry)
    left, bottom, width, height = layout.track_box
    across = (layout.track_xlim[1] - layout.track_xlim[0]) / width
    up = (layout.track_ylim[1] - layout.track_ylim[0]) / height
    assert across == pytest.approx(up)  # a metre is as many pixels across as up
    for name in graph.names:
        column, row = layout.track_pixel(*graph.xy(graph.endpoint(name)))
        assert left < column < left + width
        assert FRAME_HEIGHT_PX - bottom - height < row < FRAME_HEIGHT_PX - bottom


def test_the_separation_bar_is_the_track_distance_long(swap, swap_gif):
    scenario, verified = swap
    play = playback(verified.schedule.duration, max_frames=80)
    geometry = frame_geometry(verified, play.times())
    layout = frame_layout(verified.schedule.track, geometry)
    frames = _frames(swap_gif)
    for k in (0, len(frames) // 3, len(frames) // 2, len(frames) - 1):
        end = layout.bar_pixel(geometry.distance[k])
        assert _near(_pixel(frames[k], end - 4, layout.bar_row), "tab:green"), k
        assert _near(_pixel(frames[k], end + 4, layout.bar_row), "white"), k
        assert geometry.distance[k] == pytest.approx(
            scenario.track.separation(verified.schedule.configuration_at(geometry.t[k])), abs=1e-9
        )
    assert geometry.distance[0] == pytest.approx(20.0)
    assert not geometry.near.any()  # exact moves one vehicle at a time: never closer than 10 m


def test_the_separation_bar_is_red_near_the_minimum():
    # both on leg A, 1.6 m apart (under 1.25 x 1.5 m): the nearer one drives out first
    route = route_of((10.0, 10.0, 10.0), ("A:3", "A:4.6"), ("B:5", "C:5"))
    verified = certify(make_schedule(route, LIMITS, method=Exact()))
    gif = animation_gif(verified, max_frames=6)
    play = playback(verified.schedule.duration, max_frames=6)
    geometry = frame_geometry(verified, play.times())
    layout = frame_layout(verified.schedule.track, geometry)
    first = _frames(gif)[0]
    end = layout.bar_pixel(geometry.distance[0])
    assert geometry.distance[0] == pytest.approx(1.6)
    assert geometry.near[0]
    assert _near(_pixel(first, end - 4, layout.bar_row), "tab:red")
    assert _near(_pixel(first, end + 4, layout.bar_row), "white")
    assert _near(_pixel(first, layout.bar_pixel(0.5), layout.bar_row), "tab:red")


def test_the_texts_of_a_frame(swap):
    _, verified = swap
    duration = verified.schedule.duration
    geometry = frame_geometry(verified, [0.0, duration])
    assert clock_text(geometry.t[0], duration) == "t = 0.0 s of 67.5 s"
    assert clock_text(geometry.t[1], duration) == "t = 67.5 s of 67.5 s"
    assert clock_text(12.34, 27.51) == "t = 12.3 s of 27.5 s"
    assert speed_text("agv1", float(geometry.speed[0, 0])) == "agv1  0.00 m/s"
    assert speed_text("agv2", 0.8449) == "agv2  0.84 m/s"
    assert distance_text(12.345, 1.5) == "12.35 m (minimum 1.5 m)"


def test_a_long_schedule_is_played_faster_within_the_frame_cap():
    route = route_of((1000.0, 800.0, 1500.0), ("A:1000", "B:800"), ("B:800", "A:1000"))
    verified = certify(make_schedule(route, LIMITS, method=Exact()))
    play = playback(verified.schedule.duration, fps=10, max_frames=30)
    assert verified.schedule.duration > 5000.0
    assert play.speedup >= verified.schedule.duration / 2.9
    gif = animation_gif(verified, names=("a", "b"), fps=10, max_frames=30)
    image = Image.open(io.BytesIO(gif))
    assert image.n_frames == play.frame_count <= 30
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)


def test_a_zero_duration_schedule_is_one_frame():
    route = route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("A:10", "B:10"))
    verified = certify(make_schedule(route, LIMITS, method=Exact()))
    assert verified.schedule.duration == 0.0
    image = Image.open(io.BytesIO(animation_gif(verified)))
    assert image.n_frames == 1


@pytest.mark.parametrize(
    ("render", "what"),
    [
        pytest.param(animation_gif, "animate", id="animation"),
        pytest.param(configuration_png, "plot_configuration", id="configuration"),
        pytest.param(lambda s: frame_geometry(s, [0.0]), "frame_geometry", id="geometry"),
    ],
)
def test_unverified_schedules_are_refused(swap, render, what):
    _, verified = swap
    with pytest.raises(UnverifiedScheduleError, match=f"{what} takes a VerifiedSchedule"):
        render(verified.schedule)


def test_the_gif_encoder_reproduces_its_frames_exactly():
    rng = np.random.default_rng(7)
    colours = rng.integers(0, 256, size=(40, 3), dtype=np.uint8)
    frames = [colours[rng.integers(0, 40, size=(30, 50))] for _ in range(3)]
    frames.append(frames[-1].copy())  # unchanged: kept as it is
    moved = frames[-1].copy()
    moved[10:12, 20:23] = colours[0]
    frames.append(moved)
    gif = gif_bytes(iter(frames), delays_ms=[100, 100, 50, 30, 2000], palette_samples=frames[:1])
    decoded = _frames(gif)
    assert len(decoded) == len(frames)
    for got, want in zip(decoded, frames, strict=True):
        assert np.array_equal(got, want)


# -- the configuration space drawn flat ------------------------------------------------------------------
TRACKS = {
    "equal": YGraph({"A": 10.0, "B": 10.0, "C": 10.0}),
    "unequal": YGraph({"A": 12.0, "B": 8.0, "C": 15.0}),
}


@pytest.mark.parametrize("track", TRACKS.values(), ids=TRACKS.keys())
def test_each_region_is_drawn_as_its_polygon(track):
    layout = ConfigurationLayout.of(track, min_separation=1.5)
    vertices = {str(v): layout.vertices[k] for k, v in enumerate(track.boundary_vertices)}
    names = track.names
    assert len(layout.regions) == 12
    for key in layout.regions:
        polygon = layout.region_polygon(key)
        if key.nearer:  # T(k, r): a triangle from the valley of its ray (vehicle r at O)
            assert polygon.shape == (3, 2)
            end = f"{names[key.first_leg]}:{track.lengths[key.first_leg]:g}"
            valley = f"(O, {end})" if key.nearer == 1 else f"({end}, O)"
            assert np.array_equal(polygon[0], vertices[valley])
        else:  # Q(i, j): the kite origin, V2(i), P(i, j), V1(j)
            i, j = (f"{names[n]}:{track.lengths[n]:g}" for n in (key.first_leg, key.second_leg))
            assert polygon.shape == (4, 2)
            assert np.array_equal(polygon[0], [0.0, 0.0])
            assert np.array_equal(polygon[1], vertices[f"({i}, O)"])
            assert np.array_equal(polygon[2], vertices[f"({i}, {j})"])
            assert np.array_equal(polygon[3], vertices[f"(O, {j})"])
        # no two regions overlap: a point well inside one is inside no other
        centre = polygon.mean(axis=0) if key.nearer else 0.5 * polygon[2]
        assert [other for other in layout.regions if _inside(centre, layout.region_polygon(other))] == [key]


ROUTES = {
    "swap": route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10")),
    "swap-other-way": plan(
        YGraph({"A": 12.0, "B": 8.0, "C": 15.0}),
        conf("A:12", "B:8"),
        conf("B:8", "A:12"),
        min_separation=1.5,
        homotopy="other",
    ),
    "from-a-triangle": route_of((10.0, 8.0, 15.0), ("A:3", "A:7"), ("B:6", "C:4")),
    "to-a-triangle": route_of((10.0, 8.0, 15.0), ("B:2", "C:9"), ("C:12", "C:4")),
    "from-a-ray": route_of((10.0, 8.0, 15.0), ("O", "B:5"), ("C:3", "A:9")),
    "quadrangle-to-quadrangle": route_of((12.0, 8.0, 15.0), ("A:6", "B:2"), ("C:7", "A:3")),
}


@pytest.mark.parametrize("route", ROUTES.values(), ids=ROUTES.keys())
def test_the_route_is_drawn_in_the_regions_it_visits(route):
    layout = ConfigurationLayout.of(route.graph, min_separation=route.min_separation)
    visited = set(route.region_keys)
    checked = 0
    for a, b in itertools.pairwise(route.indexed_waypoints):
        key = segment_region_key(a, b)
        if key is None:
            continue
        assert key in visited
        configurations = _segment(a, b)
        for c in configurations[1:-1]:  # the segment's interior
            assert _in_region(layout.point(c, key), layout.region_polygon(key)), (c, key)
            checked += 1
    assert checked > 0
    # and the polylines drawn pass through every sample, start to goal
    configurations, regions = route_samples(route)
    lines = layout.paths(configurations, regions)
    assert np.allclose(lines[0][0], layout.point(route.indexed_waypoints[0], regions[0]))
    assert np.allclose(lines[-1][-1], layout.point(route.indexed_waypoints[-1], regions[-1]))


def _segment(a, b, count: int = 9):
    leg1 = a[0] if a[0] != JUNCTION_INDEX else b[0]
    leg2 = a[2] if a[2] != JUNCTION_INDEX else b[2]
    configurations = []
    for f in np.linspace(0.0, 1.0, count):
        s1, s2 = a[1] + f * (b[1] - a[1]), a[3] + f * (b[3] - a[3])
        configurations.append(
            (leg1 if s1 > 0 else JUNCTION_INDEX, s1, leg2 if s2 > 0 else JUNCTION_INDEX, s2)
        )
    return configurations


def _random_configurations(graph: YGraph, count: int, seed: int):
    rng = np.random.default_rng(seed)
    found = []
    while len(found) < count:
        legs = rng.integers(-1, 3, size=2)
        s = [
            0.0 if leg == JUNCTION_INDEX else float(rng.uniform(0.01, 1.0) * graph.lengths[leg])
            for leg in legs
        ]
        c = (int(legs[0]), s[0], int(legs[1]), s[1])
        if (c[0] == c[2] == JUNCTION_INDEX) or (c[0] == c[2] and c[1] == c[3]):
            continue
        found.append(c)
    return found


@pytest.mark.parametrize("track", TRACKS.values(), ids=TRACKS.keys())
def test_the_retraction_lies_on_the_boundary_circle(track):
    layout = ConfigurationLayout.of(track)
    star = layout.vertices
    on_circle = 0
    for c in _random_configurations(track, 300, seed=11):
        image = layout.boundary_image(c)
        assert _distance_to_outline(image, star) < 1e-9
        trace = layout.retraction(c)
        assert np.allclose(trace[-1], image)
        assert np.allclose(trace[0], layout.point(c))
        if c[0] != c[2] and JUNCTION_INDEX not in (c[0], c[2]):  # a quadrangle: straight out from the centre
            point = layout.base_point(c)
            m = max(c[1] / track.lengths[c[0]], c[3] / track.lengths[c[2]])
            assert np.allclose(point, m * image)
            on_circle += m == 1.0
    assert on_circle == 0  # the random points were inside


@pytest.mark.parametrize("track", TRACKS.values(), ids=TRACKS.keys())
def test_antipodal_boundary_points_are_drawn_opposite(track):
    layout = ConfigurationLayout.of(track)
    half = 0.5 * track.perimeter
    for theta in np.linspace(0.0, track.perimeter, 61):
        assert np.allclose(layout.boundary_point(theta + half), -layout.boundary_point(theta), atol=1e-12)
    # r(c) and r(swap(c)) are half a perimeter apart, so drawn opposite
    for c in _random_configurations(track, 200, seed=5):
        swapped = (c[2], c[3], c[0], c[1])
        assert np.allclose(layout.boundary_image(swapped), -layout.boundary_image(c), atol=1e-12)
    # the swap: start and goal (peaks, vehicles exchanged) opposite, the route half way round
    route = ROUTES["swap-other-way"]
    swap_layout = ConfigurationLayout.of(route.graph)
    start, goal = (swap_layout.point(c) for c in (route.indexed_waypoints[0], route.indexed_waypoints[-1]))
    assert np.allclose(goal, -start)
    assert abs(route.arc_length) == pytest.approx(0.5 * route.graph.perimeter)


@pytest.mark.parametrize(("separation", "count"), [(0.0, 0), (1.5, 12)])
def test_the_too_close_parts(separation, count):
    track = TRACKS["unequal"]
    layout = ConfigurationLayout.of(track, min_separation=separation)
    polygons = layout.too_close_polygons()
    assert len(polygons) == count
    if count:
        near = [(0, 0.5, 1, 0.4), (2, 3.0, 2, 3.8), (JUNCTION_INDEX, 0.0, 1, 1.0)]
        far = [(0, 6.0, 1, 4.0), (2, 3.0, 2, 9.0)]
        for c in near:
            assert any(_inside(layout.point(c), p) for p in polygons), c
        for c in far:
            assert not any(_inside(layout.point(c), p) for p in polygons), c


def test_the_schedules_path_stays_in_its_class(swap):
    _, verified = swap
    layout = ConfigurationLayout.of(verified.schedule.route.graph, min_separation=1.5)
    configurations, regions = schedule_samples(verified, count=400)
    assert len(configurations) == 400
    keys = set(verified.schedule.route.region_keys)
    for c, region in zip(configurations, regions, strict=True):
        if region is not None and region.nearer == 0 and JUNCTION_INDEX not in (c[0], c[2]):
            assert region in keys
            assert _in_region(layout.point(c), layout.region_polygon(region))


@pytest.mark.parametrize("legs", legs_cases([3, 4, 8], slow={4, 8}))
def test_render_configuration_of_a_route_and_of_a_schedule(legs):
    """A Y's configuration space drawn flat; a star's as ``G_k``, as :func:`plot_retract_graph` draws it."""
    route = ROUTES["from-a-triangle"] if legs == 3 else _route(legs)
    verified = timed(legs)
    names = None if legs == 3 else ("agv1", "agv2")
    for subject in (route, verified):
        png = configuration_png(subject, names=names)
        if legs > 3:
            assert png == retract_graph_png(subject, names=names)
        image = Image.open(io.BytesIO(png))
        assert image.format == "PNG"
        assert image.size[0] > 800
        assert image.size[1] > 900
    for unverified in ("a route", verified.schedule):
        with pytest.raises(UnverifiedScheduleError, match="plot_configuration takes a VerifiedSchedule"):
            configuration_png(unverified)
    with pytest.raises(InputError, match="names must be two strings"):
        configuration_png(route, names=("only one",))
    if legs > 3:
        with pytest.raises(InputError, match=r"needs a YGraph .*retract graph"):
            ConfigurationLayout.of(route.graph)


# -- the retract graph G_k of a star drawn as a table -------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("k", range(3, 9), ids=legs_id)
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


@pytest.mark.slow
@pytest.mark.parametrize("k", [4, 8], ids=legs_id)
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


G_K_ROUTES = {
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


@pytest.mark.slow
@pytest.mark.parametrize("make", G_K_ROUTES.values(), ids=G_K_ROUTES.keys())
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


@pytest.mark.slow
def test_a_point_inside_an_edge_is_drawn_its_share_of_the_way_along():
    route = G_K_ROUTES["partial-5"]()
    layout = RetractGraphLayout.of(route.graph)
    start = route_points(route)[0]  # vehicle 1 at the end of A, vehicle 2 at C:6 of 12 m
    assert start.vertex < 0
    assert start.offset == pytest.approx(6.0)
    peak, valley = (layout.vertices[v] for v in layout.edges[start.edge])
    drawn = layout.point(start)
    assert drawn[0] == pytest.approx(0.5 * (peak[0] + valley[0]))  # half way along the row


@pytest.mark.slow
@pytest.mark.parametrize("k", [4, 8], ids=legs_id)
def test_the_schedules_path_retracts_onto_the_routes_edges(k):
    verified = timed(k)
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


@pytest.mark.slow
def test_the_titles_name_the_class_and_the_rule_that_chose_the_route():
    y_route = plan(YGraph({"A": 10.0, "B": 10.0, "C": 10.0}), conf("A:10", "B:10"), conf("B:10", "A:10"))
    assert class_name(y_route) == y_route.way_round.value == "counterclockwise"  # the animation's, as before
    shortest, tied, other = _route(4), _tied_route(), G_K_ROUTES["other-class"]()
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


# -- the pipeline and the command line -------------------------------------------------------------------
@pytest.mark.parametrize("legs", legs_cases([3, 4, 8], slow={4, 8}))
def test_plot_writes_configuration_png(tmp_path, capsys, legs):
    assert JUNCTION_PLOT_NAMES == ("configuration.png",)
    plots = tmp_path / "plots"
    argv = ["schedule", scenario_file(tmp_path, legs), "--method", "exact", "--plot", str(plots)]
    assert main(argv) == EXIT_OK
    capsys.readouterr()
    data = (plots / "configuration.png").read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    assert sorted(p.name for p in plots.iterdir()) == sorted([*PLOT_NAMES, *JUNCTION_PLOT_NAMES])
    for name in (*PLOT_NAMES, *JUNCTION_PLOT_NAMES):
        Image.open(plots / name).verify()


#: Frames asked of ``trajgen animate``, by number of legs (each exact schedule takes 67.5 s).
ANIMATE_FRAMES = {3: 40, 4: 10, 8: 10}


@pytest.mark.parametrize("legs", legs_cases(sorted(ANIMATE_FRAMES), slow={4, 8}))
def test_animate_writes_the_gif(tmp_path, capsys, legs):
    out = tmp_path / "movie" / f"legs{legs}.gif"
    frames = ANIMATE_FRAMES[legs]
    argv = ["animate", scenario_file(tmp_path, legs), "--out", str(out), "--method", "exact"]
    assert main([*argv, "--max-frames", str(frames), "--fps", "5"]) == EXIT_OK
    stdout = capsys.readouterr().out
    image = Image.open(out)
    assert image.size == (FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
    play = playback(67.5, fps=5, max_frames=frames)
    assert 2 <= image.n_frames == play.frame_count <= frames
    assert f"{play.frame_count} frames" in stdout
    assert play.label in stdout
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]  # no temporary files left


@pytest.mark.parametrize(
    ("out", "extra", "match"),
    [
        pytest.param("movie.png", [], "does not end in .gif", id="not-gif"),
        pytest.param("folder.gif", [], "exists as a folder", id="a-folder"),
        pytest.param("sub/", [], "names no file", id="trailing-slash"),
        pytest.param("file/x.gif", [], "exists and is not a folder", id="below-a-file"),
        pytest.param("ok.gif", ["--fps", "0"], "fps .* from 1 to 50", id="bad-fps"),
        pytest.param("ok.gif", ["--max-frames", "1"], "max_frames .* from 2", id="bad-max-frames"),
        pytest.param(
            "ok.gif", ["--method", "toppra", "--homotopy", "planned"], "--homotopy", id="bad-homotopy"
        ),
    ],
)
def test_animate_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, monkeypatch, out, extra, match):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.gif").mkdir()
    (tmp_path / "file").write_text("a file")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert main(["animate", SWAP, "--out", out, *extra]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith("trajgen: error:")
    assert re.search(match, err), err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_the_default_frame_cap_is_documented():
    assert DEFAULT_MAX_FRAMES == 300
    assert math.isclose(playback(29.9).speedup, 1.0)
    assert playback(30.0).speedup == 2.0


# -- the coordination and speed plots explain themselves --------------------------------------------------


@pytest.fixture(scope="module")
def swap_by_method():
    """The demo swap by every method, verified (optimal parks shallower: other paths, another panel)."""
    from trajgen.methods import METHODS

    scenario = default_scenario()
    route = scenario.route()
    return {cls.name: certify(make_schedule(route, scenario.limits, method=cls())) for cls in METHODS}


def test_the_coordination_plot_draws_the_too_close_region_as_the_diagrams_exact_polygons(swap_by_method):
    from matplotlib.patches import Polygon

    from trajgen.model.coordination import CoordinationDiagram, schedule_paths
    from trajgen.plots import plot_coordination

    exact = swap_by_method["exact"].schedule
    figure = plot_coordination({"exact": swap_by_method["exact"]})
    (axis,) = figure.axes
    drawn = sorted(
        tuple(map(tuple, np.round(p.get_xy()[:-1], 9))) for p in axis.patches if isinstance(p, Polygon)
    )
    paths, times, _ = schedule_paths(exact)
    diagram = CoordinationDiagram(paths, exact.limits.min_separation, exact, times)
    expected = sorted(
        tuple(tuple(np.round(v, 9)) for v in polygon) for c in diagram.conflicts for polygon in c.polygons
    )
    assert drawn == expected
    assert len(drawn) >= 2  # not a raster: one patch per convex piece of each conflict
    assert not axis.collections  # no contour mesh


def test_a_curve_along_the_frame_stays_inside_it(swap_by_method):
    from trajgen.plots import plot_coordination

    (axis,) = plot_coordination({"exact": swap_by_method["exact"]}).axes
    (curve,) = axis.get_lines()
    x, y = curve.get_xdata(), curve.get_ydata()
    (x0, x1), (y0, y1) = axis.get_xlim(), axis.get_ylim()
    # exact waits at 0 and ends at the full travel: both must lie inside the frame, not on it
    assert x0 < x.min()
    assert x.max() < x1
    assert y0 < y.min()
    assert y.max() < y1
    assert curve.get_zorder() > 2


def test_two_panels_say_why_each_has_its_own_axes(swap_by_method):
    from trajgen.plots import plot_coordination

    figure = plot_coordination(swap_by_method)
    assert len(figure.axes) == 2
    why = figure.get_suptitle()
    assert "different paths" in why
    assert "the other class" in why
    assert all("class " in axis.get_title() for axis in figure.axes)
    one = plot_coordination({"exact": swap_by_method["exact"]})
    assert one.get_suptitle() == ""


def test_the_speed_plot_says_what_a_negative_velocity_means(swap_by_method):
    from trajgen.plots import plot_speed

    title = plot_speed(swap_by_method["optimal"], names=("agv1", "agv2")).axes[0].get_title()
    assert "v < 0 is backing out of a side leg" in title


# -- layout.png: every track from above, each vehicle's moves ---------------------------------------------


@pytest.mark.parametrize("name", ["h", "passing-loop", "ring"])
def test_the_moves_of_a_graphs_exact_schedule_are_its_routes_moves(name):
    """Agreement of two computations: the moves read off the states and the planner's moves."""
    from trajgen.plots.layout import schedule_moves

    verified = case(name).verified("exact")
    route = verified.schedule.route
    moves = schedule_moves(verified.schedule)
    assert [m.vehicle for m in moves] == [m.vehicle for m in route.moves]
    assert [m.length for m in moves] == pytest.approx([m.length for m in route.moves], abs=1e-6)
    track = verified.schedule.track
    for drawn, planned in zip(moves, route.moves, strict=True):
        first = EdgePoint(int(drawn.edges[0]), float(drawn.s[0]))
        last = EdgePoint(int(drawn.edges[-1]), float(drawn.s[-1]))
        assert track.distance(first, planned.points[0]) <= 1e-6
        assert track.distance(last, planned.points[-1]) <= 1e-6
        assert drawn.start < drawn.end


def test_the_swaps_moves_in_closed_form():
    """agv2 backs from B through O to the end of C (20 m), agv1 drives A to B (20 m), agv2 C to A (20 m)."""
    from trajgen.plots.layout import schedule_moves

    moves = schedule_moves(case("y").verified("exact").schedule)
    assert [(m.vehicle, round(m.length, 6)) for m in moves] == [(1, 20.0), (0, 20.0), (1, 20.0)]
    assert moves[0].end <= moves[1].start + 1e-9  # one at a time
    assert moves[1].end <= moves[2].start + 1e-9


@pytest.mark.parametrize("method", ["exact", "toppra"])
@pytest.mark.parametrize("name", ["y", "4-leg", "8-leg", "h", "passing-loop", "ring"])
def test_the_layout_of_every_track_draws_each_move_in_its_vehicles_colour(name, method):
    from trajgen.plots import plot_layout
    from trajgen.plots.layout import schedule_moves

    verified = case(name).verified(method)
    figure = plot_layout(verified, names=("agv1", "agv2"))
    axis = figure.axes[0]
    coloured = [line for line in axis.get_lines() if line.get_linewidth() == pytest.approx(2.2)]
    moves = schedule_moves(verified.schedule)
    assert len(coloured) == len(moves) >= 2
    for line, move in zip(coloured, moves, strict=True):
        assert to_rgb(line.get_color()) == to_rgb(VEHICLE_COLOURS[move.vehicle])
    numbers = sorted(int(t.get_text()) for t in axis.texts if t.get_text().isdigit())
    assert numbers == list(range(1, len(moves) + 1))
    assert f"{len(moves)} moves" in axis.get_title()
    legend = [t.get_text() for t in axis.get_legend().get_texts()]
    assert legend == ["agv1 start", "agv1 goal", "agv2 start", "agv2 goal"]


def test_the_layout_refuses_names_that_are_not_one_per_vehicle():
    from trajgen.plots import plot_layout

    with pytest.raises(
        InputError, match=r"plot_layout names must be 2 strings, one per vehicle, got \('a',\)"
    ):
        plot_layout(case("y").verified("exact"), names=("a",))
    with pytest.raises(InputError, match=r"plot_layout names must be 2 strings, one per vehicle, got 'ab'"):
        plot_layout(case("y").verified("exact"), names="ab")  # one name, not two
    with pytest.raises(UnverifiedScheduleError, match="plot_layout"):
        plot_layout(case("y").verified("exact").schedule)


# -- track graphs: the too-close region, the pictures of a run, the layout's geometry, the route plot ------


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


# -- any number of vehicles below the planners ------------------------------------------------------------


def _pairs_that_conflict(schedule, separation: float, step: float = 0.05) -> int:
    """Pairs of vehicles whose paths come closer than the separation anywhere, by sampling both paths."""
    track = schedule.track
    samples = []
    for path in schedule.paths:
        travel = np.linspace(0.0, path.length, max(2, int(path.length / step) + 1))
        samples.append(path.locate(travel))
    count = 0
    for (edge_a, s_a), (edge_b, s_b) in itertools.combinations(samples, 2):
        a, b = np.meshgrid(np.arange(edge_a.size), np.arange(edge_b.size))
        apart = track.distances(edge_a[a.ravel()], s_a[a.ravel()], edge_b[b.ravel()], s_b[b.ravel()])
        count += bool(np.min(apart) < separation - 1e-6)
    return count


@pytest.mark.parametrize("case", FLEETS, ids=lambda case: case.name)
def test_every_picture_of_a_fleet_shows_every_vehicle(case):
    """Speed, layout, coordination (a panel per pair that conflicts) and animation for 3 and 4 vehicles."""
    from trajgen.plots import plot_layout, plot_speed

    verified, names = case.verified("exact"), case.route().names
    toppra = case.verified("toppra")
    speed = plot_speed(verified, names=names)
    for axis in speed.axes[:2]:
        drawn = [line.get_label() for line in axis.get_lines() if not line.get_label().startswith("_")]
        assert [label for label in drawn if label in names] == list(names)
        colours = {to_rgb(line.get_color()) for line in axis.get_lines() if line.get_label() in names}
        assert len(colours) == case.count  # one colour each
    layout = plot_layout(verified, names=names)
    labels = layout.axes[0].get_legend_handles_labels()[1]
    for name in names:
        assert f"{name} start" in labels
        assert f"{name} goal" in labels
    coordination = plot_coordination({"exact": verified, "toppra": toppra})
    expected = _pairs_that_conflict(verified.schedule, SEPARATION)
    assert expected >= 2
    assert len(coordination.axes) == expected
    animation = animate(verified, names=names, max_frames=10)
    frames = list(animation.frames())
    assert len(frames) == animation.frame_count
    geometry = frame_geometry(verified, [0.0, verified.schedule.duration])
    assert geometry.x.shape[0] == case.count


def test_the_coordination_of_a_fleet_with_no_conflict_draws_the_pair_that_comes_closest():
    track = TrackGraph.from_edges({"main": ("W", "E", 100.0)})
    route = one_at_a_time(
        track,
        ("main:10", "main:50", "main:60"),
        ((0, ("main:10", "main:15")), (1, ("main:50", "main:55")), (2, ("main:60", "main:65"))),
        separation=SEPARATION,
        names=("agv1", "agv2", "agv3"),
    )
    limits = Limits((VehicleLimits(1.0, 0.5, 1.0),) * 3, SEPARATION)
    verified = certify(make_schedule(route, limits, method="exact"))
    figure = plot_coordination({"exact": verified})
    (axis,) = figure.axes
    assert (axis.get_xlabel(), axis.get_ylabel()) == ("vehicle 2 travelled [m]", "vehicle 3 travelled [m]")
