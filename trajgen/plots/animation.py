"""The animation: a track of 3 to 8 legs seen from above, both vehicles moving per a schedule, as GIF bytes.

Each frame shows the track to scale, each vehicle at its position (a dot, and
a disc of diameter the minimum separation: on one leg the discs touch exactly
when the vehicles are at the minimum), where each starts (hollow circle) and
ends (hollow square), a clock, each vehicle's speed and, below, the track
distance between the vehicles as a bar against the minimum (red when closer
than :data:`NEAR_FACTOR` times the minimum).

Resources are bounded whatever the duration: at most ``max_frames`` frames
(a long schedule is played faster, by a round speed-up written on every
frame), drawn one at a time into one figure and encoded at once
(:func:`trajgen.plots.gif.gif_bytes`).

The geometry of a frame is computed apart from the drawing
(:func:`playback`, :func:`frame_geometry`, :func:`frame_layout`, the ``*_text``
functions), so it can be checked without looking at pixels.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from topology import JUNCTION_INDEX, StarGraph
from topology.indexed import track_distance
from topology.validation import short_repr
from trajgen.errors import InputError, OptionError
from trajgen.plots.figure import frame_painter, new_figure
from trajgen.plots.gif import GIF_DELAY_UNIT_MS, gif_bytes
from trajgen.plots.speed import VEHICLE_COLOURS
from trajgen.progress import progress
from trajgen.summary import class_name
from trajgen.values import ArrayValue, frozen
from trajgen.verify import VerifiedSchedule, require_verified

__all__ = [
    "DEFAULT_FPS",
    "DEFAULT_MAX_FRAMES",
    "END_HOLD_MS",
    "FRAME_DPI",
    "FRAME_HEIGHT_PX",
    "FRAME_WIDTH_PX",
    "MAX_FPS",
    "MAX_FRAMES_LIMIT",
    "NEAR_FACTOR",
    "FrameGeometry",
    "FrameLayout",
    "Playback",
    "clock_text",
    "distance_text",
    "frame_geometry",
    "frame_layout",
    "playback",
    "render_animation",
    "speed_text",
]

#: Frames shown per second of playback, unless asked otherwise.
DEFAULT_FPS = 10
#: Highest frame rate accepted (GIF delays are whole hundredths of a second; viewers slow faster ones).
MAX_FPS = 50
#: Most frames of an animation, unless asked otherwise: 30 s of playback at 10 frames per second.
DEFAULT_MAX_FRAMES = 300
#: The largest ``max_frames`` accepted.
MAX_FRAMES_LIMIT = 3000
#: How long the last frame (the goal) is held before the animation loops, milliseconds.
END_HOLD_MS = 2000
#: Frame size, pixels, and the resolution it is drawn at, dots per inch.
FRAME_WIDTH_PX = 640
FRAME_HEIGHT_PX = 600
FRAME_DPI = 100
#: The separation bar turns red below this multiple of the minimum separation.
NEAR_FACTOR = 1.25

#: Where the parts sit in the frame: (left, bottom, width, height) as fractions of the frame.
_TRACK_BOX = (0.02, 0.2, 0.96, 0.66)
_BAR_BOX = (0.06, 0.075, 0.88, 0.05)
#: Speed-ups are 1, 2, 3, 4, 5, 6 or 8 times a power of ten.
_ROUND_SPEEDUPS = (1, 2, 3, 4, 5, 6, 8)


def _check_count(value: object, name: str, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        raise OptionError(
            f"animation {name} must be an integer from {low} to {high}, got {short_repr(value)}"
        )
    return int(value)


def _round_speedup(required: float) -> float:
    """The smallest round speed-up (1, 2, 3, 4, 5, 6, 8 times a power of ten) at least ``required``."""
    if required <= 1.0:
        return 1.0
    decade = 10.0 ** math.floor(math.log10(required))
    for digit in (*_ROUND_SPEEDUPS, 10):
        if digit * decade >= required * (1.0 - 1e-12):
            return digit * decade
    return 10.0 * decade  # pragma: no cover (10 * decade >= required always)


@dataclass(frozen=True, slots=True)
class Playback:
    """How a schedule is played: which instants become frames, and how fast.

    Attributes
    ----------
    duration : float
        The schedule's makespan, seconds.
    fps : int
        Frames per second asked for.
    delay_ms : int
        How long each frame is shown, milliseconds (``1000 / fps`` rounded to 10 ms);
        the last frame is held :data:`END_HOLD_MS`.
    speedup : float
        Schedule seconds per second of playback: 1 (real time) unless the
        schedule is too long for ``max_frames`` frames, then the smallest round
        number (2, 3, 4, 5, 6, 8, 10, 20, ...) that fits.
    frame_count : int
        Number of frames, at most ``max_frames`` (1 for a schedule of zero duration).
    """

    duration: float
    fps: int
    delay_ms: int
    speedup: float
    frame_count: int

    @property
    def step(self) -> float:
        """Schedule time between frames, seconds."""
        return self.speedup * self.delay_ms / 1000.0

    def times(self) -> np.ndarray:
        """Schedule time of each frame, seconds, shape (frame_count,): every ``step``, the last at the end."""
        times = np.arange(self.frame_count, dtype=float) * self.step
        times[-1] = self.duration
        return times

    @property
    def label(self) -> str:
        """What the frames say about the speed: ``"real time"`` or e.g. ``"×4 speed"``."""
        return "real time" if self.speedup == 1.0 else f"×{self.speedup:g} speed"


def playback(duration: float, *, fps: int = DEFAULT_FPS, max_frames: int = DEFAULT_MAX_FRAMES) -> Playback:
    """The frames of a ``duration``-second schedule at ``fps`` frames per second, at most ``max_frames``.

    Parameters
    ----------
    duration : float
        Makespan, seconds, finite and >= 0.
    fps : int, optional
        Frames per second of playback, 1 to :data:`MAX_FPS` (default :data:`DEFAULT_FPS`).
    max_frames : int, optional
        Most frames, 2 to :data:`MAX_FRAMES_LIMIT` (default :data:`DEFAULT_MAX_FRAMES`).

    Raises
    ------
    OptionError
        ``fps`` or ``max_frames`` out of range, or a duration that is not a finite number >= 0.

    Examples
    --------
    >>> playback(27.5).frame_count, playback(27.5).label
    (276, 'real time')
    >>> long = playback(100.0)
    >>> long.label, long.frame_count
    ('×4 speed', 251)
    """
    fps = _check_count(fps, "fps (frames per second)", 1, MAX_FPS)
    max_frames = _check_count(max_frames, "max_frames", 2, MAX_FRAMES_LIMIT)
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 0.0 <= duration < math.inf:
        raise OptionError(f"animation duration must be a finite number of seconds >= 0, got {duration!r}")
    delay_ms = GIF_DELAY_UNIT_MS * max(1, round(1000.0 / fps / GIF_DELAY_UNIT_MS))
    played = delay_ms / 1000.0
    speedup = _round_speedup(duration / (played * (max_frames - 1)))
    intervals = math.ceil(duration / (speedup * played) - 1e-9) if duration > 0.0 else 0
    return Playback(float(duration), fps, delay_ms, speedup, intervals + 1)


@dataclass(frozen=True, slots=True, eq=False)
class FrameGeometry(ArrayValue):
    """Where the vehicles are in each frame (read-only arrays).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Schedule time of each frame, seconds.
    x, y : ndarray, shape (2, n)
        Each vehicle's position from above, metres, junction at the origin
        (the legs' directions ``StarGraph.angles_deg``, as in the CSV export).
    velocity : ndarray, shape (2, n)
        Each vehicle's velocity along its signed axis, m/s.
    distance : ndarray, shape (n,)
        Track distance between the vehicles, metres: the length of the separation bar.
    min_separation : float
        The minimum the schedule keeps, metres.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    velocity: np.ndarray
    distance: np.ndarray
    min_separation: float

    def __post_init__(self) -> None:
        for name in ("t", "x", "y", "velocity", "distance"):
            object.__setattr__(self, name, frozen(np.asarray(getattr(self, name), dtype=float)))

    @property
    def speed(self) -> np.ndarray:
        """Each vehicle's speed ``|velocity|``, m/s, shape (2, n)."""
        return np.abs(self.velocity)

    @property
    def near(self) -> np.ndarray:
        """Whether the bar is drawn red: closer than :data:`NEAR_FACTOR` times the minimum; shape (n,)."""
        return self.distance < NEAR_FACTOR * self.min_separation


def frame_geometry(verified: VerifiedSchedule, times) -> FrameGeometry:
    """The vehicles' positions, velocities and track distance at the frames' times.

    Parameters
    ----------
    verified : VerifiedSchedule
    times : array_like, shape (n,)
        Seconds (clipped to the schedule).
    """
    schedule = require_verified(verified, "frame_geometry").schedule
    state = schedule.state(times)
    angles = np.radians(np.array(schedule.route.graph.angles_deg))
    direction = angles[np.where(state.leg == JUNCTION_INDEX, 0, state.leg)]
    return FrameGeometry(
        t=state.t,
        x=state.s * np.cos(direction),
        y=state.s * np.sin(direction),
        velocity=state.velocity,
        distance=track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1]),
        min_separation=max(schedule.limits.min_separation, schedule.route.min_separation),
    )


