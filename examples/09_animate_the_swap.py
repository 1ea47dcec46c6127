"""09 — Watch the swap: an animated GIF of the track, and the configuration space drawn flat.

Numbers and curves say that a schedule is safe; a picture of the two AGVs on
the track says what they do. We time the swap of ``swap.toml`` with the
optimal method, let the verifier certify it, and render

- ``swap.gif``: the Y-track from above, to scale, both vehicles moving per the
  schedule, a clock, each vehicle's speed and a bar for the track distance
  between them (red when it comes near the minimum). At 10 frames per second
  and at most 300 frames, the 27.5-s swap plays in real time; a longer
  schedule would play faster, by a round speed-up written on every frame.
- ``configuration.png``: the configuration space of the paper drawn flat, six
  quadrangles and six triangles round the deleted point where both vehicles
  would be at the junction, with the planner's route, the schedule's path, and
  its retraction onto the boundary circle: the swap goes half way round it.

Both renderers return bytes; ``commit_files`` writes them together (or neither).
"""

import os
import tempfile
from pathlib import Path

import numpy as np

from trajgen import Optimal, certify, load_scenario, make_schedule
from trajgen.export import commit_files
from trajgen.model.summary import class_label
from trajgen.plots import animate, encode_gif, plot_configuration, png_bytes
from trajgen.plots.animation_layout import frame_geometry, playback

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()

# 1. The schedule to show: the optimal swap, certified (plots accept nothing else).
route = scenario.route()
verified = certify(make_schedule(route, scenario.limits, method=Optimal()))
duration = verified.schedule.duration
print(f"optimal swap: {duration:.2f} s, class {class_label(verified.schedule.route)}")

# 2. How it will be played: which instants become frames, and how fast.
play = playback(duration, fps=10, max_frames=300)
print(f"frames: {play.frame_count} at {1000 / play.delay_ms:g} per second, {play.label}")
long_play = playback(4 * 3600.0, fps=10, max_frames=300)
print(f"(a 4-hour schedule would take {long_play.frame_count} frames, {long_play.label})")

# 3. What a frame shows, as numbers: the vehicles' positions and the bar at the closest approach.
geometry = frame_geometry(verified, play.times())
closest = int(np.argmin(geometry.distance))
for vehicle, name in enumerate(scenario.names):
    print(
        f"t = {geometry.t[closest]:.1f} s: {name} at x = {geometry.x[vehicle, closest]:6.2f} m, "
        f"y = {geometry.y[vehicle, closest]:6.2f} m, {geometry.speed[vehicle, closest]:.2f} m/s"
    )
print(
    f"separation bar: {geometry.distance[closest]:.2f} m against the minimum {geometry.min_separation:g} m "
    f"({'red' if geometry.near[closest] else 'green'})"
)

# 4. The animation's frames as a GIF, the configuration's Figure as a PNG, written in one commit.
files = {
    output / "swap.gif": encode_gif(animate(verified, names=scenario.names)),
    output / "configuration.png": png_bytes(plot_configuration(verified, names=scenario.names)),
}
for path in commit_files(files):
    print(f"wrote {path} ({path.stat().st_size:,} bytes)")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
