"""Value objects of the track (3 to 8 legs): positions, configurations, distances, and their errors."""

from __future__ import annotations

import math

import pytest

from tests.support.helpers import legs_id
from tests.support.star_spec import LEGS4
from topology import (
    JUNCTION,
    Configuration,
    Position,
    PositionError,
    SeparationError,
    StarGraph,
    TrackError,
    YGraph,
    plan,
)

TRACK = YGraph({"A": 10.0, "B": 8.0, "C": 15.0})


def test_junction_is_normalized():
    assert Position("A", 0.0) == JUNCTION
    assert Position("B", -0.0).leg is None
    assert hash(Position("C", 0)) == hash(JUNCTION)
    assert Position.parse("O") is JUNCTION


def test_value_objects_are_immutable_and_hashable():
    p = Position("A", 2.5)
    with pytest.raises(AttributeError):
        p.s = 3.0  # type: ignore[misc]
    assert {p, Position("A", 2.5)} == {p}
    assert {TRACK, YGraph({"A": 10.0, "B": 8.0, "C": 15.0})} == {TRACK}
    c = Configuration(p, JUNCTION)
    assert c.swapped().swapped() == c


@pytest.mark.parametrize(
    ("p", "q", "expected"),
    [
        pytest.param("A:2", "A:7", 5.0, id="same-leg"),
        pytest.param("A:2", "B:7", 9.0, id="different-legs"),
        pytest.param("O", "C:4", 4.0, id="junction"),
        pytest.param("C:15", "B:8", 23.0, id="endpoints"),
    ],
)
def test_track_distance_closed_form(p, q, expected):
    assert TRACK.distance(Position.parse(p), Position.parse(q)) == expected
    assert TRACK.distance(Position.parse(q), Position.parse(p)) == expected


def test_xy_uses_leg_angles():
    track = YGraph({"A": 1.0, "B": 1.0, "C": 1.0}, angles_deg={"A": 0.0, "B": 120.0, "C": 240.0})
    x, y = track.xy(Position("B", 2 / 2))
    assert (x, y) == pytest.approx((math.cos(math.radians(120)), math.sin(math.radians(120))))
    assert TRACK.xy(JUNCTION) == (0.0, 0.0)
    assert TRACK.xy(Position("A", 10.0)) == pytest.approx((0.0, 10.0))  # default A points at 90 degrees


@pytest.mark.parametrize("k", range(3, 9), ids=legs_id)
def test_a_star_spreads_its_legs_evenly_by_default(k):
    names = [f"leg{j}" for j in range(k)]
    star = StarGraph({name: 1.0 + j for j, name in enumerate(names)})
    assert star.leg_count == k
    assert star.names == tuple(names)
    assert star.lengths == tuple(1.0 + j for j in range(k))
    assert star.angles_deg == pytest.approx([(90.0 + 360.0 * j / k) % 360.0 for j in range(k)])
    assert (star.cycle is None) == (k > 3)
    assert star.boundary_length == pytest.approx(2 * (k - 1) * sum(star.lengths))
    # the planar layout follows the angles
    x, y = star.xy(Position(names[-1], 2.0))
    angle = math.radians(90.0 + 360.0 * (k - 1) / k)
    assert (x, y) == pytest.approx((2.0 * math.cos(angle), 2.0 * math.sin(angle)))


def test_counterclockwise_angles_may_start_anywhere():
    star = StarGraph(LEGS4, angles_deg={"N": 300, "W": 10, "S": 100, "E": 200})
    assert star.angles_deg == (300.0, 10.0, 100.0, 200.0)


def test_legs_accept_pairs_and_keep_order():
    track = YGraph([("x", 1.0), ("y", 2.0), ("z", 3.0)])
    assert track.names == ("x", "y", "z")
    assert dict(track.legs) == {"x": 1.0, "y": 2.0, "z": 3.0}


# -- every bad input of issue 2, section 3 -------------------------------------------------------------

START = Configuration(Position("A", 10.0), Position("B", 8.0))
GOAL = START.swapped()
#: A swap on the 4-way crossing :data:`LEGS4` (whose shortest leg is 2 m).
CROSSING_START = Configuration(Position("N", 10.0), Position("W", 10.0))


