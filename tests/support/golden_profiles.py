"""Golden profile files: the cases, how each one's bytes are made, and the writer of the stored files.

The files under ``tests/data/golden/`` were written by this module from the
per-value Python formatter (``f"{round(v, places) + 0.0:.{places}f}"``) that
the vectorized one replaced; ``tests/test_golden.py`` checks that every case
still renders to exactly those bytes. Short schedules are stored whole; long
ones as SHA-256 digests (:data:`LONG_DIGESTS`).

Remake the files only for an intended format change, and say so in the commit::

    python -m tests.support.golden_profiles
"""

from __future__ import annotations

import functools
import hashlib
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from limits import Limits, VehicleLimits
from tests.conftest import REPO
from topology import Configuration, Position, YGraph, plan
from trajgen import Exact, Toppra, certify, load_scenario, make_schedule
from trajgen.export.csv import CsvOptions, Units, profile_chunks, render_profile
from trajgen.export.plc import plc_tables
from trajgen.simulation_pipeline import run_simulation
from trajgen.verification import VerifiedSchedule

GOLDEN = REPO / "tests" / "data" / "golden"
NAMES = ("agv1", "agv2")
#: Sample period of the golden generic CSVs, seconds (coarse: small files).
GOLDEN_PERIOD = 0.25
#: Points per table of the golden table files (small files).
GOLDEN_POINTS = 300

_METHODS = {"exact": Exact, "toppra": Toppra}


@functools.cache
def example_schedule(scenario: str, method: str) -> VerifiedSchedule:
    """``examples/<scenario>.toml`` timed by ``method`` (``exact`` or ``toppra``), verified."""
    loaded = load_scenario(REPO / "examples" / f"{scenario}.toml")
    return certify(make_schedule(loaded.route(), loaded.limits, method=_METHODS[method]()))


@functools.cache
def long_swap(leg_length: float) -> VerifiedSchedule:
    """The exact swap on a Y of three ``leg_length``-metre legs, end of A to end of B (1 m/s, 0.5 m/s²)."""
    vehicle = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits(vehicles=(vehicle, vehicle), min_separation=1.5)
    track = YGraph({"A": leg_length, "B": leg_length, "C": leg_length})
    a_end, b_end = Position.parse(f"A:{leg_length}"), Position.parse(f"B:{leg_length}")
    route = plan(track, Configuration(a_end, b_end), Configuration(b_end, a_end), min_separation=1.5)
    return certify(make_schedule(route, limits, method=Exact()))


def profile_digests(verified: VerifiedSchedule, options: CsvOptions) -> tuple[str, str]:
    """SHA-256 (hex) of both vehicles' generic CSV, streamed chunk by chunk (never whole in memory)."""
    digests = []
    for vehicle in (0, 1):
        digest = hashlib.sha256()
        for chunk in profile_chunks(verified, vehicle, options):
            digest.update(chunk)
        digests.append(digest.hexdigest())
    return digests[0], digests[1]


#: Long exact swaps (leg length in metres -> duration in seconds and the SHA-256 of both generic CSVs
#: at the default options), from the per-value formatter. The tests check these (10 min and 1 h);
#: ``benchmarks/bench_csv.py`` checks the 1 h and 4 h ones.
LONG_DIGESTS = {
    100.0: (
        607.5,
        (
            "3bfb77a9cc0bca20307b7fa89e13c28012aab75805d63a75a4b907226dda929c",
            "1c50f3521b0ec68b62e5ffa7eac4b82f7e477ddd5bc90bd8a7bb73952005414d",
        ),
    ),
    533.0: (
        3205.5,
        (
            "bd46301945ce37fd0e1a986f4898bea569756b9244243bf0df62ea00478a8f58",
            "8d9b02a15878c2c56b6e7a2d4cf82c2f47fb6bf98118114c5c7a728677216748",
        ),
    ),
}


@dataclass(frozen=True)
class GoldenCase:
    """One stored set of files: a folder under :data:`GOLDEN` and what renders them.

    Attributes
    ----------
    name : str
        The folder name, also the test id.
    render : callable
        Returns ``{file name: bytes}``.
    """

    name: str
    render: Callable[[], dict[str, bytes]]


def _generic(scenario: str, method: str, options: CsvOptions) -> Callable[[], dict[str, bytes]]:
    def render() -> dict[str, bytes]:
        verified = example_schedule(scenario, method)
        return {
            f"{name}.csv": render_profile(verified, vehicle, options) for vehicle, name in enumerate(NAMES)
        }

    return render


def _table(scenario: str, method: str, dialect: str, points: int | None) -> Callable[[], dict[str, bytes]]:
    def render() -> dict[str, bytes]:
        tables = plc_tables(example_schedule(scenario, method), dialect, max_points=points)
        suffix = tables.dialect.suffix
        return {f"{name}{suffix}": data for name, data in zip(NAMES, tables.contents, strict=True)}

    return render


