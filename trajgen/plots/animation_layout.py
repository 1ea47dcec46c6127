"""The animation's frames computed apart from the pixels: which instants are played and where everything is.

The animation (drawn and encoded by :mod:`trajgen.plots.animation`) plays a schedule on its
track seen from above (a junction's legs, or any track graph). What each frame shows is computed
here, so it can be checked without looking at pixels:

- the instants played (:func:`playback`): at most ``max_frames`` frames, whatever the
  duration (a long schedule is played faster, by a round speed-up);
- the vehicles' positions from above, speeds and track distance (:func:`frame_geometry`);
- where the track (to scale) and the separation bar sit in the frame, in pixels
  (:func:`frame_layout`);
- the texts: the clock, each vehicle's speed, the bar's value (the ``*_text`` functions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from topology import TrackGraph
from topology.validation import short_repr
from trajgen.errors import OptionError
from trajgen.model.values import ArrayValue, frozen
from trajgen.plots.gif import GIF_DELAY_UNIT_MS
from trajgen.plots.track_layout import TrackLayout
from trajgen.verification import VerifiedSchedule, require_verified

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
    x, y : ndarray, shape (m, n)
        Each vehicle's position from above, metres, where the track's layout draws it
        (:class:`~trajgen.plots.track_layout.TrackLayout`; a star's junction at the origin, its legs
        at their angles).
    across : ndarray, shape (m, 2, n)
        The unit vector across the vehicle's edge as drawn there (its direction turned a quarter
        counterclockwise): the vehicle's name is written beside its edge, not on it.
    velocity : ndarray, shape (m, n)
        Each vehicle's velocity along its signed axis, m/s.
    distance : ndarray, shape (n,)
        Track distance between the vehicles, metres: the length of the separation bar.
    min_separation : float
        The minimum the schedule keeps, metres.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    across: np.ndarray
    velocity: np.ndarray
    distance: np.ndarray
    min_separation: float

    def __post_init__(self) -> None:
        for name in ("t", "x", "y", "across", "velocity", "distance"):
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
    track = schedule.track
    layout = TrackLayout.of(track)
    count = state.edge.shape[0]
    xy = np.stack([layout.points(state.edge[v], state.s[v]) for v in range(count)])  # (m, n, 2)
    tangent = np.stack([layout.tangents(state.edge[v], state.s[v]) for v in range(count)])
    across = np.stack([-tangent[..., 1], tangent[..., 0]], axis=1)  # (m, 2, n)
    pairs = [(a, b) for a in range(count) for b in range(a + 1, count)]
    distance = np.full(state.t.shape, np.inf)  # the closest pair's track distance
    for a, b in pairs:
        distance = np.minimum(distance, track.distances(state.edge[a], state.s[a], state.edge[b], state.s[b]))
    return FrameGeometry(
        t=state.t,
        x=xy[:, :, 0],
        y=xy[:, :, 1],
        across=across,
        velocity=state.velocity,
        distance=distance,
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


def frame_layout(track: TrackGraph, geometry: FrameGeometry) -> FrameLayout:
    """The layout of the frames of ``geometry`` on ``track``: the whole track to scale, and the bar's range.

    The track area shows every edge as :class:`~trajgen.plots.track_layout.TrackLayout` draws it
    (a star's legs at their angles from the junction) with a margin for the labels and the
    vehicles' discs, widened in one direction so that a metre is as many pixels across as up.
    The bar's range is the largest track distance of the frames (at least :data:`NEAR_FACTOR`
    times the minimum), with 5 % to spare.
    """
    drawn = TrackLayout.of(track)
    every = np.vstack([drawn.nodes, *drawn.edges])
    ends_x, ends_y = every[:, 0], every[:, 1]
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
