"""The planner's indexed form: region keys and track distances over arrays agree with the scalar rules."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from topology import JUNCTION_INDEX, Region, RegionKey, YGraph
from topology.indexed import reduce_regions, region_key, region_keys, track_distance

samples = st.lists(
    st.tuples(
        st.integers(JUNCTION_INDEX, 2),
        st.sampled_from([0.5, 1.0, 2.0, 3.5]),
        st.integers(JUNCTION_INDEX, 2),
        st.sampled_from([0.5, 1.0, 2.0, 3.5]),
    ),
    min_size=1,
    max_size=60,
)


@given(samples)
def test_vectorized_region_keys_agree_with_the_scalar_rule(rows):
    leg1, s1, leg2, s2 = (np.array(column) for column in zip(*rows, strict=True))
    assert region_keys(leg1, s1, leg2, s2) == [region_key(*row) for row in rows]


@given(samples)
def test_track_distance_over_arrays_agrees_with_the_definition(rows):
    leg1, s1, leg2, s2 = (np.array(column) for column in zip(*rows, strict=True))
    expected = [abs(a - b) if la == lb != JUNCTION_INDEX else a + b for la, a, lb, b in rows]
    assert np.array_equal(track_distance(leg1, s1, leg2, s2), expected)


def test_region_keys_name_the_regions_of_algorithm_section_6():
    track = YGraph({"A": 5.0, "B": 5.0, "C": 5.0})
    keys = region_keys([0, 2, 2, -1], [1.0, 1.0, 3.0, 0.0], [1, 2, 2, 1], [2.0, 3.0, 1.0, 2.0])
    assert [str(Region.from_key(track, k)) if k else None for k in keys] == [
        "Q(A,B)",
        "T(C,1)",
        "T(C,2)",
        None,
    ]
    assert Region("C", "C", 2).key(track) == RegionKey(2, 2, 2)


def test_reduce_regions_cancels_a_back_and_forth_through_one_ray():
    assert reduce_regions(["Q(A,B)", None, "Q(A,C)", None, "Q(A,B)", "Q(C,B)"]) == ("Q(A,B)", "Q(C,B)")
