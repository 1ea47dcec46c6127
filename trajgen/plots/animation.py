"""The animation drawn: a schedule played on the track seen from above, frame by frame, as GIF bytes.

Each frame shows the track to scale, each vehicle at its position (a dot, and
a disc of diameter the minimum separation: on one leg the discs touch exactly
when the vehicles are at the minimum), where each starts (hollow circle) and
ends (hollow square), a clock, each vehicle's speed and, below, the track
distance between the vehicles as a bar against the minimum (red when closer
than :data:`~trajgen.plots.animation_layout.NEAR_FACTOR` times the minimum).

Resources are bounded whatever the duration: at most ``max_frames`` frames
(a long schedule is played faster, by a round speed-up written on every
frame), drawn one at a time into one figure and encoded at once
(:func:`trajgen.plots.gif.gif_bytes`).

What each frame shows (the instants, the positions, the layout in pixels, the
texts) is computed apart from the drawing, in :mod:`trajgen.plots.animation_layout`.
"""

from __future__ import annotations

import math

import numpy as np

from topology import TrackGraph
from trajgen.plots.animation_layout import (
    DEFAULT_FPS,
    DEFAULT_MAX_FRAMES,
    END_HOLD_MS,
    FRAME_DPI,
    FRAME_HEIGHT_PX,
    FRAME_WIDTH_PX,
    FrameGeometry,
    FrameLayout,
    Playback,
    clock_text,
    distance_text,
    frame_geometry,
    frame_layout,
    playback,
    speed_text,
)
from trajgen.plots.figure import checked_names, frame_painter, new_figure
from trajgen.plots.speed import vehicle_colour
from trajgen.plots.track_drawing import draw_track
from trajgen.plots.track_layout import TrackLayout
from trajgen.progress import progress
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["Animation", "animate"]


def _speed_places(count: int) -> list[tuple[float, str]]:
    """Where each vehicle's speed is written across the top: ``(x, alignment)``, the first at the left."""
    if count == 1:
        return [(0.03, "left")]
    places = []
    for v in range(count):
        alignment = "left" if v == 0 else "right" if v == count - 1 else "center"
        places.append((0.03 + 0.94 * v / (count - 1), alignment))
    return places


def _round_length(target: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) at most ``target``, metres."""
    decade = 10.0 ** math.floor(math.log10(target))
    return max(digit * decade for digit in (1, 2, 5) if digit * decade <= target)


def _free_corners(drawn: TrackLayout, labels: list, layout: FrameLayout) -> list[str]:
    """The track area's corners, farthest from the drawn track and its labels first (legend, scale bar)."""
    every = np.vstack([drawn.nodes, *drawn.edges, *(np.reshape(label, (1, 2)) for label in labels)])
    corners = {
        "upper left": (layout.track_xlim[0], layout.track_ylim[1]),
        "upper right": (layout.track_xlim[1], layout.track_ylim[1]),
        "lower left": (layout.track_xlim[0], layout.track_ylim[0]),
        "lower right": (layout.track_xlim[1], layout.track_ylim[0]),
    }

    def clearance(corner) -> float:
        return float(np.min(np.linalg.norm(every - np.array(corner), axis=1)))

    return sorted(corners, key=lambda name: -clearance(corners[name]))


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
            f"{' and '.join(names)}: {schedule.method.name} schedule, {schedule.duration:.2f} s",
            ha="center",
            va="center",
            fontsize=11,
        )
        self.clock = figure.text(0.03, 0.915, "", ha="left", va="center", fontsize=12, family="monospace")
        figure.text(0.97, 0.915, play.label, ha="right", va="center", fontsize=12, weight="bold")
        self.speeds = [
            figure.text(x, 0.875, "", ha=ha, va="center", fontsize=11, color=vehicle_colour(v), weight="bold")
            for v, (x, ha) in enumerate(_speed_places(len(names)))
        ]
        self.vehicles = self._draw_track(schedule.track, layout)
        self.bar, self.minimum, self.bar_value = self._draw_bar(layout)
        moving = [self.clock, *self.speeds]
        for disc, dot, name in self.vehicles:
            moving += [disc, dot, name]
        moving += [self.bar, *self.minimum, self.bar_value]
        self.paint = frame_painter(figure, moving)

    def _axes(self, box: tuple[float, float, float, float]):
        sizes = (FRAME_WIDTH_PX, FRAME_HEIGHT_PX, FRAME_WIDTH_PX, FRAME_HEIGHT_PX)
        return self.figure.add_axes([value / size for value, size in zip(box, sizes, strict=True)])

    def _draw_track(self, track: TrackGraph, layout: FrameLayout) -> list:
        """The track (:func:`~trajgen.plots.track_drawing.draw_track`); returns the vehicles' artists.

        Both vehicles' starts and goals are marked; the legend and the scale bar sit in the two
        corners farthest from the track and its labels.
        """
        axis = self._axes(layout.track_box)
        axis.set_xlim(*layout.track_xlim)
        axis.set_ylim(*layout.track_ylim)
        axis.set_aspect("auto")  # the limits already give a metre the same pixels both ways
        axis.set_axis_off()
        drawn = TrackLayout.of(track)
        labels = draw_track(axis, drawn)
        self._mark_ends(axis)
        corners = _free_corners(drawn, labels, layout)
        axis.legend(loc=corners[0], fontsize=8, framealpha=0.9, ncols=2)
        self._scale_bar(axis, layout, corners[1])
        return self._vehicle_artists(axis)

    def _mark_ends(self, axis) -> None:
        geometry = self.geometry
        for v in range(len(self.names)):
            for k, marker, what in ((0, "o", "start"), (-1, "s", "goal")):
                axis.plot(
                    geometry.x[v, k],
                    geometry.y[v, k],
                    marker,
                    markersize=13,
                    markerfacecolor="none",
                    markeredgecolor=vehicle_colour(v),
                    markeredgewidth=1.5,
                    zorder=3,
                    label=f"{self.names[v]} {what}",
                )

    def _scale_bar(self, axis, layout: FrameLayout, corner: str) -> None:
        span = layout.track_xlim[1] - layout.track_xlim[0]
        height = layout.track_ylim[1] - layout.track_ylim[0]
        length = _round_length(0.2 * span)
        left = "left" in corner
        x0 = layout.track_xlim[0] + 0.04 * span if left else layout.track_xlim[1] - 0.04 * span - length
        lower = "lower" in corner
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

    def _vehicle_artists(self, axis) -> list:
        radius = 0.5 * self.geometry.min_separation
        vehicles = []
        for v in range(len(self.names)):
            colour = vehicle_colour(v)
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
            # the name beside its edge (clear of the edge's label), on the side away from the others
            others = [u for u in range(len(self.vehicles)) if u != v]
            nearest = min(
                others, key=lambda u: math.hypot(x - geometry.x[u, k], y - geometry.y[u, k]), default=v
            )
            away = np.array([x - geometry.x[nearest, k], y - geometry.y[nearest, k]])
            away = away / np.hypot(*away) if np.hypot(*away) > 0.0 else np.array([0.0, 1.0])
            across = geometry.across[v, :, k]
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


