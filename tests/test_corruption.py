"""Every number a schedule holds is checked: a corrupted float array is refused, or changes nothing exported.

For each method on the swap and the crossing, every float array reachable from
the schedule (:func:`tests.support.corruption.float_arrays`) gets, in turn, a NaN, +inf,
-inf, two adjacent entries swapped, and one entry moved by 1e-3 of its value, at a
seeded place, with nothing recomputed. Each corrupted schedule must either fail
:func:`trajgen.verification.certify` with a :class:`VerificationError` whose details name the
array, or export the very same CSV bytes as the original.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from tests.conftest import REPO
from tests.support.corruption import CORRUPTIONS, corrupt_array, corrupted, float_arrays, names
from trajgen import Exact, Optimal, Toppra, certify, load_scenario
from trajgen.errors import VerificationError
from trajgen.export.csv import CsvOptions, render_profile
from trajgen.model.schedule import CubicKinematics

SCENARIOS = {"swap": REPO / "examples" / "swap.toml", "crossing": REPO / "examples" / "crossing.toml"}
#: a generous budget: the test is about the optimal method's own schedule, not its fallback
METHODS = {"exact": Exact(), "toppra": Toppra(), "optimal": Optimal()}
#: a coarse period keeps the export cheap; any change of the motion shows in some row
OPTIONS = CsvOptions(sample_period=0.05)
SEED = 2026


@functools.cache
def schedule_of(scenario: str, method: str):
    loaded = load_scenario(SCENARIOS[scenario])
    schedule = METHODS[method].schedule(loaded.route(), loaded.limits)
    assert schedule.fallback_reason is None, schedule.notes
    return schedule


def exported(schedule) -> tuple[bytes, bytes]:
    verified = certify(schedule)
    return render_profile(verified, 0, OPTIONS), render_profile(verified, 1, OPTIONS)


@pytest.mark.parametrize(
    ("path", "message", "expected"),
    [
        (
            "sections[0].kinematics.vehicles[1].times",
            "sections[0].kinematics.vehicles[1].times[4] is nan",
            True,
        ),
        (
            "sections[0].kinematics.vehicles[1].jerk",
            "sections[0].kinematics.vehicles[1].{times,initial,jerk}",
            True,
        ),
        (
            "sections[0].kinematics.vehicles[1].jerk",
            "sections[0].kinematics.vehicles[0].{times,initial,jerk}",
            False,
        ),
        ("sections[0].maps[1].s_start", "sections[0].maps[1].{axis_start,axis_end,s_start} interval 2", True),
        ("sections[0].maps[1].s_start", "sections[0].maps[1].s_start_other", False),
        (
            "sections[0].kinematics.path.blends[2].corner",
            "differs from sections[0].kinematics.path.{vertices,blends}",
            True,
        ),
        ("sections[1].kinematics.grid", "sections[10].kinematics.{grid,speed,times}", False),
    ],
    ids=[
        "exact-path",
        "braces",
        "other-vehicle",
        "map-braces",
        "longer-name",
        "list-of-objects",
        "other-section",
    ],
)
def test_names_recognizes_the_array_and_nothing_else(path, message, expected):
    assert names(message, path) is expected


def corruptions(schedule):
    """(path, kind, corrupted schedule) for every float array and every corruption, seeded."""
    rng = np.random.default_rng(SEED)
    for path, array in float_arrays(schedule):
        for kind in CORRUPTIONS:
            bad = corrupt_array(array, kind, rng)
            if bad is not None:
                yield path, kind, corrupted(schedule, path, bad)


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("scenario", list(SCENARIOS))
def test_every_corruption_is_refused_by_name_or_changes_nothing_exported(scenario, method):
    schedule = schedule_of(scenario, method)
    original = exported(schedule)
    slipped, unnamed, refused, unchanged = [], [], 0, 0
    for path, kind, mutant in corruptions(schedule):
        try:
            files = exported(mutant)
        except VerificationError as error:
            refused += 1
            if not names("; ".join(error.details), path):
                unnamed.append(f"{path} ({kind}): {str(error)[:300]}")
            continue
        if files != original:
            slipped.append(f"{path} ({kind})")
        else:
            unchanged += 1
    assert not slipped, f"{len(slipped)} corruptions pass verify and change the CSV: {slipped}"
    assert not unnamed, f"{len(unnamed)} refusals do not name the array: {unnamed}"
    # the walk reached the motion: every kinematics array of every section was corrupted and refused
    assert refused >= 5 * 3 * len(schedule.sections), (refused, unchanged)


def test_the_walk_reaches_every_array_that_defines_the_motion():
    schedule = schedule_of("swap", "exact")
    paths = {path for path, _ in float_arrays(schedule)}
    for k, section in enumerate(schedule.sections):
        assert isinstance(section.kinematics, CubicKinematics)
        for vehicle in range(2):
            for name in ("times", "initial", "jerk"):
                assert f"sections[{k}].kinematics.vehicles[{vehicle}].{name}" in paths
            for name in ("axis_start", "axis_end", "s_start"):
                assert f"sections[{k}].maps[{vehicle}].{name}" in paths
    toppra = {path for path, _ in float_arrays(schedule_of("swap", "toppra"))}
    assert {"sections[0].kinematics.grid", "sections[0].kinematics.path.vertices"} <= toppra
    assert any(path.startswith("sections[0].kinematics.path.blends[") for path in toppra)


def test_a_corrupted_copy_leaves_the_original_and_every_cache_as_they_were():
    schedule = schedule_of("swap", "toppra")
    path = "sections[0].kinematics.path.vertices"
    vertices = np.array(schedule.sections[0].kinematics.path.vertices)
    vertices[-1] += 0.5
    mutant = corrupted(schedule, path, vertices)
    assert mutant.sections[0].kinematics.path.vertices[-1, 0] == vertices[-1, 0]
    assert schedule.sections[0].kinematics.path.vertices[-1, 0] == vertices[-1, 0] - 0.5
    # the path's tables were not rebuilt: the verifier must see that they disagree with its data
    with pytest.raises(VerificationError, match="the path of section 1 of 2") as caught:
        certify(mutant)
    assert any("sections[0].kinematics.path." in detail for detail in caught.value.details)
