"""The verifier's mutation table: mutants of valid schedules, caught or passed, closed form vs 1 ms samples.

Run from the repository root: ``python benchmarks/bench_mutants.py``. The mutants
are built with ``tests/support/mutants.py``; the sampled second opinion is
``tests/support/sampled_verifier.py`` (it sees only its 1 ms samples).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # the tests' helpers

from limits import Limits, VehicleLimits
from tests.support.helpers import LIMITS, route_of, too_close
from tests.support.mutants import between_samples, free_window, with_bump, with_coefficient
from tests.support.sampled_verifier import sampled_verify
from topology.indexed import track_distance
from trajgen import Exact, Optimal, Schedule, verify
from trajgen.progress import progress

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


def with_section(schedule: Schedule, index: int, **changes) -> Schedule:
    sections = list(schedule.sections)
    sections[index] = dataclasses.replace(sections[index], **changes)
    return dataclasses.replace(schedule, sections=tuple(sections))


def mutants():
    exact = Exact().schedule(route_of(*SWAP), LIMITS)
    optimal = Optimal().schedule(route_of(*SWAP), LIMITS)
    cruise = between_samples(exact, 0.5 * exact.sections[0].duration)
    mover = int(np.argmax(np.abs(exact.state([cruise]).velocity[:, 0])))
    state = optimal.sample(1e-3)
    near = float(state.t[int(np.argmin(track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])))])
    far = int(np.argmax(optimal.state([near]).s[:, 0]))
    section = next(s for s in optimal.sections if s.start_time <= near < s.start_time + s.duration)
    inward = -int(section.maps[far].outward[0])
    window = free_window(optimal, far, near)
    yield (
        "1 % velocity spike, 0.8 ms between samples",
        with_bump(exact, mover, cruise, 0.8e-3, 0.01 * 0.2e-3),
        True,
    )
    yield "0.1 % velocity spike, 0.8 ms", with_bump(exact, mover, cruise, 0.8e-3, 0.001 * 0.2e-3), True
    yield (
        "1 mm separation dip, 0.8 ms between samples",
        with_bump(optimal, far, window, 0.8e-3, inward * 1e-3),
        True,
    )
    yield "1 um separation dip, 0.8 ms", with_bump(optimal, far, window, 0.8e-3, inward * 1e-6), True
    yield (
        "full collision, 0.8 ms between samples",
        with_bump(optimal, far, window, 0.8e-3, inward * 2.0),
        True,
    )
    for column, name in ((0, "position"), (1, "velocity"), (2, "acceleration")):
        yield f"NaN in one {name} coefficient", with_coefficient(exact, 1, column, math.nan)[0], True
        yield f"inf in one {name} coefficient", with_coefficient(exact, 1, column, math.inf)[0], True
    fast = VehicleLimits(1.2, 0.6, 1.2)
    quick = Exact().schedule(route_of(*SWAP), Limits((fast, fast), min_separation=1.5))
    yield "20 % too fast throughout", Schedule(quick.route, LIMITS, quick.method, quick.sections, True), True
    yield "closer than asked (10.5 m)", too_close(exact), True
    other = route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "C:10"))
    yield "wrong goal", Schedule(other, LIMITS, exact.method, exact.sections, True), True
    first, second = exact.sections[1].maps
    shifted = dataclasses.replace(first, s_start=np.array(first.s_start) + 0.5)
    yield "position map shifted 0.5 m (a jump)", with_section(exact, 1, maps=(shifted, second)), True
    earlier = exact.sections[1].start_time - 1.0
    yield "sections overlapping by 1 s", with_section(exact, 1, start_time=earlier), True
    yield "0.1 nm bump over 40 ms (inside tolerances)", with_bump(exact, mover, cruise, 40e-3, 1e-10), False
    yield "the valid optimal swap", optimal, False


def main() -> None:
    print("| mutant | closed-form verifier | sampled every 1 ms | right? |")
    print("| --- | --- | --- | --- |")
    wrong = 0
    cases = list(mutants())
    for name, schedule, defective in progress(cases, description="mutants"):
        closed, sampled = verify(schedule).passed, sampled_verify(schedule).passed
        right = closed is not defective
        wrong += not right
        closed_text = "caught" if not closed else "passed"
        sampled_text = "caught" if not sampled else ("missed" if defective else "passed")
        tqdm.write(
            f"| {name} | {closed_text} | {sampled_text} | {'yes' if right else 'NO'} |"
        )  # above the bar
    print(f"\nverifier verdicts wrong: {wrong} (target 0)")


if __name__ == "__main__":
    main()