class Animation:
    """A schedule played on the track seen from above: its frames, made one at a time when asked.

    Made by :func:`animate`. The GIF is made at the edge (the command line):
    :func:`~trajgen.plots.gif.encode_gif`.

    Attributes
    ----------
    frame_count : int
    delays_ms : tuple of float, shape (frame_count,)
        How long each frame is shown, milliseconds (the last, the goal, is held
        :data:`~trajgen.plots.animation_layout.END_HOLD_MS`).
    palette_samples : tuple of ndarray, each (height, width, 3), uint8
        The first frame, the closest approach's and the last: the colours a GIF palette needs.
    figure : matplotlib.figure.Figure
        The scene, showing the frame drawn last.
    """

    __slots__ = ("_scene", "delays_ms", "frame_count", "palette_samples")

    def __init__(self, scene: _Scene, frame_count: int, delays_ms, palette_samples) -> None:
        self._scene = scene
        self.frame_count = frame_count
        self.delays_ms = tuple(delays_ms)
        self.palette_samples = tuple(palette_samples)

    @property
    def figure(self):
        """The scene's Figure, showing the frame drawn last."""
        return self._scene.figure

    def frames(self):
        """Each frame in order, an RGB array of shape (height, width, 3), uint8, drawn when asked."""
        count = self.frame_count
        shown = progress(range(count), total=count, description="animation frames")
        return (self._scene.pixels(k) for k in shown)


def animate(
    verified: VerifiedSchedule,
    *,
    names=None,
    fps: int = DEFAULT_FPS,
    max_frames: int = DEFAULT_MAX_FRAMES,
) -> Animation:
    """The schedule played on the track seen from above: an :class:`Animation` (nothing is encoded).

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.certify`.
    names : sequence of str, optional
        The vehicles' names, one per vehicle, written beside them.
    fps : int, optional
        Frames per second of playback, 1 to :data:`~trajgen.plots.animation_layout.MAX_FPS` (default 10).
    max_frames : int, optional
        Most frames, 2 to :data:`~trajgen.plots.animation_layout.MAX_FRAMES_LIMIT` (default 300: 30 s at
        10 fps). A schedule longer than ``max_frames / fps`` seconds is played faster (see
        :func:`~trajgen.plots.animation_layout.playback`).

    Returns
    -------
    Animation
        Frames of :data:`~trajgen.plots.animation_layout.FRAME_WIDTH_PX` x
        :data:`~trajgen.plots.animation_layout.FRAME_HEIGHT_PX` pixels.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    OptionError
        ``fps`` or ``max_frames`` out of range.
    InputError
        ``names`` is not one string per vehicle.
    """
    schedule = require_verified(verified, "animate").schedule
    names = checked_names(names, schedule.limits.count, what="animation")
    play = playback(schedule.duration, fps=fps, max_frames=max_frames)
    geometry = frame_geometry(verified, play.times())
    layout = frame_layout(schedule.track, geometry)
    scene = _Scene(verified, geometry, layout, names, play)
    count = play.frame_count
    samples = [scene.pixels(k) for k in sorted({0, int(np.argmin(geometry.distance)), count - 1})]
    delays = [play.delay_ms] * (count - 1) + [END_HOLD_MS]
    return Animation(scene, count, delays, samples)
