"""Ways to format the generic CSV's rows, compared: MB/s of formatting alone, and whether the bytes are right.

Run: ``python benchmarks/bench_formatters.py [--legs 533] [--repeat N] [--only NAME ...]``.

The rows of both vehicles' profiles of the exact swap with legs of ``--legs``
metres (533 m: 3,205.5 s, about 1 h), default options, are formatted by each
way in blocks of 20,000 rows. Sampling is done beforehand and not timed; the
columns (x and y from the leg angles, units) are made inside the timed part by
every way alike. Each way's files (header + rows) are checked against the
SHA-256 digests that the per-value Python formatter wrote
(``bench_csv.KNOWN_DIGESTS``).

- ``python``: ``f"{round(float(v), p) + 0.0:.{p}f}"`` per value (the formatter before);
- ``percent``: one ``bytes`` %-format of a whole block (``%.6f``/``%.9f``, correctly rounded), then
  ``-0.000...`` replaced;
- ``numpy-strings``: ``numpy.strings`` (``np.char``) on ``S`` arrays: integer and fraction digits by
  ``astype``, ``zfill`` and ``add``;
- ``savetxt``: ``numpy.savetxt`` into a ``BytesIO`` (%-format per row), then ``-0.000...`` replaced;
- ``digit-planes``: one uint8 plane per character position from integer division by 10, transposed,
  and the padding dropped with a boolean mask;
- ``word-tables``: :func:`trajgen.export.numbers.format_number_rows`, the formatter kept (digits four
  at a time by table look-up into 32-bit words, rows of one width written in place).

``percent``, ``numpy-strings``, ``savetxt`` and ``digit-planes`` leave values at or above
:func:`~trajgen.export.numbers.exact_limit` to Python nowhere: the schedule has none (asserted).
"""

from __future__ import annotations

import argparse
import hashlib
import io
import itertools
import time

import numpy as np
from bench_csv import KNOWN_DIGESTS

from limits import Limits, VehicleLimits
from topology import JUNCTION_INDEX, Configuration, Position, YGraph, plan
from trajgen import Exact, certify, make_schedule
from trajgen.export.csv import HEADER_NAMES, ROWS_PER_CHUNK, CsvOptions, profile_rows
from trajgen.export.numbers import exact_limit, fixed_point_text, format_number_rows
from trajgen.model.schedule import sample_block

PLACES = (6, 9, 9, 9, 9, None, 9, 9, 9)  # t, axis, v, a, j, leg, s, x, y (metres)
SEPARATORS = (";",) * 8 + ("\r\n",)


def columns_of(graph, state, vehicle: int) -> list[np.ndarray]:
    """The nine columns of a vehicle's rows in metres, as trajgen.export.csv makes them."""
    angles = np.radians(np.array(graph.angles_deg))
    leg, s = state.leg[vehicle], state.s[vehicle]
    angle = angles[np.where(leg == JUNCTION_INDEX, 0, leg)]
    x, y = s * np.cos(angle), s * np.sin(angle)
    return [
        state.t,
        state.axis[vehicle] * 1.0,
        state.velocity[vehicle] * 1.0,
        state.acceleration[vehicle] * 1.0,
        state.jerk[vehicle] * 1.0,
        state.leg[vehicle] + 1,
        state.s[vehicle] * 1.0,
        x * 1.0,
        y * 1.0,
    ]


def _no_negative_zero(data: bytes) -> bytes:
    """``-0.000000`` (6 places) and ``-0.000000000`` (9 places) fields as ``0.000...`` (``+ 0.0``)."""
    for zero in (b"0.000000;", b"0.000000000;", b"0.000000000\r"):
        data = data.replace(b"-" + zero, zero)
    return data


def python_rows(columns) -> bytes:
    texts = []
    for values, places in zip(columns, PLACES, strict=True):
        if places is None:
            texts.append([str(v) for v in values.tolist()])
        else:
            texts.append([f"{round(float(v), places) + 0.0:.{places}f}" for v in values])
    return ("\r\n".join(";".join(fields) for fields in zip(*texts, strict=True)) + "\r\n").encode("ascii")


_ROW_FORMAT = b";".join(b"%d" if p is None else b"%%.%df" % p for p in PLACES) + b"\r\n"


def percent_rows(columns) -> bytes:
    arguments = tuple(itertools.chain.from_iterable(zip(*(c.tolist() for c in columns), strict=True)))
    return _no_negative_zero((_ROW_FORMAT * columns[0].size) % arguments)


def _rounded(values: np.ndarray, places: int) -> tuple[np.ndarray, np.ndarray]:
    """``round(v, places) * 10**places`` as int64, and the entries whose product is a half-integer."""
    scaled = values * 10.0**places
    nearest = np.rint(scaled)
    return nearest.astype(np.int64), np.flatnonzero(np.abs(scaled - nearest) == 0.5)


def strings_rows(columns) -> bytes:
    rows = None
    for values, places, separator in zip(columns, PLACES, SEPARATORS, strict=True):
        if places is None:
            text = values.astype("S20")
        else:
            units, halves = _rounded(values, places)
            whole, fraction = np.divmod(np.abs(units), 10**places)
            text = np.strings.add(np.where(units < 0, b"-", b""), whole.astype("S20"))
            text = np.strings.add(
                np.strings.add(text, b"."), np.strings.zfill(fraction.astype("S20"), places)
            )
            text = text.astype(f"S{text.itemsize + 2}")
            for index in halves.tolist():  # the exact product decides: Python's text
                text[index] = fixed_point_text(values[index], places).encode("ascii")
        text = np.strings.add(text, separator.encode("ascii"))
        rows = text if rows is None else np.strings.add(rows, text)
    return b"".join(rows.tolist())