@dataclass(frozen=True, slots=True)
class FrameLayout:
    """Where the track and the separation bar sit in a frame, in pixels, and their scales.

    Attributes
    ----------
    width, height : int
        Frame size, pixels.
    track_box : (float, float, float, float)
        The track's drawing area: left, bottom, width, height in pixels from the
        frame's bottom-left corner.
    track_xlim, track_ylim : (float, float)
        Metres shown across and up that area: the same metres per pixel both ways (to scale).
    bar_box : (float, float, float, float)
        The separation bar's area, pixels, like ``track_box``.
    bar_xlim : (float, float)
        Metres across the bar's area (0 at its left edge).
    """

    width: int
    height: int
    track_box: tuple[float, float, float, float]
    track_xlim: tuple[float, float]
    track_ylim: tuple[float, float]
    bar_box: tuple[float, float, float, float]
    bar_xlim: tuple[float, float]

    @property
    def metres_per_pixel(self) -> float:
        """The track's scale, metres per pixel (both directions)."""
        return (self.track_xlim[1] - self.track_xlim[0]) / self.track_box[2]

    def track_pixel(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Pixel column and row (from the frame's top-left corner) of positions ``x, y`` in metres."""
        left, bottom, width, height = self.track_box
        column = (
            left + (np.asarray(x) - self.track_xlim[0]) / (self.track_xlim[1] - self.track_xlim[0]) * width
        )
        up = (
            bottom + (np.asarray(y) - self.track_ylim[0]) / (self.track_ylim[1] - self.track_ylim[0]) * height
        )
        return column, self.height - up

    def bar_pixel(self, metres) -> np.ndarray:
        """Pixel column of a length along the separation bar, metres from its left end."""
        left, _, width, _ = self.bar_box
        return left + (np.asarray(metres) - self.bar_xlim[0]) / (self.bar_xlim[1] - self.bar_xlim[0]) * width

    @property
    def bar_row(self) -> float:
        """Pixel row (from the top) of the middle of the separation bar."""
        _, bottom, _, height = self.bar_box
        return self.height - (bottom + 0.5 * height)


def _box(fraction: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    left, bottom, width, height = fraction
    return (left * FRAME_WIDTH_PX, bottom * FRAME_HEIGHT_PX, width * FRAME_WIDTH_PX, height * FRAME_HEIGHT_PX)


def frame_layout(graph: StarGraph, geometry: FrameGeometry) -> FrameLayout:
    """The layout of the frames of ``geometry`` on ``graph``: the whole track to scale, and the bar's range.

    The track area shows every leg with a margin for the labels and the vehicles' discs,
    widened in one direction so that a metre is as many pixels across as up. The bar's
    range is the largest track distance of the frames (at least :data:`NEAR_FACTOR`
    times the minimum), with 5 % to spare.
    """
    angles = np.radians(np.array(graph.angles_deg))
    ends_x = np.append(np.array(graph.lengths) * np.cos(angles), 0.0)
    ends_y = np.append(np.array(graph.lengths) * np.sin(angles), 0.0)
    span = max(float(np.ptp(ends_x)), float(np.ptp(ends_y)), 1e-9)
    margin = 0.14 * span + 0.5 * geometry.min_separation
    xlim = [float(ends_x.min()) - margin, float(ends_x.max()) + margin]
    ylim = [float(ends_y.min()) - margin, float(ends_y.max()) + margin]
    box = _box(_TRACK_BOX)
    per_pixel = max((xlim[1] - xlim[0]) / box[2], (ylim[1] - ylim[0]) / box[3])
    for limits, pixels in ((xlim, box[2]), (ylim, box[3])):
        extra = 0.5 * (per_pixel * pixels - (limits[1] - limits[0]))
        limits[0] -= extra
        limits[1] += extra
    largest = float(geometry.distance.max()) if geometry.distance.size else 0.0
    bar_max = 1.05 * max(largest, NEAR_FACTOR * geometry.min_separation, 1e-9)
    return FrameLayout(
        width=FRAME_WIDTH_PX,
        height=FRAME_HEIGHT_PX,
        track_box=box,
        track_xlim=(xlim[0], xlim[1]),
        track_ylim=(ylim[0], ylim[1]),
        bar_box=_box(_BAR_BOX),
        bar_xlim=(0.0, bar_max),
    )


def clock_text(t: float, duration: float) -> str:
    """The clock of a frame, e.g. ``"t = 12.3 s of 27.5 s"``."""
    return f"t = {t:.1f} s of {duration:.1f} s"


def speed_text(name: str, speed: float) -> str:
    """A vehicle's current speed, e.g. ``"agv1  0.84 m/s"``."""
    return f"{name}  {speed:.2f} m/s"


def distance_text(distance: float, min_separation: float) -> str:
    """The value of the separation bar, e.g. ``"12.35 m (minimum 1.5 m)"``."""
    return f"{distance:.2f} m (minimum {min_separation:g} m)"


def _round_length(target: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) at most ``target``, metres."""
    decade = 10.0 ** math.floor(math.log10(target))
    return max(digit * decade for digit in (1, 2, 5) if digit * decade <= target)


def _free_corners(graph: StarGraph, layout: FrameLayout) -> list[str]:
    """The track area's corners, farthest from the legs first, as legend locations."""
    angles = np.radians(np.array(graph.angles_deg))
    ends = np.stack([np.array(graph.lengths) * np.cos(angles), np.array(graph.lengths) * np.sin(angles)], 1)
    corners = {
        "upper left": (layout.track_xlim[0], layout.track_ylim[1]),
        "upper right": (layout.track_xlim[1], layout.track_ylim[1]),
        "lower left": (layout.track_xlim[0], layout.track_ylim[0]),
        "lower right": (layout.track_xlim[1], layout.track_ylim[0]),
    }

    def clearance(corner) -> float:
        point = np.array(corner)
        along = np.clip((ends @ point) / np.einsum("ij,ij->i", ends, ends), 0.0, 1.0)
        return float(np.min(np.linalg.norm(point - along[:, None] * ends, axis=1)))

    return sorted(corners, key=lambda name: -clearance(corners[name]))


def _widest_gap(angles_deg: Sequence[float]) -> float:
    """The direction halfway across the widest angle between two neighbouring legs, radians."""
    angles = sorted(a % 360.0 for a in angles_deg)
    count = len(angles)
    gaps = [((angles[(k + 1) % count] - angles[k]) % 360.0, k) for k in range(count)]
    width, k = max(gaps)
    return math.radians(angles[k] + 0.5 * width)


def _disc(x: float, y: float, radius: float) -> np.ndarray:
    angle = np.linspace(0.0, 2.0 * np.pi, 48)
    return np.column_stack([x + radius * np.cos(angle), y + radius * np.sin(angle)])


class _Scene:
    """One figure: the still parts drawn once, the moving parts updated and drawn for each frame."""

    def __init__(
        self,
        verified: VerifiedSchedule,
        geometry: FrameGeometry,
        layout: FrameLayout,
        names: tuple[str, str],
        play: Playback,
    ) -> None:
        schedule = verified.schedule
        self.geometry = geometry
        self.names = names
        self.duration = schedule.duration
        figure = new_figure(figsize=(FRAME_WIDTH_PX / FRAME_DPI, FRAME_HEIGHT_PX / FRAME_DPI))
        figure.set_dpi(FRAME_DPI)
        self.figure = figure
        figure.text(
            0.5,
            0.965,
            f"{names[0]} and {names[1]}: {schedule.method.name} schedule, {schedule.duration:.2f} s, "
            f"{class_name(schedule.route)}",
            ha="center",
            va="center",
            fontsize=11,
        )
        self.clock = figure.text(0.03, 0.915, "", ha="left", va="center", fontsize=12, family="monospace")
        figure.text(0.97, 0.915, play.label, ha="right", va="center", fontsize=12, weight="bold")
        self.speeds = [
            figure.text(
                x, 0.875, "", ha=ha, va="center", fontsize=11, color=VEHICLE_COLOURS[v], weight="bold"
            )
            for v, (x, ha) in enumerate(((0.03, "left"), (0.97, "right")))
        ]
        self.vehicles = self._draw_track(schedule.route.graph, layout)
        self.bar, self.minimum, self.bar_value = self._draw_bar(layout)
        moving = [self.clock, *self.speeds]
        for disc, dot, name in self.vehicles:
            moving += [disc, dot, name]
        moving += [self.bar, *self.minimum, self.bar_value]
        self.paint = frame_painter(figure, moving)

    def _axes(self, box: tuple[float, float, float, float]):
        sizes = (FRAME_WIDTH_PX, FRAME_HEIGHT_PX, FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
        return self.figure.add_axes([value / size for value, size in zip(box, sizes, strict=True)])

    def _draw_track(self, graph: StarGraph, layout: FrameLayout) -> list:
        geometry = self.geometry
        axis = self._axes(layout.track_box)
        axis.set_xlim(*layout.track_xlim)
        axis.set_ylim(*layout.track_ylim)
        axis.set_aspect("auto")  # the limits already give a metre the same pixels both ways
        axis.set_axis_off()
        span = layout.track_xlim[1] - layout.track_xlim[0]
        height = layout.track_ylim[1] - layout.track_ylim[0]
        for name, length, angle in zip(graph.names, graph.lengths, np.radians(graph.angles_deg), strict=True):
            direction = np.array([math.cos(angle), math.sin(angle)])
            axis.plot(
                [0.0, length * direction[0]],
                [0.0, length * direction[1]],
                color="0.75",
                linewidth=7,
                solid_capstyle="round",
                zorder=1,
            )
            label = length * direction + 0.075 * span * direction
            axis.text(*label, f"{name}\n{length:g} m", ha="center", va="center", fontsize=9, color="0.3")
        axis.plot([0.0], [0.0], "o", color="white", markeredgecolor="0.3", markersize=7, zorder=2)
        free = _widest_gap(graph.angles_deg)
        axis.annotate(
            "O",
            (0.0, 0.0),
            xytext=(10 * math.cos(free), 10 * math.sin(free)),
            textcoords="offset points",
            ha="center",
            va="center",
            fontsize=9,
            color="0.3",
        )
        for v in range(2):
            for k, marker, what in ((0, "o", "start"), (-1, "s", "goal")):
                axis.plot(
                    geometry.x[v, k],
                    geometry.y[v, k],
                    marker,
                    markersize=13,
                    markerfacecolor="none",
                    markeredgecolor=VEHICLE_COLOURS[v],
                    markeredgewidth=1.5,
                    zorder=3,
                    label=f"{self.names[v]} {what}",
                )
        corners = _free_corners(graph, layout)
        axis.legend(loc=corners[0], fontsize=8, framealpha=0.9, ncols=2)
        length = _round_length(0.2 * span)
        left = "left" in corners[1]
        x0 = layout.track_xlim[0] + 0.04 * span if left else layout.track_xlim[1] - 0.04 * span - length
        lower = "lower" in corners[1]
        y0 = layout.track_ylim[0] + 0.05 * height if lower else layout.track_ylim[1] - 0.08 * height
        axis.plot([x0, x0 + length], [y0, y0], color="black", linewidth=2, solid_capstyle="butt")
        axis.text(
            x0 + 0.5 * length,
            y0 + 0.012 * height,
            f"{length:g} m (to scale)",
            ha="center",
            va="bottom",
            fontsize=8,
        )
        radius = 0.5 * geometry.min_separation
        vehicles = []
        for v in range(2):
            colour = VEHICLE_COLOURS[v]
            disc = axis.fill(*_disc(0.0, 0.0, radius).T, color=colour, alpha=0.3, linewidth=0, zorder=4)[0]
            dot = axis.plot(
                [0.0], [0.0], "o", color=colour, markersize=10, markeredgecolor="black", markeredgewidth=0.8
            )[0]
            name = axis.annotate(
                self.names[v],
                (0.0, 0.0),
                xytext=(0.0, 0.0),
                textcoords="offset points",
                fontsize=10,
                color=colour,
                weight="bold",
            )
            vehicles.append((disc, dot, name))
        self.radius = radius
        return vehicles

    def _draw_bar(self, layout: FrameLayout):
        figure, geometry = self.figure, self.geometry
        axis = self._axes(layout.bar_box)
        axis.set_xlim(*layout.bar_xlim)
        axis.set_ylim(-0.5, 0.5)
        axis.set_yticks([])
        axis.tick_params(axis="x", labelsize=8)
        axis.set_xlabel("track distance between the vehicles [m]", fontsize=9, labelpad=2)
        bar = axis.barh([0.0], [0.0], height=1.0, color="tab:green")[0]
        required = geometry.min_separation
        minimum = [axis.axvline(required, color="tab:red", linestyle="--", linewidth=1.5)] if required else []
        top = (layout.bar_box[1] + layout.bar_box[3]) / FRAME_HEIGHT_PX + 0.022
        figure.text(
            layout.bar_box[0] / FRAME_WIDTH_PX,
            top,
            "separation along the track (dashed: the minimum)",
            ha="left",
            va="center",
            fontsize=9,
        )
        value = figure.text(
            (layout.bar_box[0] + layout.bar_box[2]) / FRAME_WIDTH_PX,
            top,
            "",
            ha="right",
            va="center",
            fontsize=10,
            weight="bold",
        )
        return bar, minimum, value

    def pixels(self, k: int) -> np.ndarray:
        """Frame ``k`` as an RGB array, shape (height, width, 3)."""
        geometry = self.geometry
        self.clock.set_text(clock_text(float(geometry.t[k]), self.duration))
        for v, (disc, dot, name) in enumerate(self.vehicles):
            x, y = float(geometry.x[v, k]), float(geometry.y[v, k])
            disc.set_xy(_disc(x, y, self.radius))
            dot.set_data([x], [y])
            name.xy = (x, y)
            # the name beside the leg (clear of the leg's label), on the side away from the other vehicle
            away = np.array([x - geometry.x[1 - v, k], y - geometry.y[1 - v, k]])
            away = away / np.hypot(*away) if np.hypot(*away) > 0.0 else np.array([0.0, 1.0])
            radius = math.hypot(x, y)
            if radius > 0.0:
                across = np.array([-y, x]) / radius
                away = across if across @ away >= 0.0 else -across
            name.xyann = tuple(11.0 * away)
            name.set_horizontalalignment("left" if away[0] > 0.3 else "right" if away[0] < -0.3 else "center")
            name.set_verticalalignment("bottom" if away[1] > 0.3 else "top" if away[1] < -0.3 else "center")
            self.speeds[v].set_text(speed_text(self.names[v], float(geometry.speed[v, k])))
        distance = float(geometry.distance[k])
        colour = "tab:red" if geometry.near[k] else "tab:green"
        self.bar.set_width(distance)
        self.bar.set_color(colour)
        self.bar_value.set_text(distance_text(distance, geometry.min_separation))
        self.bar_value.set_color(colour)
        return self.paint()


def _check_names(names: object) -> tuple[str, str]:
    if (
        not isinstance(names, Sequence)
        or isinstance(names, str)
        or len(names) != 2
        or not all(isinstance(name, str) for name in names)
    ):
        raise InputError(
            f"animation names must be two strings (vehicle 1, vehicle 2), got {short_repr(names)}"
        )
    return (names[0], names[1])


def render_animation(
    verified: VerifiedSchedule,
    *,
    names: tuple[str, str] = ("vehicle 1", "vehicle 2"),
    fps: int = DEFAULT_FPS,
    max_frames: int = DEFAULT_MAX_FRAMES,
) -> bytes:
    """The schedule played on the track seen from above, as GIF bytes (nothing is written).

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.certify`.
    names : pair of str, optional
        The vehicles' names, written beside them.
    fps : int, optional
        Frames per second of playback, 1 to :data:`MAX_FPS` (default 10).
    max_frames : int, optional
        Most frames, 2 to :data:`MAX_FRAMES_LIMIT` (default 300: 30 s at 10 fps). A
        schedule longer than ``max_frames / fps`` seconds is played faster (see :func:`playback`).

    Returns
    -------
    bytes
        An animated GIF of :data:`FRAME_WIDTH_PX` x :data:`FRAME_HEIGHT_PX` pixels that loops;
        the last frame (the goal) is held :data:`END_HOLD_MS` ms.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    OptionError
        ``fps`` or ``max_frames`` out of range.
    InputError
        ``names`` is not two strings.
    """
    schedule = require_verified(verified, "render_animation").schedule
    names = _check_names(names)
    play = playback(schedule.duration, fps=fps, max_frames=max_frames)
    geometry = frame_geometry(verified, play.times())
    layout = frame_layout(schedule.route.graph, geometry)
    scene = _Scene(verified, geometry, layout, names, play)
    count = play.frame_count
    samples = [scene.pixels(k) for k in sorted({0, int(np.argmin(geometry.distance)), count - 1})]
    frames = (scene.pixels(k) for k in progress(range(count), total=count, description="animation frames"))
    delays = [play.delay_ms] * (count - 1) + [END_HOLD_MS]
    return gif_bytes(frames, delays_ms=delays, palette_samples=samples)
