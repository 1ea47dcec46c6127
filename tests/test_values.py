"""Results are honest values: read-only arrays, value equality that never raises, hashes that agree."""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.helpers import LIMITS, route_of
from trajgen import Exact, Optimal, Toppra
from trajgen.model.axes import route_axes

SWAP = ((10.0, 10.0, 10.0), ("A:10", "B:10"), ("B:10", "A:10"))


@pytest.mark.parametrize("method", [Exact(), Toppra(), Optimal()], ids=["exact", "toppra", "optimal"])
def test_equal_computations_give_equal_schedules_with_equal_hashes(method):
    first = method.schedule(route_of(*SWAP), LIMITS)
    second = method.schedule(route_of(*SWAP), LIMITS)
    assert first is not second
    assert first == second
    assert hash(first) == hash(second)
    assert len({first, second}) == 1


def test_different_schedules_compare_unequal():
    route = route_of(*SWAP)
    assert Exact().schedule(route, LIMITS) != Exact(jerk=False).schedule(route, LIMITS)
    assert Exact().schedule(route, LIMITS) != Toppra().schedule(route, LIMITS)
    assert Exact().schedule(route, LIMITS) != "a schedule"


@pytest.mark.parametrize("method", [Exact(), Toppra(), Optimal()], ids=["exact", "toppra", "optimal"])
def test_arrays_inside_a_schedule_are_read_only(method):
    schedule = method.schedule(route_of(*SWAP), LIMITS)
    with pytest.raises(ValueError, match="read-only"):
        schedule.sections[0].maps[0].legs[0] = 2
    kinematics = schedule.sections[0].kinematics
    arrays = (
        [profile.initial for profile in kinematics.vehicles]
        if hasattr(kinematics, "vehicles")
        else [kinematics.speed, kinematics.times, kinematics.path.vertices]
    )
    for array in arrays:
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0
    state = schedule.state([0.0, 1.0])
    with pytest.raises(ValueError, match="read-only"):
        state.s[0, 0] = 5.0


def test_a_schedule_does_not_share_memory_with_its_inputs():
    axes = route_axes(route_of(*SWAP))
    with pytest.raises(ValueError, match="read-only"):
        axes.axes[0, 0] = 1.0
    source = np.array([0.0, 1.0])
    from trajgen.model.schedule import AxisMap

    mapped = AxisMap(source, source, np.array([0, 0]), source, np.array([1, 1]))
    source[0] = 9.0
    assert mapped.axis_start[0] == 0.0


def test_frozen_fields_cannot_be_rebound():
    schedule = Exact().schedule(route_of(*SWAP), LIMITS)
    with pytest.raises(AttributeError):
        schedule.sections = ()  # type: ignore[misc]


def test_equality_and_hash_agree_on_signed_zero_and_nan():
    from trajgen.model.schedule import AxisMap

    parked = AxisMap.parked(0.0, 1, 2.0)
    assert parked == parked.flipped()
    assert hash(parked) == hash(parked.flipped())
    # (an axis map refuses a NaN; a sampled state may hold one, e.g. of an executed motion)
    from trajgen.model.schedule import ScheduleState

    def state(value):
        one = np.array([[value], [1.0]])
        return ScheduleState(np.array([0.0]), one, one, one, one, np.zeros((2, 1), dtype=int), one)

    with_nan, twin = state(np.nan), state(-np.nan)
    assert with_nan == twin
    assert hash(with_nan) == hash(twin)


def test_sampled_states_cannot_be_written_through_their_base():
    state = Exact().schedule(route_of(*SWAP), LIMITS).state([0.0, 5.0, 10.0])
    for array in (state.axis, state.velocity, state.acceleration, state.jerk, state.leg, state.s, state.t):
        base = array if array.base is None else array.base
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 1
        with pytest.raises(ValueError, match="read-only"):
            base.flat[0] = 1
    with pytest.raises(ValueError, match="cannot set WRITEABLE flag"):
        state.velocity.flags.writeable = True  # a view of a read-only buffer stays read-only


def test_a_state_built_from_the_callers_arrays_copies_them():
    from trajgen.model.schedule import ScheduleState

    mine = np.zeros((2, 3))
    state = ScheduleState(np.zeros(3), mine, mine, mine, mine, np.zeros((2, 3), dtype=int), mine)
    mine[0, 0] = 7.0
    assert state.axis[0, 0] == 0.0
    assert mine.flags.writeable


def test_routes_with_different_indexed_data_are_different_values():
    import dataclasses

    from topology import PositionError

    route = route_of(*SWAP)
    other = route_of((10.0, 10.0, 10.0), ("A:10", "B:10"), ("A:10", "C:5"))
    forged = dataclasses.replace(
        route,
        indexed_waypoints=other.indexed_waypoints[:1] * len(route.waypoints),
    )
    assert forged != route
    with pytest.raises(PositionError, match=r"one indexed waypoint and one cumulative travel per waypoint"):
        dataclasses.replace(route, indexed_waypoints=other.indexed_waypoints)