def _trace(options: CsvOptions) -> Callable[[], dict[str, bytes]]:
    def render() -> dict[str, bytes]:
        scenario = load_scenario(REPO / "examples" / "swap.toml")
        with tempfile.TemporaryDirectory() as folder:
            run_simulation(
                scenario, ["stop:agv1@8+3"], period=0.1, method=Exact(), trace_dir=folder, csv_options=options
            )
            return {path.name: path.read_bytes() for path in sorted(Path(folder).iterdir())}

    return render


def _generic_options(units: Units, delimiter: str = ";", decimal: str = ".") -> CsvOptions:
    return CsvOptions(sample_period=GOLDEN_PERIOD, delimiter=delimiter, decimal=decimal, units=units)


METRES, MILLIMETRES = Units.METRES, Units.MILLIMETRES
TABLE_DIALECTS = ("twincat-cam", "codesys-xy", "logix-time-cam", "siemens-xy", "velocity-profile")

#: Every golden case: the generic CSV in both units and several delimiters and decimal marks, every
#: table dialect, on the swap (exact), the 4-leg crossing (exact and toppra: reversing, jerk, negative
#: x and y, the junction), and a simulated trace.
CASES = (
    GoldenCase("generic-swap-exact-m", _generic("swap", "exact", _generic_options(METRES))),
    GoldenCase("generic-swap-exact-mm", _generic("swap", "exact", _generic_options(MILLIMETRES))),
    GoldenCase(
        "generic-swap-exact-m-tab-comma", _generic("swap", "exact", _generic_options(METRES, "\t", ","))
    ),
    GoldenCase(
        "generic-swap-exact-mm-space-comma",
        _generic("swap", "exact", _generic_options(MILLIMETRES, " ", ",")),
    ),
    GoldenCase(
        "generic-swap-exact-mm-comma-delimiter", _generic("swap", "exact", _generic_options(MILLIMETRES, ","))
    ),
    GoldenCase("generic-crossing-exact-m", _generic("crossing", "exact", _generic_options(METRES))),
    GoldenCase("generic-crossing-exact-mm", _generic("crossing", "exact", _generic_options(MILLIMETRES))),
    GoldenCase("generic-crossing-toppra-m", _generic("crossing", "toppra", _generic_options(METRES))),
    GoldenCase(
        "generic-crossing-toppra-mm-tab-comma",
        _generic("crossing", "toppra", _generic_options(MILLIMETRES, "\t", ",")),
    ),
    *(GoldenCase(f"{d}-swap-exact", _table("swap", "exact", d, GOLDEN_POINTS)) for d in TABLE_DIALECTS),
    *(
        GoldenCase(f"{d}-crossing-toppra", _table("crossing", "toppra", d, GOLDEN_POINTS))
        for d in TABLE_DIALECTS
        if d != "logix-time-cam"  # a cubic spline needs a jerk-limited schedule
    ),
    GoldenCase("logix-time-cam-crossing-exact-default", _table("crossing", "exact", "logix-time-cam", None)),
    GoldenCase(
        "velocity-profile-crossing-exact-default", _table("crossing", "exact", "velocity-profile", None)
    ),
    GoldenCase(
        "trace-swap-stop-mm-tab-comma", _trace(CsvOptions(delimiter="\t", decimal=",", units=MILLIMETRES))
    ),
)


def first_difference(expected: bytes, actual: bytes) -> str | None:
    """``None`` if the two files are equal, else where they first differ: the line and both versions.

    Lines are split after LF (a CR stays with its line, so a lost CR shows).
    """
    if expected == actual:
        return None
    old, new = expected.splitlines(keepends=True), actual.splitlines(keepends=True)
    for number, (before, after) in enumerate(zip(old, new, strict=False), start=1):
        if before != after:
            return f"line {number} differs: expected {before!r}, got {after!r}"
    shorter = min(len(old), len(new))
    return (
        f"the files agree on {shorter} lines, then the expected one has {len(old) - shorter} more "
        f"and the rendered one {len(new) - shorter} more"
    )


def write_golden_files() -> None:
    """Write every case's files under :data:`GOLDEN` (removing files of no case)."""
    for stale in GOLDEN.rglob("*"):
        if stale.is_file():
            stale.unlink()
    for case in CASES:
        folder = GOLDEN / case.name
        folder.mkdir(parents=True, exist_ok=True)
        for name, data in case.render().items():
            (folder / name).write_bytes(data)


if __name__ == "__main__":
    write_golden_files()
    for length in (100.0, 533.0, 2133.0):
        verified = long_swap(length)
        sys.stdout.write(
            f"{length}: ({verified.schedule.duration!r}, {profile_digests(verified, CsvOptions())!r}),\n"
        )
