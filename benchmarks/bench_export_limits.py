"""No exported number above its limit: the largest value of each limited column, per dialect and unit setting.

Run: ``python benchmarks/bench_export_limits.py [--methods exact toppra optimal]``.

The bench sets are the built-in scenarios (``swap``, ``crossing``, ``h``) and the other example track
graphs (``examples/graphs/``: ``main-line-with-sidings``, ``passing-loop``, ``ring-with-spurs``),
each timed by every method given. Every export is written, then its numbers are read back as text
from the files, in the files' own units: per dialect and unit setting, the largest ``|v|``,
``|a|``, ``|j|`` over all sets and both vehicles, as ``value / limit = ratio`` against that
vehicle's limit in those units (``ABOVE`` where a value exceeds its limit). The table dialects
write positions only (no limited number), except the velocity profile's velocities (``v``, mm/s);
for them also the largest velocity, acceleration and jerk of the tables as their controllers
interpolate them, over each limit (``limit_ratios`` of the tables read back: derived between the
points, not written, and held to the verifier's 1e-6). A schedule without jerk limits (``toppra``)
records so in its generic CSV, whose ``j`` column states no limit: it is left out. Every export is
checked with ``trajgen check`` as the command does by default (a table of a schedule without jerk
limits, whose format cannot record it, with ``--ignore-jerk``): ``check passes n/n``. No figure
depends on the clock.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from trajgen import certify
from trajgen.export.csv import CsvOptions, Units, profile_chunk_pair, profile_paths
from trajgen.export.plc.check import check_profiles
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.export.plc.files import plc_tables, table_paths
from trajgen.export.plc.tables import Interpolation
from trajgen.methods import make_schedule
from trajgen.scenario import builtin_scenario, load_scenario

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "graphs"
BUILT_IN = ("swap", "crossing", "h")
GRAPHS = ("main-line-with-sidings", "passing-loop", "ring-with-spurs")
#: The generic CSV's settings that change its numbers: the unit and the decimal mark.
GENERIC_SETTINGS = tuple((units, decimal) for units in Units for decimal in (".", ","))
#: The limited columns of the generic CSV: (name, index among the fields, the limit's attribute).
GENERIC_COLUMNS = (("v", 2, "max_velocity"), ("a", 3, "max_acceleration"), ("j", 4, "max_jerk"))


def bench_sets():
    """``(name, scenario)`` of every bench set."""
    for name in BUILT_IN:
        yield name, builtin_scenario(name)
    for name in GRAPHS:
        yield name, load_scenario(EXAMPLES / f"{name}.toml")


def column_values(data: bytes, delimiter: str, decimal: str, first_row: int) -> list[list[float]]:
    """The fields of every row from ``first_row`` (0-based line) on, as numbers (``None``: no number)."""
    rows = []
    for line in data.decode("ascii").split("\n")[first_row:]:
        line = line.rstrip("\r")
        if not line:
            continue
        fields = []
        for field in line.split(delimiter):
            try:
                fields.append(float(field.replace(decimal, ".") if decimal != "." else field))
            except ValueError:
                fields.append(None)
        rows.append(fields)
    return rows


class Worst:
    """The largest value of a column over its limit, and the value and limit it was."""

    def __init__(self) -> None:
        self.ratio, self.value, self.limit = 0.0, 0.0, 0.0

    def add(self, value: float, limit: float) -> None:
        """Take ``|value|`` against ``limit`` (both in the file's units)."""
        if abs(value) / limit > self.ratio or self.limit == 0.0:
            self.ratio, self.value, self.limit = abs(value) / limit, abs(value), limit

    def text(self, digits: int) -> str:
        """``value / limit = ratio``, or ``-`` if nothing was taken."""
        if self.limit == 0.0:
            return "-"
        flag = "" if self.value <= self.limit else " ABOVE"
        return f"{self.value:.{digits}f} / {self.limit:g} = {self.ratio:.12f}{flag}"

    def ratio_text(self) -> str:
        """The largest ratio alone, and whether it is within the verifier's 1e-6."""
        if self.limit == 0.0:
            return "-"
        return f"{self.ratio:.12f}" + ("" if self.ratio <= 1.0 + 1e-6 else " ABOVE 1 + 1e-6")


def generic(verified, scenario, units: Units, decimal: str, worst: dict, folder: Path) -> bool:
    """Write one generic CSV setting, take its columns into ``worst``; whether ``check`` passes it."""
    options = CsvOptions(units=units, decimal=decimal)
    paths = profile_paths(scenario.names, folder)
    for path, chunks in zip(paths, profile_chunk_pair(verified, options), strict=True):
        path.write_bytes(b"".join(chunks))
    schedule = verified.schedule
    for vehicle, path in enumerate(paths):
        data = path.read_bytes()
        header = 2 if data.startswith(b"#") else 1  # the record line of a schedule without jerk limits
        limits = schedule.limits.vehicles[vehicle]
        for row in column_values(data, options.delimiter, decimal, header):
            for name, index, limit in GENERIC_COLUMNS:
                if name == "j" and not schedule.jerk_limited:
                    continue
                worst[name].add(row[index], getattr(limits, limit) * units.scale)
    return check_profiles(scenario, folder).passed


def table(verified, scenario, dialect: TableDialect, worst: dict, folder: Path) -> bool:
    """Write one table dialect, take its velocities and ratios into ``worst``; whether ``check`` passes it."""
    tables = plc_tables(verified, dialect)
    paths = table_paths(dialect, scenario.names, folder)
    for path, data in zip(paths, tables.contents, strict=True):
        path.write_bytes(data)
    schedule = verified.schedule
    first = 0 if dialect.header is None else 1
    for vehicle, path in enumerate(paths):
        limits = schedule.limits.vehicles[vehicle]
        if dialect.interpolation is Interpolation.VELOCITY:  # the slave column is the velocity, mm/s
            for row in column_values(path.read_bytes(), dialect.delimiter, ".", first):
                worst["v (mm/s)"].add(row[1], limits.max_velocity * 1000.0)
        for name, ratios in tables.check.ratios.items():
            if ratios is not None:
                worst[f"interpolated {name}"].add(ratios[vehicle], 1.0)
    verdict = check_profiles(scenario, folder, dialect=dialect, jerk=schedule.jerk_limited)
    return verdict.passed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", nargs="+", default=["exact", "toppra", "optimal"])
    args = parser.parse_args()
    sets = list(bench_sets())
    schedules = [
        (name, scenario, method, certify(make_schedule(scenario.route(), scenario.limits, method=method)))
        for name, scenario in sets
        for method in args.methods
    ]
    print(f"bench sets: {', '.join(name for name, _ in sets)}; methods: {', '.join(args.methods)}")
    settings = [("generic", units, decimal) for units, decimal in GENERIC_SETTINGS]
    settings += [
        (dialect.name.value, None, None) for dialect in DIALECTS if isinstance(dialect, TableDialect)
    ]
    for dialect_name, units, decimal in settings:
        dialect = DIALECTS.lookup(dialect_name)
        keys = ["v", "a", "j"] if units is not None else ["v (mm/s)"]
        if units is None:
            keys += ["interpolated velocity", "interpolated acceleration", "interpolated jerk"]
        worst = {key: Worst() for key in keys}
        checked, exports = 0, 0
        for _, scenario, _, verified in schedules:
            if dialect.interpolation is Interpolation.CUBIC and not verified.schedule.jerk_limited:
                continue  # a spline needs a jerk-limited schedule: refused
            with tempfile.TemporaryDirectory() as folder:
                if units is not None:
                    passed = generic(verified, scenario, units, decimal, worst, Path(folder))
                else:
                    passed = table(verified, scenario, dialect, worst, Path(folder))
            exports += 1
            checked += passed
        label = dialect_name if units is None else f"generic {units.value}, decimal {decimal!r}"
        print(f"\n{label} ({exports} exports, trajgen check passes {checked}/{exports})")
        digits = 9 if units is Units.METRES else 6
        for key in keys:
            if key.startswith("interpolated"):
                print(f"  {key:<27}{worst[key].ratio_text()} (not written: derived between the points)")
            elif units is None and dialect.interpolation is not Interpolation.VELOCITY:
                print(f"  {key:<27}- (positions only: no number with a limit)")
            else:
                print(f"  {key:<27}{worst[key].text(digits if units is not None else 9)}")


if __name__ == "__main__":
    main()
