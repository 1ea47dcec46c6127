"""The CSV step on long schedules: MB/s of sampling, formatting and writing both files, and peak memory.

Run: ``python benchmarks/bench_csv.py [--legs 533 2133] [--repeat N] [--dir DIR]``.

Each size runs in a fresh subprocess, so the peak resident set size
(``ru_maxrss``) is that size's. The schedule is the exact swap on a Y of three
equal legs (end of A to end of B; 1 m/s, 0.5 m/s², 1 m/s³, separation 1.5 m):
legs of 533 m take 3,205.5 s (about 1 h), legs of 2133 m 12,805.5 s (about
4 h). Planning, timing and verifying are not timed; the CSV step is
:func:`trajgen.export.write_profiles` at the default options (0.01 s,
metres) into a new folder: sampling, formatting, writing both files, ``fsync``
and the atomic commit. With ``--repeat N`` the fastest of N runs is reported
(each into its own folder, removed untimed). The files are checked against
the SHA-256 digests that the per-value Python formatter wrote (``ok``;
``MISMATCH``; ``-`` for a size with no recorded digest).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: SHA-256 of both generic CSVs (default options) of the exact swap per leg length in metres, with
#: the schedule's duration, as the per-value Python formatter wrote them.
KNOWN_DIGESTS = {
    533.0: (
        3205.5,
        (
            "bd46301945ce37fd0e1a986f4898bea569756b9244243bf0df62ea00478a8f58",
            "8d9b02a15878c2c56b6e7a2d4cf82c2f47fb6bf98118114c5c7a728677216748",
        ),
    ),
    2133.0: (
        12805.5,
        (
            "90536ed2fb6107be6c8fdfc79197913897dcfc28b90df3620ddc23a2ce531ece",
            "5a1de3d4a0ba15eae5f88d62094182bfb81b147b982640cc1e1a71a7a582223c",
        ),
    ),
}


def _peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux


def _file_digest(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while block := stream.read(1 << 20):
            digest.update(block)
    return digest.hexdigest()


def measure(leg_length: float, repeat: int, directory: str | None) -> dict:
    """Time the CSV step of one schedule in this process; the figures as a dict."""
    from limits import Limits, VehicleLimits
    from topology import Configuration, Position, YGraph, plan
    from trajgen import Exact, certify, make_schedule
    from trajgen.export.csv import CsvOptions, profile_rows, write_profiles

    vehicle = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits(vehicles=(vehicle, vehicle), min_separation=1.5)
    track = YGraph({"A": leg_length, "B": leg_length, "C": leg_length})
    a_end, b_end = Position.parse(f"A:{leg_length}"), Position.parse(f"B:{leg_length}")
    route = plan(track, Configuration(a_end, b_end), Configuration(b_end, a_end), min_separation=1.5)
    verified = certify(make_schedule(route, limits, method=Exact()))
    duration = verified.schedule.duration
    options = CsvOptions()
    rss_before = _peak_rss_mib()
    times = []
    with tempfile.TemporaryDirectory(prefix="bench-csv-", dir=directory) as folder:
        for attempt in range(repeat):
            target = Path(folder) / f"run-{attempt}"  # a new folder each time: no files to replace
            begin = time.perf_counter()
            paths = write_profiles(verified, ("agv1", "agv2"), target, options=options)
            times.append(time.perf_counter() - begin)
            size = sum(path.stat().st_size for path in paths)
            digests = tuple(_file_digest(path) for path in paths)
            shutil.rmtree(target)
    known = KNOWN_DIGESTS.get(leg_length)
    if known is None:
        check = "-"
    elif known == (duration, digests):
        check = "ok"
    else:
        check = "MISMATCH"
    return {
        "legs_m": leg_length,
        "duration_s": duration,
        "rows": profile_rows(duration, options),
        "bytes": size,
        "seconds": min(times),
        "rss_before_mib": rss_before,
        "peak_rss_mib": _peak_rss_mib(),
        "check": check,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--legs", type=float, nargs="+", default=[533.0, 2133.0], help="leg lengths, metres (533 2133)"
    )
    parser.add_argument("--repeat", type=int, default=1, help="runs per size, the fastest reported (1)")
    parser.add_argument("--dir", default=None, help="folder for the temporary files (the system's)")
    parser.add_argument("--one", type=float, default=None, help=argparse.SUPPRESS)  # the child's size
    args = parser.parse_args()
    if args.one is not None:
        print(json.dumps(measure(args.one, args.repeat, args.dir)))
        return
    print(
        f"{'schedule s':>11} {'rows/file':>10} {'MB written':>11} {'seconds':>8} {'MB/s':>7} "
        f"{'RSS before MiB':>15} {'peak RSS MiB':>13} {'digests':>8}"
    )
    for length in args.legs:
        command = [sys.executable, __file__, "--one", str(length), "--repeat", str(args.repeat)]
        if args.dir is not None:
            command += ["--dir", args.dir]
        output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
        figures = json.loads(output.strip().splitlines()[-1])
        megabytes = figures["bytes"] / 1e6
        print(
            f"{figures['duration_s']:11.1f} {figures['rows']:10,d} {megabytes:11.1f} "
            f"{figures['seconds']:8.2f} {megabytes / figures['seconds']:7.1f} "
            f"{figures['rss_before_mib']:15.1f} {figures['peak_rss_mib']:13.1f} {figures['check']:>8}"
        )


if __name__ == "__main__":
    main()
