"""``trajgen animate``: a scenario's verified schedule played on the track, written as an animated GIF."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from trajgen.cli.options import add_method, scenario_from, scenario_method
from trajgen.cli.parser import EXIT_OK
from trajgen.errors import OutputError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.plots.animation_layout import (
    DEFAULT_FPS,
    DEFAULT_MAX_FRAMES,
    FRAME_HEIGHT_PX,
    FRAME_WIDTH_PX,
    MAX_FPS,
    MAX_FRAMES_LIMIT,
    playback,
)

__all__ = ["gif_path", "register"]


def gif_path(text: str) -> Path:
    """The ``--out`` file: a path naming a ``.gif`` file (any case), not a folder.

    Raises
    ------
    OutputError
        The path is empty, ends with a separator, does not end in ``.gif``, or is a folder.
    """
    if not text or text.endswith((os.sep, "/")) or not Path(text).name:
        raise OutputError(f"--out {text!r} names no file: expected a file name ending in .gif")
    path = Path(text)
    if path.suffix.lower() != ".gif":
        raise OutputError(f"--out {text!r} does not end in .gif: expected an animated GIF file name")
    check_output_paths([path])  # not a folder, below a folder (or none yet)
    return path


def _command_animate(args: argparse.Namespace) -> int:
    path = gif_path(args.out)
    playback(0.0, fps=args.fps, max_frames=args.max_frames)  # bad options are refused before computing
    from trajgen.pipeline import run
    from trajgen.plots.animation import animate
    from trajgen.plots.gif import encode_gif

    scenario = scenario_from(args.scenario)
    verified = run(scenario, method=scenario_method(args, scenario)).verified
    gif = encode_gif(animate(verified, names=scenario.names, fps=args.fps, max_frames=args.max_frames))
    (written,) = commit_files({path: gif})
    play = playback(verified.schedule.duration, fps=args.fps, max_frames=args.max_frames)
    print(
        f"{verified.schedule.method.name} schedule, {verified.schedule.duration:.2f} s: "
        f"{play.frame_count} frames of {FRAME_WIDTH_PX}x{FRAME_HEIGHT_PX} px at {1000 / play.delay_ms:g} "
        f"frames per second, {play.label}"
    )
    print(f"wrote {written} ({len(gif):,} bytes)")
    return EXIT_OK


def register(commands) -> None:
    """Add ``animate`` to the sub-commands."""
    animate = commands.add_parser(
        "animate",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    animate.add_argument("scenario", help="scenario TOML file")
    animate.add_argument("--out", metavar="FILE.gif", required=True, help="the GIF to write")
    add_method(animate)
    animate.add_argument(
        "--fps",
        type=int,
        default=DEFAULT_FPS,
        help=f"frames per second of playback, 1 to {MAX_FPS} ({DEFAULT_FPS})",
    )
    animate.add_argument(
        "--max-frames",
        type=int,
        default=DEFAULT_MAX_FRAMES,
        help=f"most frames, 2 to {MAX_FRAMES_LIMIT} ({DEFAULT_MAX_FRAMES}); a longer schedule is played\n"
        "faster, by a round speed-up written on the frames (e.g. ×4)",
    )
    animate.set_defaults(run=_command_animate)
