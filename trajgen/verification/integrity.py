"""A schedule's own numbers, checked before the verifier reads any motion from them.

Every float a schedule's sections hold must be finite, every knot sequence
must increase, each vehicle's profile must end with its section, and every
array derived from others must agree with them: a TOPPRA section's knot times
with its grid and path speeds, a path's piece tables (fields a dataclass
derives in ``__post_init__``) with what its constructor derives from its data.
A failure names the array by its path from the schedule, for example
``sections[2].kinematics.vehicles[0].times[4] is nan``.

The motion itself (limits, separation, continuity, start and goal, homotopy
class) is checked afterwards by :mod:`trajgen.verification`, whose failures name
the arrays of the interval where they occur.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from trajgen.model.blended import BlendedPath, ToppraKinematics
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import AxisMap, CubicKinematics, Schedule

__all__ = ["array_failures"]

#: Relative round-off allowed between a TOPPRA section's knot times and those its grid and speeds give.
_TIME_CONSISTENCY = 1e-9


def _index(array: np.ndarray, flat: int) -> str:
    return ", ".join(str(int(i)) for i in np.unravel_index(flat, array.shape))


def _finite(array: np.ndarray, path: str, failures: list[str]) -> bool:
    """Whether every entry is finite; else a failure naming the first that is not."""
    values = np.asarray(array, dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        k = int(bad[0])
        more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
        failures.append(
            f"{path}[{_index(values, k)}] is {float(values.flat[k])!r}{more}: expected a finite number"
        )
        return False
    return True


def _shape(array: np.ndarray, path: str, shape: tuple[int | None, ...], failures: list[str]) -> bool:
    actual = np.shape(array)
    if len(actual) != len(shape) or any(
        want is not None and got != want for got, want in zip(actual, shape, strict=True)
    ):
        expected = "(" + ", ".join("m" if want is None else str(want) for want in shape) + ")"
        failures.append(f"{path} has shape {actual}: expected {expected}")
        return False
    return True


def _increasing(times: np.ndarray, path: str, failures: list[str], *, strictly: bool = True) -> bool:
    steps = np.diff(times)
    bad = np.flatnonzero(~(steps > 0.0) if strictly else ~(steps >= 0.0))
    if bad.size:
        k = int(bad[0])
        failures.append(
            f"{path} does not increase at [{k + 1}] ({float(times[k])!r}, then {float(times[k + 1])!r}): "
            f"expected {'strictly ' if strictly else ''}increasing values"
        )
        return False
    return True


def _derived_fields(value: object, path: str, failures: list[str]) -> None:
    """Fields a dataclass derives itself (``init=False``) equal what its constructor derives anew."""
    fields = dataclasses.fields(value)  # type: ignore[arg-type]
    data = [f.name for f in fields if f.init]
    derived = [f.name for f in fields if not f.init]
    if not derived:
        return
    given = f"{path}.{{{','.join(data)}}}"
    try:
        rebuilt = type(value)(**{name: getattr(value, name) for name in data})
    except (ValueError, TypeError, ArithmeticError) as error:
        failures.append(f"{given} do not form a {type(value).__name__}: {error}")
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
        failures.append(f"{path}.{{{','.join(differ)}}} disagree with {given}: expected what the data give")


def _profile(profile: object, path: str, failures: list[str]) -> float | None:
    """Checks of one piecewise cubic; its end time if it moves (``None`` for a zero-length profile)."""
    if type(profile) is not PiecewiseCubic:
        failures.append(f"{path} is a {type(profile).__name__}: expected a PiecewiseCubic")
        return None
    times, initial, jerk = profile.times, profile.initial, profile.jerk
    if not _shape(times, f"{path}.times", (None,), failures):
        return None
    if times.size < 2:
        failures.append(f"{path}.times has {times.size} knots: expected at least 2")
        return None
    intervals = times.size - 1
    if not (
        _shape(initial, f"{path}.initial", (intervals, 3), failures)
        and _shape(jerk, f"{path}.jerk", (intervals,), failures)
    ):
        return None
    finite = [
        _finite(values, f"{path}.{name}", failures)
        for name, values in (("times", times), ("initial", initial), ("jerk", jerk))
    ]
    if not all(finite):
        return None
    if times[0] != 0.0:
        failures.append(
            f"{path}.times[0] is {float(times[0])!r}: expected 0 (each section keeps its own clock)"
        )
        return None
    if times.size == 2 and times[1] == 0.0:
        return None  # at rest for no time: a vehicle with nothing to do in the section
    if not _increasing(times, f"{path}.times", failures):
        return None
    return float(times[-1])


def _cubic(kinematics: CubicKinematics, path: str, failures: list[str]) -> None:
    ends = [
        _profile(profile, f"{path}.vehicles[{v}]", failures) for v, profile in enumerate(kinematics.vehicles)
    ]
    moving = [(v, end) for v, end in enumerate(ends) if end is not None]
    if len(moving) == 2 and abs(moving[0][1] - moving[1][1]) > 1e-12 * max(1.0, moving[0][1]):
        failures.append(
            f"{path}.vehicles[0].times ends at {moving[0][1]!r} s and {path}.vehicles[1].times at "
            f"{moving[1][1]!r} s: expected both vehicles' profiles to end with their section"
        )


def _toppra(kinematics: ToppraKinematics, path: str, failures: list[str]) -> None:
    grid, speed, times = kinematics.grid, kinematics.speed, kinematics.times
    if not all(
        _shape(values, f"{path}.{name}", (None,), failures)
        for name, values in (("grid", grid), ("speed", speed), ("times", times))
    ):
        return
    if not grid.size == speed.size == times.size or grid.size < 2:
        failures.append(
            f"{path}.grid, .speed and .times have {grid.size}, {speed.size} and {times.size} entries: "
            "expected the same number, at least 2"
        )
        return
    if not all(
        _finite(values, f"{path}.{name}", failures)
        for name, values in (("grid", grid), ("speed", speed), ("times", times))
    ):
        return
    for name, values in (("grid", grid), ("times", times)):
        if values[0] != 0.0:
            failures.append(f"{path}.{name}[0] is {float(values[0])!r}: expected 0")
            return
        if not _increasing(values, f"{path}.{name}", failures):
            return
    if np.any(speed < 0.0):
        k = int(np.argmax(speed < 0.0))
        failures.append(
            f"{path}.speed[{k}] is {float(speed[k])!r}: expected >= 0 (the path is driven forwards)"
        )
        return
    # constant path acceleration between grid points: each interval lasts 2 ds / (speed before + after)
    with np.errstate(divide="ignore"):
        expected = 2.0 * np.diff(grid) / (speed[:-1] + speed[1:])
    allowed = _TIME_CONSISTENCY * expected + 64.0 * np.spacing(max(1.0, float(times[-1])))
    off = np.flatnonzero(~(np.abs(np.diff(times) - expected) <= allowed))
    if off.size:
        k = int(off[0])
        failures.append(
            f"{path}.{{grid,speed,times}} disagree at interval {k}: it lasts "
            f"{float(times[k + 1] - times[k])!r} s by the times and {float(expected[k])!r} s by the grid "
            "and speeds: expected knot times that agree with them"
        )
    path_object = kinematics.path
    if type(path_object) is not BlendedPath:
        failures.append(f"{path}.path is a {type(path_object).__name__}: expected a BlendedPath")
        return
    if not _finite(path_object.vertices, f"{path}.path.vertices", failures):
        return
    for k, blend in enumerate(path_object.blends):
        if blend is not None:
            for name in ("before", "corner", "after"):
                if not _finite(getattr(blend, name), f"{path}.path.blends[{k}].{name}", failures):
                    return
    _derived_fields(path_object, f"{path}.path", failures)
    if not abs(grid[-1] - path_object.length) <= 1e-9 * max(1.0, path_object.length):
        failures.append(
            f"{path}.grid ends at {float(grid[-1])!r} m but its path is {float(path_object.length)!r} m "
            "long: expected the grid to cover the path"
        )


def _axis_map(axis_map: object, path: str, failures: list[str]) -> None:
    if type(axis_map) is not AxisMap:
        failures.append(f"{path} is a {type(axis_map).__name__}: expected an AxisMap")
        return
    for name in ("axis_start", "axis_end", "s_start"):
        _finite(getattr(axis_map, name), f"{path}.{name}", failures)


def _kinematics(kinematics: object, path: str, failures: list[str]) -> None:
    if type(kinematics) is CubicKinematics:
        _cubic(kinematics, path, failures)
    elif type(kinematics) is ToppraKinematics:
        _toppra(kinematics, path, failures)
    # any other kind is refused by the verifier as uncheckable


def array_failures(schedule: Schedule) -> list[str]:
    """Every failure of the schedule's own numbers, each naming its array.

    Parameters
    ----------
    schedule : Schedule

    Returns
    -------
    list of str
        Empty if every array is finite, ordered and consistent.
    """
    failures: list[str] = []
    if not schedule.sections:
        return ["sections is empty: expected at least one section"]
    clock: float | None = 0.0  # where the previous section ends, None once a section is broken
    for i, section in enumerate(schedule.sections):
        where = f"sections[{i}]"
        start = section.start_time
        count = len(failures)
        if not (isinstance(start, (int, float)) and math.isfinite(start)):
            failures.append(f"{where}.start_time is {float(start)!r}: expected a finite number of seconds")
        _kinematics(section.kinematics, f"{where}.kinematics", failures)
        for vehicle, axis_map in enumerate(section.maps):
            _axis_map(axis_map, f"{where}.maps[{vehicle}]", failures)
        if len(failures) > count:
            clock = None
            continue
        if clock is not None and not abs(start - clock) <= 1e-9 * max(1.0, clock):
            failures.append(
                f"{where}.start_time is {float(start)!r} s: expected {float(clock)!r} s, "
                "where the section before it ends"
            )
        clock = start + section.duration
    return failures