def savetxt_rows(columns) -> bytes:
    buffer = io.BytesIO()
    formats = ["%d" if p is None else f"%.{p}f" for p in PLACES]
    np.savetxt(buffer, np.column_stack(columns), fmt=formats, delimiter=";", newline="\r\n")
    return _no_negative_zero(buffer.getvalue())


def planes_rows(columns) -> bytes:
    rows = columns[0].size
    planes = []
    for values, places, separator in zip(columns, PLACES, SEPARATORS, strict=True):
        if places is None:
            units, halves, places = values.astype(np.int64), np.array([], dtype=int), 0
        else:
            units, halves = _rounded(values, places)
        magnitude = np.abs(units).astype(np.uint64)
        digits = max(len(str(int(magnitude.max()))), places + 1)
        width = digits + (1 if places else 0) + 1  # and a sign
        field = np.zeros((width, rows), dtype=np.uint8)
        remaining, line = magnitude, width - 1
        for digit in range(digits):
            higher = remaining // np.uint64(10)
            character = (remaining - higher * np.uint64(10)).astype(np.uint8) + ord("0")
            field[line] = character if digit <= places else np.where(remaining > 0, character, 0)
            remaining, line = higher, line - 1
            if places and digit == places - 1:
                field[line], line = ord("."), line - 1
        negative = np.flatnonzero(units < 0)
        first = np.argmax(field[:, negative] != 0, axis=0)  # the first digit of each negative row
        field[first - 1, negative] = ord("-")
        for index in halves.tolist():
            text = np.frombuffer(fixed_point_text(values[index], places).encode("ascii"), dtype=np.uint8)
            field[:, index] = 0
            field[width - text.size :, index] = text
        planes.append(field)
        planes.append(
            np.broadcast_to(
                np.frombuffer(separator.encode("ascii"), dtype=np.uint8)[:, None], (len(separator), rows)
            )
        )
    block = np.ascontiguousarray(np.concatenate(planes).T)
    return block[block != 0].tobytes()


def word_tables_rows(columns) -> bytes:
    return format_number_rows(list(zip(columns, PLACES, strict=True)), SEPARATORS)


WAYS = {
    "python": python_rows,
    "percent": percent_rows,
    "numpy-strings": strings_rows,
    "savetxt": savetxt_rows,
    "digit-planes": planes_rows,
    "word-tables": word_tables_rows,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--legs", type=float, default=533.0, help="leg length, metres (533: about 1 h)")
    parser.add_argument("--repeat", type=int, default=1, help="runs per way, the fastest reported (1)")
    parser.add_argument("--only", nargs="+", choices=sorted(WAYS), help="these ways only")
    args = parser.parse_args()
    vehicle = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits(vehicles=(vehicle, vehicle), min_separation=1.5)
    length = args.legs
    track = YGraph({"A": length, "B": length, "C": length})
    a_end, b_end = Position.parse(f"A:{length}"), Position.parse(f"B:{length}")
    route = plan(track, Configuration(a_end, b_end), Configuration(b_end, a_end), min_separation=1.5)
    schedule = certify(make_schedule(route, limits, method=Exact())).schedule
    options = CsvOptions()
    rows = profile_rows(schedule.duration, options)
    states = [
        schedule.state(sample_block(schedule.duration, options.sample_period, first, first + ROWS_PER_CHUNK))
        for first in range(0, rows, ROWS_PER_CHUNK)
    ]
    for state in states:
        for vehicle_index in (0, 1):
            for values, places in zip(
                columns_of(schedule.route.graph, state, vehicle_index), PLACES, strict=True
            ):
                assert places is None or np.all(np.abs(values) < exact_limit(places))
    header = (";".join(HEADER_NAMES[options.units]) + "\r\n").encode("ascii")
    known = KNOWN_DIGESTS.get(length)
    print(f"{schedule.duration:.1f} s schedule, {rows:,} rows per file, formatting both files:")
    print(f"{'way':>14} {'seconds':>8} {'MB':>6} {'MB/s':>7} {'digests':>8}")
    for name, way in WAYS.items():
        if args.only and name not in args.only:
            continue
        best = float("inf")
        for _ in range(args.repeat):
            digests = [hashlib.sha256(header), hashlib.sha256(header)]
            size = 2 * len(header)
            elapsed = 0.0
            for state in states:
                for vehicle_index in (0, 1):
                    begin = time.perf_counter()
                    data = way(columns_of(schedule.route.graph, state, vehicle_index))
                    elapsed += time.perf_counter() - begin
                    digests[vehicle_index].update(data)
                    size += len(data)
            best = min(best, elapsed)
        found = (schedule.duration, tuple(d.hexdigest() for d in digests))
        check = "-" if known is None else "ok" if found == known else "MISMATCH"
        print(f"{name:>14} {best:8.2f} {size / 1e6:6.1f} {size / 1e6 / best:7.1f} {check:>8}")


if __name__ == "__main__":
    main()
