"""A schedule's own numbers, checked before the verifier reads any motion from them.

Every float a schedule's sections hold must be finite, every knot sequence
must increase, each vehicle's profile must end with its section, and every
array derived from others must agree with them: a TOPPRA section's knot times
with its grid and path speeds, a path's piece tables (fields a dataclass
derives in ``__post_init__``) with what its constructor derives from its data.
A failure says in words whose numbers are broken and how (``vehicle 1's knot times in
section 2 hold nan: expected finite numbers``); its details name the array by its path from
the schedule, for example ``sections[1].kinematics.vehicles[0].times[4] is nan``.

The motion itself (limits, separation, continuity, start and goal, the route's class) is
checked afterwards by :mod:`trajgen.verification`, whose failures' details name the arrays of
the interval where they occur.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from trajgen.model.blended import BlendedPath, ToppraKinematics
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import AxisMap, CubicKinematics
from trajgen.verification.report import Finding

__all__ = ["array_failures", "count_failures"]

#: Relative round-off allowed between a TOPPRA section's knot times and those its grid and speeds give.
_TIME_CONSISTENCY = 1e-9


class _Array(NamedTuple):
    """Some numbers of a schedule: their path from it (for the details) and their name in words."""

    path: str
    words: str

    def field(self, name: str, words: str) -> _Array:
        """A field of these numbers: ``path.name``, named ``words``."""
        return _Array(f"{self.path}.{name}", words)


def _fail(failures: list[str], message: str, detail: str) -> None:
    failures.append(Finding(message, detail))


def _index(array: np.ndarray, flat: int) -> str:
    return ", ".join(str(int(i)) for i in np.unravel_index(flat, array.shape))


def _finite(array: np.ndarray, where: _Array, failures: list[str]) -> bool:
    """Whether every entry is finite; else a failure naming the first that is not."""
    values = np.asarray(array, dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        k = int(bad[0])
        more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
        value = float(values.flat[k])
        _fail(
            failures,
            f"{where.words} hold {value!r}{more}: expected finite numbers",
            f"{where.path}[{_index(values, k)}] is {value!r}{more}: expected a finite number",
        )
        return False
    return True


def _shape(array: np.ndarray, where: _Array, shape: tuple[int | None, ...], failures: list[str]) -> bool:
    actual = np.shape(array)
    if len(actual) != len(shape) or any(
        want is not None and got != want for got, want in zip(actual, shape, strict=True)
    ):
        expected = "(" + ", ".join("m" if want is None else str(want) for want in shape) + ")"
        _fail(
            failures,
            f"{where.words} are malformed: {actual} numbers where {expected} are expected",
            f"{where.path} has shape {actual}: expected {expected}",
        )
        return False
    return True


def _increasing(times: np.ndarray, where: _Array, failures: list[str], *, strictly: bool = True) -> bool:
    steps = np.diff(times)
    bad = np.flatnonzero(~(steps > 0.0) if strictly else ~(steps >= 0.0))
    if bad.size:
        k = int(bad[0])
        values = f"({float(times[k])!r}, then {float(times[k + 1])!r})"
        expected = f"expected {'strictly ' if strictly else ''}increasing values"
        _fail(
            failures,
            f"{where.words} do not increase at number {k + 2} {values}: {expected}",
            f"{where.path} does not increase at [{k + 1}] {values}: {expected}",
        )
        return False
    return True


def _derived_fields(value: object, where: _Array, failures: list[str]) -> None:
    """Fields a dataclass derives itself (``init=False``) equal what its constructor derives anew."""
    fields = dataclasses.fields(value)  # type: ignore[arg-type]
    data = [f.name for f in fields if f.init]
    derived = [f.name for f in fields if not f.init]
    if not derived:
        return
    given = f"{where.path}.{{{','.join(data)}}}"
    try:
        rebuilt = type(value)(**{name: getattr(value, name) for name in data})
    except (ValueError, TypeError, ArithmeticError) as error:
        _fail(
            failures,
            f"{where.words} cannot be built from its numbers: {error}",
            f"{given} do not form a {type(value).__name__}: {error}",
        )
        return
    differ = []
    for name in derived:
        stored, fresh = getattr(value, name), getattr(rebuilt, name)
        if isinstance(stored, np.ndarray) or isinstance(fresh, np.ndarray):
            same = np.shape(stored) == np.shape(fresh) and bool(np.array_equal(stored, fresh))
        else:
            same = stored == fresh
        if not same:
            differ.append(name)
    if differ:
        _fail(
            failures,
            f"{where.words} holds tables that disagree with its own data: expected what the data give",
            f"{where.path}.{{{','.join(differ)}}} disagree with {given}: expected what the data give",
        )


def _wrong_type(value: object, where: _Array, expected: str, failures: list[str]) -> None:
    _fail(
        failures,
        f"{where.words} are a {type(value).__name__}, which the verifier does not know: "
        f"expected a {expected}",
        f"{where.path} is a {type(value).__name__}: expected a {expected}",
    )


def _profile(profile: object, where: _Array, failures: list[str]) -> float | None:
    """Checks of one piecewise cubic; its end time if it moves (``None`` for a zero-length profile)."""
    if type(profile) is not PiecewiseCubic:
        _wrong_type(profile, where, "PiecewiseCubic", failures)
        return None
    times, initial, jerk = profile.times, profile.initial, profile.jerk
    knots = where.field("times", f"{where.words}: its knot times")
    if not _shape(times, knots, (None,), failures):
        return None
    if times.size < 2:
        _fail(
            failures,
            f"{knots.words} number {times.size}: expected at least 2",
            f"{knots.path} has {times.size} knots: expected at least 2",
        )
        return None
    intervals = times.size - 1
    states = where.field("initial", f"{where.words}: its states at the knots")
    jerks = where.field("jerk", f"{where.words}: its jerks")
    if not (
        _shape(initial, states, (intervals, 3), failures) and _shape(jerk, jerks, (intervals,), failures)
    ):
        return None
    finite = [
        _finite(values, array, failures)
        for array, values in ((knots, times), (states, initial), (jerks, jerk))
    ]
    if not all(finite):
        return None
    if times[0] != 0.0:
        _fail(
            failures,
            f"{knots.words} start at {float(times[0])!r} s: expected 0 (each section keeps its own clock)",
            f"{knots.path}[0] is {float(times[0])!r}: expected 0 (each section keeps its own clock)",
        )
        return None
    if times.size == 2 and times[1] == 0.0:
        return None  # at rest for no time: a vehicle with nothing to do in the section
    if not _increasing(times, knots, failures):
        return None
    return float(times[-1])


def _cubic(kinematics: CubicKinematics, where: _Array, section: str, failures: list[str]) -> None:
    ends = [
        _profile(
            profile,
            where.field(f"vehicles[{v}]", f"vehicle {v + 1}'s motion in {section}"),
            failures,
        )
        for v, profile in enumerate(kinematics.vehicles)
    ]
    moving = [(v, end) for v, end in enumerate(ends) if end is not None]
    if len(moving) == 2 and abs(moving[0][1] - moving[1][1]) > 1e-12 * max(1.0, moving[0][1]):
        _fail(
            failures,
            f"in {section}, vehicle 1's motion ends at {moving[0][1]!r} s and vehicle 2's at "
            f"{moving[1][1]!r} s: expected both to end with their section",
            f"{where.path}.vehicles[0].times ends at {moving[0][1]!r} s and {where.path}.vehicles[1].times "
            f"at {moving[1][1]!r} s: expected both vehicles' profiles to end with their section",
        )


def _toppra(kinematics: ToppraKinematics, where: _Array, section: str, failures: list[str]) -> None:
    grid, speed, times = kinematics.grid, kinematics.speed, kinematics.times
    arrays = {
        "grid": where.field("grid", f"the path positions of {section}"),
        "speed": where.field("speed", f"the path speeds of {section}"),
        "times": where.field("times", f"the knot times of {section}"),
    }
    values = {"grid": grid, "speed": speed, "times": times}
    if not all(_shape(values[name], arrays[name], (None,), failures) for name in arrays):
        return
    if not grid.size == speed.size == times.size or grid.size < 2:
        _fail(
            failures,
            f"the timing of {section} has {grid.size} path positions, {speed.size} speeds and "
            f"{times.size} times: expected the same number, at least 2",
            f"{where.path}.grid, .speed and .times have {grid.size}, {speed.size} and {times.size} "
            "entries: expected the same number, at least 2",
        )
        return
    if not all(_finite(values[name], arrays[name], failures) for name in arrays):
        return
    for name in ("grid", "times"):
        if values[name][0] != 0.0:
            first = float(values[name][0])
            _fail(
                failures,
                f"{arrays[name].words} start at {first!r}: expected 0",
                f"{arrays[name].path}[0] is {first!r}: expected 0",
            )
            return
        if not _increasing(values[name], arrays[name], failures):
            return
    if np.any(speed < 0.0):
        k = int(np.argmax(speed < 0.0))
        _fail(
            failures,
            f"{arrays['speed'].words} hold {float(speed[k])!r} at number {k + 1}: expected >= 0 "
            "(the path is driven forwards)",
            f"{arrays['speed'].path}[{k}] is {float(speed[k])!r}: expected >= 0 "
            "(the path is driven forwards)",
        )
        return
    # constant path acceleration between grid points: each interval lasts 2 ds / (speed before + after)
    with np.errstate(divide="ignore"):
        expected = 2.0 * np.diff(grid) / (speed[:-1] + speed[1:])
    allowed = _TIME_CONSISTENCY * expected + 64.0 * np.spacing(max(1.0, float(times[-1])))
    off = np.flatnonzero(~(np.abs(np.diff(times) - expected) <= allowed))
    if off.size:
        k = int(off[0])
        lasts = (
            f"{float(times[k + 1] - times[k])!r} s by the times and {float(expected[k])!r} s by the grid "
            "and speeds: expected knot times that agree with them"
        )
        _fail(
            failures,
            f"the timing of {section} disagrees with itself from t={float(times[k])!r} s: "
            f"a step lasts {lasts}",
            f"{where.path}.{{grid,speed,times}} disagree at interval {k}: it lasts {lasts}",
        )
    path_object = kinematics.path
    path = where.field("path", f"the path of {section}")
    if type(path_object) is not BlendedPath:
        _wrong_type(path_object, path, "BlendedPath", failures)
        return
    if not _finite(path_object.vertices, path.field("vertices", f"{path.words}: its corners"), failures):
        return
    for k, blend in enumerate(path_object.blends):
        if blend is not None:
            for name in ("before", "corner", "after"):
                array = path.field(f"blends[{k}].{name}", f"{path.words}: its blend at corner {k + 1}")
                if not _finite(getattr(blend, name), array, failures):
                    return
    _derived_fields(path_object, path, failures)
    if not abs(grid[-1] - path_object.length) <= 1e-9 * max(1.0, path_object.length):
        _fail(
            failures,
            f"{arrays['grid'].words} end at {float(grid[-1])!r} m but the path is "
            f"{float(path_object.length)!r} m long: expected them to cover the path",
            f"{where.path}.grid ends at {float(grid[-1])!r} m but its path is "
            f"{float(path_object.length)!r} m long: expected the grid to cover the path",
        )


def _axis_map(axis_map: object, where: _Array, failures: list[str]) -> None:
    if type(axis_map) is not AxisMap:
        _wrong_type(axis_map, where, "AxisMap", failures)
        return
    for name in ("axis_start", "axis_end", "s_start"):
        _finite(getattr(axis_map, name), where.field(name, where.words), failures)


def _kinematics(kinematics: object, where: _Array, section: str, failures: list[str]) -> None:
    if type(kinematics) is CubicKinematics:
        _cubic(kinematics, where, section, failures)
    elif type(kinematics) is ToppraKinematics:
        _toppra(kinematics, where, section, failures)
    # any other kind is refused by the verifier as uncheckable


def array_failures(schedule) -> list[str]:
    """Every failure of the schedule's own numbers, each naming its array in its details.

    Parameters
    ----------
    schedule : Schedule or GraphSchedule

    Returns
    -------
    list of str
        Empty if every array is finite, ordered and consistent; else
        :class:`~trajgen.verification.report.Finding` objects.
    """
    failures: list[str] = []
    if not schedule.sections:
        return ["the schedule has no section: expected at least one"]
    clock: float | None = 0.0  # where the previous section ends, None once a section is broken
    count_all = len(schedule.sections)
    for i, section_object in enumerate(schedule.sections):
        where = f"sections[{i}]"
        start = section_object.start_time
        section = f"section {i + 1} of {count_all}"
        if isinstance(start, (int, float)) and math.isfinite(start):
            section += f" (from t={float(start):.3f} s)"
        count = len(failures)
        if not (isinstance(start, (int, float)) and math.isfinite(start)):
            _fail(
                failures,
                f"section {i + 1} of {count_all} starts at t={float(start)!r} s: expected a finite number "
                "of seconds",
                f"{where}.start_time is {float(start)!r}: expected a finite number of seconds",
            )
        _kinematics(section_object.kinematics, _Array(f"{where}.kinematics", ""), section, failures)
        for vehicle, axis_map in enumerate(getattr(section_object, "maps", ())):  # a star's sections
            words = f"vehicle {vehicle + 1}'s track map (where its axis lies on the track) in {section}"
            _axis_map(axis_map, _Array(f"{where}.maps[{vehicle}]", words), failures)
        if len(failures) > count:
            clock = None
            continue
        if clock is not None and not abs(start - clock) <= 1e-9 * max(1.0, clock):
            expected = f"expected {float(clock)!r} s, where the section before it ends"
            _fail(
                failures,
                f"section {i + 1} of {count_all} starts at t={float(start)!r} s: {expected}",
                f"{where}.start_time is {float(start)!r} s: {expected}",
            )
        clock = start + section_object.duration
    return failures


def count_failures(schedule) -> list[str]:
    """A track graph's schedule has a path for every vehicle its route moves, and moves each in every section.

    Parameters
    ----------
    schedule : GraphSchedule

    Returns
    -------
    list of str
        Empty if the counts agree; else :class:`~trajgen.verification.report.Finding` objects naming
        the arrays.
    """
    moved = len(schedule.route.start)
    failures: list[str] = []
    if len(schedule.paths) != moved:
        failures.append(
            Finding(
                f"the schedule has {len(schedule.paths)} path(s), its route moves {moved} vehicle(s): "
                "expected one per vehicle",
                "paths",
            )
        )
    for k, section in enumerate(schedule.sections):
        kinematics = section.kinematics
        if type(kinematics) is CubicKinematics:
            count = len(kinematics.vehicles)
        elif type(kinematics) is ToppraKinematics:
            count = kinematics.path.dof
        else:
            continue  # refused as kinematics the verifier does not know, below
        if count != moved:
            failures.append(
                Finding(
                    f"section {k + 1} moves {count} vehicle(s), the route {moved}: expected one per vehicle",
                    f"sections[{k}].kinematics",
                )
            )
    return failures