@pytest.mark.parametrize(
    ("build", "error", "match"),
    [
        pytest.param(
            lambda: TRACK.check(Position("D", 1.0)),
            PositionError,
            r"unknown leg 'D'.*\['A', 'B', 'C'\]",
            id="unknown-leg",
        ),
        pytest.param(
            lambda: plan(TRACK, Configuration(Position("D", 1.0), JUNCTION), GOAL),
            PositionError,
            "unknown leg 'D'",
            id="unknown-leg-in-plan",
        ),
        pytest.param(lambda: Position("A", -1.0), PositionError, r"s must be >= 0 m.*-1\.0", id="negative-s"),
        pytest.param(
            lambda: plan(TRACK, Configuration(Position("A", 10.5), JUNCTION), GOAL),
            PositionError,
            r"s=10\.5 m is beyond the end of leg 'A'.*0 <= s <= 10\.0",
            id="s-beyond-length",
        ),
        pytest.param(lambda: Position("A", math.nan), PositionError, "must be finite, got nan", id="nan-s"),
        pytest.param(lambda: Position("A", math.inf), PositionError, "must be finite, got inf", id="inf-s"),
        pytest.param(
            lambda: Position(None, 2.0), PositionError, "leg None must be the junction", id="no-leg"
        ),
        pytest.param(
            lambda: Position("A", "3"), PositionError, "must be a real number, got '3'", id="string-s"
        ),
        pytest.param(lambda: Position.parse("A=3"), PositionError, "'A=3' is malformed", id="malformed-text"),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": 0.0, "C": 1.0}),
            TrackError,
            r"leg 'B' must be > 0 m, got 0\.0",
            id="zero-length",
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": -2.0, "C": 1.0}),
            TrackError,
            "leg 'B' must be > 0 m",
            id="negative-length",
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": math.nan, "C": 1.0}),
            TrackError,
            "must be finite, got nan",
            id="nan-length",
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": math.inf, "C": 1.0}),
            TrackError,
            "must be finite, got inf",
            id="inf-length",
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": 1.0}), TrackError, "exactly 3 legs, got 2", id="two-legs"
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": 1.0, "C": 1.0, "D": 1.0}),
            TrackError,
            "exactly 3 legs, got 4",
            id="four-legs",
        ),
        pytest.param(
            lambda: YGraph([("A", 1.0), ("B", 1.0), ("A", 2.0)]),
            TrackError,
            "distinct, got 'A' twice",
            id="duplicate-names",
        ),
        pytest.param(
            lambda: YGraph({"O": 1.0, "B": 1.0, "C": 1.0}),
            TrackError,
            "'O' is not allowed",
            id="leg-named-junction",
        ),
        pytest.param(
            lambda: YGraph({"A": 1.0, "B": 1.0, "C": 1.0}, angles_deg={"A": 90, "B": 330, "C": 210}),
            TrackError,
            "not distinct and counterclockwise",
            id="clockwise-angles",
        ),
        pytest.param(
            lambda: plan(
                TRACK, Configuration(Position("A", 5.0), Position("A", 4.0)), GOAL, min_separation=1.5
            ),
            SeparationError,
            r"start \(A:5, A:4\) are 1\.0 m apart.*at least the min_separation 1\.5 m",
            id="close-at-start",
        ),
        pytest.param(
            lambda: plan(
                TRACK, START, Configuration(Position("A", 1.0), Position("B", 0.2)), min_separation=1.5
            ),
            SeparationError,
            r"goal \(A:1, B:0\.2\) are 1\.2 m apart",
            id="close-at-goal",
        ),
        pytest.param(
            lambda: plan(TRACK, Configuration(Position("A", 1.0), Position("A", 1.0)), GOAL),
            SeparationError,
            "same point",
            id="same-point",
        ),
        pytest.param(
            lambda: plan(TRACK, START, GOAL, min_separation=-0.1),
            SeparationError,
            r"between 0 m and the shortest leg 8\.0 m, got -0\.1 m",
            id="negative-separation",
        ),
        pytest.param(
            lambda: plan(TRACK, START, GOAL, min_separation=8.5),
            SeparationError,
            r"between 0 m and the shortest leg 8\.0 m, got 8\.5 m",
            id="separation-beyond-shortest-leg",
        ),
        pytest.param(
            lambda: plan(TRACK, START, GOAL, min_separation=math.nan),
            SeparationError,
            "min_separation.*must be finite",
            id="nan-separation",
        ),
        # junctions of 3 to 8 legs
        pytest.param(
            lambda: StarGraph({"A": 1.0, "B": 1.0}),
            TrackError,
            r"a track has 3 to 8 legs, got 2",
            id="star-of-two-legs",
        ),
        pytest.param(
            lambda: StarGraph({f"l{j}": 1.0 for j in range(9)}),
            TrackError,
            r"a track has 3 to 8 legs, got 9",
            id="star-of-nine-legs",
        ),
        pytest.param(
            lambda: StarGraph(LEGS4, angles_deg={"N": 90, "W": 270, "S": 180, "E": 0}),
            TrackError,
            r"not distinct and counterclockwise in the order of the legs \['N', 'W', 'S', 'E'\]",
            id="clockwise-angles-legs4",
        ),
        pytest.param(
            lambda: StarGraph(LEGS4, angles_deg={"N": 90, "W": 180, "S": 180, "E": 0}),
            TrackError,
            r"not distinct and counterclockwise",
            id="repeated-angle-legs4",
        ),
        pytest.param(
            lambda: StarGraph(LEGS4, angles_deg={"N": 90, "W": 180, "S": 270}),
            TrackError,
            r"angles_deg must give exactly the legs \['N', 'W', 'S', 'E'\]",
            id="missing-angle-legs4",
        ),
        pytest.param(
            lambda: YGraph(LEGS4), TrackError, r"a Y-track has exactly 3 legs, got 4", id="y-with-four-legs"
        ),
        pytest.param(
            lambda: plan(StarGraph(LEGS4), CROSSING_START, CROSSING_START.swapped(), min_separation=2.5),
            SeparationError,
            r"between 0 m and the shortest leg 2\.0 m, got 2\.5 m: legs 'S' \(2\.0 m\) would be too short "
            r"to serve as sidings",
            id="separation-beyond-one-leg-legs4",
        ),
        pytest.param(
            lambda: plan(StarGraph(LEGS4), CROSSING_START, CROSSING_START.swapped(), min_separation=3.5),
            SeparationError,
            r"legs 'S' \(2\.0 m\), 'E' \(3\.0 m\) would be too short",
            id="separation-beyond-two-legs-legs4",
        ),
        pytest.param(
            lambda: plan(StarGraph(LEGS4), CROSSING_START, CROSSING_START.swapped(), min_separation=-0.5),
            SeparationError,
            r"between 0 m and the shortest leg 2\.0 m, got -0\.5 m$",
            id="negative-separation-legs4",
        ),
    ],
)
def test_bad_input_raises_a_clear_error(build, error, match):
    with pytest.raises(error, match=match):
        build()


def test_input_errors_are_value_errors():
    with pytest.raises(ValueError, match="unknown leg"):
        TRACK.index("Z")
