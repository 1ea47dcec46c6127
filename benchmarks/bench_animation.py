"""How long ``trajgen animate`` takes: drawing and encoding the frames of a built-in scenario's GIF.

Run: ``python benchmarks/bench_animation.py [--scenario swap] [--method optimal] [--repeat 3]
[--fps 10] [--max-frames 300]``.

The scenario's schedule is computed and verified once, beforehand, and not timed (``trajgen
animate`` does that too: about 0.7 s for the demo swap's optimal schedule). Each repeat then times
what the command does after it: :func:`trajgen.plots.animate` (the scene drawn once, the palette
samples) and :func:`trajgen.plots.encode_gif` (every frame drawn and encoded), separately and
together, and prints seconds, frames and frames per second (the best repeat and the median: the
machine's other load only ever adds time). One process, one core.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from trajgen.pipeline import run
from trajgen.plots import animate, encode_gif
from trajgen.scenario import BuiltinScenario, builtin_scenario


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="swap", choices=[s.value for s in BuiltinScenario])
    parser.add_argument("--method", default=None, help="timing method (the scenario's default)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--fps", type=int, default=10)
    parser.add_argument("--max-frames", type=int, default=300)
    args = parser.parse_args()

    scenario = builtin_scenario(BuiltinScenario.lookup(args.scenario))
    verified = run(scenario, method=args.method).verified
    schedule = verified.schedule
    print(
        f"{args.scenario}: {schedule.method.name} schedule, {schedule.duration:.2f} s; "
        f"--fps {args.fps} --max-frames {args.max_frames}; load average {os.getloadavg()[0]:.2f}"
    )
    setups, encodings, totals, size, frames = [], [], [], 0, 0
    for _ in range(args.repeat):
        start = time.perf_counter()
        animation = animate(verified, names=scenario.names, fps=args.fps, max_frames=args.max_frames)
        drawn = time.perf_counter()
        gif = encode_gif(animation)
        end = time.perf_counter()
        setups.append(drawn - start)
        encodings.append(end - drawn)
        totals.append(end - start)
        size, frames = len(gif), animation.frame_count
    for label, pick in (("best", min), ("median", statistics.median)):
        total = pick(totals)
        print(
            f"{label:>6}: {total:.2f} s for {frames} frames ({frames / total:.1f} frames per second): "
            f"scene {pick(setups):.2f} s, frames drawn and encoded {pick(encodings):.2f} s; {size:,} bytes"
        )


if __name__ == "__main__":
    main()
