"""Would a junction's schedule keep its CSV bytes as travel along graph paths? The axis, cell by cell.

Run: ``python benchmarks/bench_travel_axis.py``.

A junction's schedule holds each vehicle's signed axis as cubics; a track graph's holds its travel
``p`` (never decreasing) and gives the axis back through its path (``axis = axis_start + heading *
(p - start)`` per segment, the heading flipping where the vehicle turns back). This evaluates every
cubic of the exact swap, the crossing and swaps on legs of 10, 100 and 1,000 m both ways, at the
generic CSV's 10 ms rows: as the junction does (``p0 + H``) and as the graph model would (the
travel cubic ``offset + sign * p0`` plus ``sign * H``, then the axis back from the travel), and
prints how many axis cells differ once written with the CSV's 9 decimals.
"""

from __future__ import annotations

import numpy as np

from limits import Limits, VehicleLimits
from topology import Configuration, Position, YGraph, plan
from trajgen import Exact, load_scenario
from trajgen.model.schedule import CubicKinematics

ROW_PERIOD = 0.01


def _text(values: np.ndarray) -> np.ndarray:
    return np.char.mod("%.9f", np.round(values, 9) + 0.0)


def _schedules():
    for name in ("swap", "crossing"):
        scenario = load_scenario(f"examples/{name}.toml")
        yield name, Exact().schedule(scenario.route(), scenario.limits)
    vehicle = VehicleLimits(max_velocity=1.0, max_acceleration=0.5, max_jerk=1.0)
    limits = Limits(vehicles=(vehicle, vehicle), min_separation=1.5)
    for length in (10.0, 100.0, 1000.0):
        track = YGraph({"A": length, "B": length, "C": length})
        a, b = Position("A", length), Position("B", length)
        route = plan(track, Configuration(a, b), Configuration(b, a), min_separation=1.5)
        yield f"swap on {length:g} m legs", Exact().schedule(route, limits)


def _differing(schedule) -> tuple[int, int]:
    """Axis cells of the rows that differ, and all of them."""
    differing = total = 0
    for vehicle in range(2):
        axis_start, start, sign = None, 0.0, 1.0
        for section in schedule.sections:
            assert type(section.kinematics) is CubicKinematics
            profile = section.kinematics.vehicles[vehicle]
            for k in range(len(profile.jerk)):
                p0, v0, a0 = profile.initial[k]
                jerk = profile.jerk[k]
                duration = profile.times[k + 1] - profile.times[k]
                if duration <= 0.0:
                    continue
                begin = section.start_time + profile.times[k]
                t = np.arange(np.ceil(begin / ROW_PERIOD) * ROW_PERIOD, begin + duration, ROW_PERIOD)
                h = t - begin
                step = h * (v0 + h * (a0 / 2.0 + h * jerk / 6.0))
                moving = 1.0 if v0 + 0.5 * duration * a0 + duration**2 * jerk / 6.0 >= 0.0 else -1.0
                if axis_start is None:
                    axis_start, sign = p0, moving
                elif moving != sign:  # a turn: the path's next segment starts here
                    start, axis_start, sign = start + sign * (p0 - axis_start), p0, moving
                travel = (start - sign * axis_start + sign * p0) + sign * step
                back = axis_start + sign * (travel - start)
                differing += int(np.sum(_text(p0 + step) != _text(back)))
                total += t.size
    return differing, total


def main() -> None:
    print(f"{'schedule':>24} {'axis cells':>11} {'differing':>10}")
    for name, schedule in _schedules():
        differing, total = _differing(schedule)
        print(f"{name:>24} {total:>11,} {differing:>10,}")


if __name__ == "__main__":
    main()
