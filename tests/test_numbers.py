"""The vectorized fixed-point formatter writes, entry by entry, what the Python expression writes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from trajgen.export.numbers import exact_limit, fixed_point_text, format_number_rows

PLACES = (6, 9)
#: How the values are laid out: a column alone, one short line per value (rows too short to be written
#: word by word at their own offsets: the padded rows are compacted), or the middle one of three columns
#: (rows of one width per column written word by word, when the widths change less than 64 times).
LAYOUTS = ("alone", "among-columns")


def vectorized_texts(values, places: int, decimal: str = ".", layout: str = "alone") -> list[str]:
    """Each value's text from :func:`format_number_rows`, the values laid out as ``layout`` says."""
    column = np.array(values, dtype=np.float64)
    if layout == "alone":
        data = format_number_rows([(column, places)], ["\n"], decimal=decimal)
        return data.decode("ascii").split("\n")[:-1]
    times, legs = np.arange(column.size) * 0.25, np.arange(column.size)
    data = format_number_rows(
        [(times, 6), (column, places), (legs, None)], [";", "\t", "\r\n"], decimal=decimal
    )
    rows = [row.split(";")[1].split("\t") for row in data.decode("ascii").split("\r\n")[:-1]]
    assert [int(leg) for _, leg in rows] == legs.tolist()
    return [text for text, _ in rows]


def python_texts(values, places: int, decimal: str = ".") -> list[str]:
    return [fixed_point_text(value, places).replace(".", decimal) for value in values]


def first_mismatch(values, places: int, decimal: str = ".", layout: str = "alone") -> tuple | None:
    """``None`` if every entry agrees, else (index, value, vectorized text, Python text)."""
    got = vectorized_texts(values, places, decimal, layout)
    expected = python_texts(values, places, decimal)
    assert len(got) == len(expected)
    for index, (mine, theirs) in enumerate(zip(got, expected, strict=True)):
        if mine != theirs:
            return index, float(values[index]).hex(), mine, theirs
    return None


def _nudged(value: float, ulps: int) -> float:
    """``value`` moved ``ulps`` units in the last place (toward +inf if positive)."""
    for _ in range(abs(ulps)):
        value = math.nextafter(value, math.inf if ulps > 0 else -math.inf)
    return value


@st.composite
def near_ties(draw, places: int) -> float:
    """Within a few units in the last place of k + 0.5 units of 10**-places (either sign)."""
    whole = draw(st.integers(-(10**15), 10**15) | st.integers(-1000, 1000))
    value = (whole + 0.5) / 10.0**places
    return _nudged(value, draw(st.integers(-3, 3)))


@st.composite
def dyadic(draw) -> float:
    """Dyadic values m * 2**-e: exact halves at some place (0.0009765625 = 2**-10 at 9 places)."""
    return draw(st.integers(-(2**40), 2**40)) * 2.0 ** -draw(st.integers(0, 45))


@st.composite
def near_limits(draw, places: int) -> float:
    limit = exact_limit(places)
    value = draw(st.sampled_from([limit, 2 * limit, limit / 2]))
    return draw(st.sampled_from([1.0, -1.0])) * _nudged(value, draw(st.integers(-3, 3)))


def values(places: int):
    """Float64 values of every kind the formatter must get right."""
    return st.one_of(
        st.floats(width=64),  # anything: subnormals, huge, infinities, NaN
        st.floats(-1e4, 1e4),
        near_ties(places),
        dyadic(),
        st.floats(-1e-8, 0.0),  # tiny negatives (no "-0")
        st.floats(0.0, 1e-300),
        near_limits(places),
    )


@pytest.mark.parametrize("layout", LAYOUTS, ids=LAYOUTS)
@pytest.mark.parametrize("places", PLACES, ids=[f"{p}-places" for p in PLACES])
@given(data=st.data())
def test_every_entry_is_the_python_text(places, layout, data):
    drawn = data.draw(st.lists(values(places), max_size=40), label="values")
    decimal = data.draw(st.sampled_from([".", ","]), label="decimal")
    assert first_mismatch(drawn, places, decimal, layout) is None


@given(data=st.data())
def test_every_entry_is_the_python_text_at_any_number_of_places(data):
    places = data.draw(st.integers(0, 15), label="places")
    drawn = data.draw(st.lists(values(places), max_size=20), label="values")
    layout = data.draw(st.sampled_from(LAYOUTS), label="layout")
    assert first_mismatch(drawn, places, ".", layout) is None


@pytest.mark.parametrize("places", PLACES, ids=[f"{p}-places" for p in PLACES])
@pytest.mark.parametrize(
    "pattern",
    [
        pytest.param("a-width-change-every-row", id="a-width-change-every-row"),
        pytest.param("few-width-changes", id="few-width-changes"),
    ],
)
def test_long_columns_of_changing_widths(places, pattern):
    """Thousands of rows: every row a new width (compacted), or long runs of one width (written in runs)."""
    rng = np.random.default_rng(7)
    if pattern == "a-width-change-every-row":
        magnitudes = 10.0 ** rng.integers(-3, 6, 5000) * rng.uniform(1.0, 9.99, 5000)
        column = np.where(np.arange(5000) % 2 == 0, magnitudes, -magnitudes)
    else:  # a smooth motion through zero and past 10, 100 and 1000, as a schedule's columns go
        column = 1500.0 * np.sin(np.linspace(-4.0, 4.0, 5000)) + rng.uniform(-1e-7, 1e-7, 5000)
    assert first_mismatch(column, places, ",", "among-columns") is None


@given(
    rows=st.integers(0, 30).flatmap(
        lambda n: st.tuples(
            st.lists(values(6), min_size=n, max_size=n),
            st.lists(values(9), min_size=n, max_size=n),
            st.lists(st.integers(-(2**63), 2**63 - 1), min_size=n, max_size=n),
        )
    ),
    separators=st.sampled_from([(";", ";", "\r\n"), ("\t", ",", "\n"), (" ", ";", ";1\r\n")]),
    decimal=st.sampled_from([".", ","]),
)
def test_rows_of_several_columns_are_the_python_rows(rows, separators, decimal):
    times, lengths, legs = rows
    data = format_number_rows(
        [(np.array(times), 6), (np.array(lengths), 9), (np.array(legs, dtype=np.int64), None)],
        separators,
        decimal=decimal,
    )
    expected = "".join(
        f"{fixed_point_text(t, 6).replace('.', decimal)}{separators[0]}"
        f"{fixed_point_text(x, 9).replace('.', decimal)}{separators[1]}{leg}{separators[2]}"
        for t, x, leg in zip(times, lengths, legs, strict=True)
    )
    assert data == expected.encode("ascii")


CLOSED_FORM = [
    pytest.param(0.0, 9, "0.000000000", id="zero"),
    pytest.param(-0.0, 9, "0.000000000", id="negative-zero"),
    pytest.param(-4e-10, 9, "0.000000000", id="tiny-negative-to-zero"),
    pytest.param(-6e-10, 9, "-0.000000001", id="tiny-negative-away-from-zero"),
    pytest.param(5e-324, 9, "0.000000000", id="smallest-subnormal"),
    pytest.param(0.0009765625, 9, "0.000976562", id="exact-half-to-even-down"),
    pytest.param(0.0029296875, 9, "0.002929688", id="exact-half-to-even-up"),
    pytest.param(-0.0009765625, 9, "-0.000976562", id="negative-exact-half"),
    # v * 10**p rounds to a half-integer; the exact product lies above (below) it
    pytest.param(2.5e-09, 9, "0.000000003", id="product-half-exact-above"),
    pytest.param(1.5e-09, 9, "0.000000001", id="product-half-exact-below"),
    pytest.param(1.5e-06, 6, "0.000002", id="product-half-exact-above-6"),
    pytest.param(3.5e-06, 6, "0.000003", id="product-half-exact-below-6"),
    pytest.param(533.0, 9, "533.000000000", id="whole-metres"),
    pytest.param(-453.90123463149996, 9, "-453.901234631", id="x-near-tie"),
    pytest.param(3205.5, 6, "3205.500000", id="time"),
    pytest.param(2133000.0, 6, "2133000.000000", id="millimetres"),
    pytest.param(4194303.999999999, 9, "4194303.999999999", id="below-the-9-place-limit"),
    pytest.param(2.0**22, 9, "4194304.000000000", id="at-the-9-place-limit"),
    pytest.param(8388607.999999999, 9, "8388607.999999999", id="above-the-9-place-limit"),
    pytest.param(4294967295.9999995, 6, "4294967296.000000", id="above-the-6-place-limit"),
    pytest.param(1e22, 6, "10000000000000000000000.000000", id="huge"),
    pytest.param(2.5, 0, "2", id="no-places-half-to-even"),
    pytest.param(-0.4, 0, "0", id="no-places-negative-to-zero"),
    pytest.param(0.0625, 3, "0.062", id="three-places-exact-half"),
    pytest.param(float("nan"), 9, "nan", id="nan"),
    pytest.param(float("inf"), 6, "inf", id="inf"),
    pytest.param(-float("inf"), 9, "-inf", id="minus-inf"),
]


@pytest.mark.parametrize(("value", "places", "text"), CLOSED_FORM)
def test_closed_form_cases(value, places, text):
    assert fixed_point_text(value, places) == text
    assert vectorized_texts([value], places) == [text]
    # the same value among ordinary ones, in either decimal mark
    assert vectorized_texts([1.25, value, -7.0], places, ",") == [
        fixed_point_text(1.25, places).replace(".", ","),
        text.replace(".", ","),
        fixed_point_text(-7.0, places).replace(".", ","),
    ]


def test_a_python_written_entry_longer_than_the_others_keeps_its_row_intact():
    values_ = np.array([1.0, 1e300, -2.5e-9, 3.0])
    data = format_number_rows([(values_, 9), (np.arange(4), None)], [";", "\r\n"])
    assert data.decode("ascii").split("\r\n")[:-1] == [
        f"{fixed_point_text(v, 9)};{k}" for k, v in enumerate(values_)
    ]


@pytest.mark.parametrize(
    ("integers", "texts"),
    [
        pytest.param(np.array([0, 1, -1, 10, -99999]), ["0", "1", "-1", "10", "-99999"], id="int64"),
        pytest.param(np.array([0, 255], dtype=np.uint8), ["0", "255"], id="uint8"),
        pytest.param(np.array([2**63 - 1, -(2**63)]), [str(2**63 - 1), str(-(2**63))], id="int64-extremes"),
    ],
)
def test_integer_columns_are_str(integers, texts):
    assert format_number_rows([(integers, None)], ["\n"]) == "".join(f"{t}\n" for t in texts).encode()


@pytest.mark.parametrize("places", range(16), ids=[f"{p}-places" for p in range(16)])
def test_the_exact_limit_keeps_round_then_format_exact(places):
    limit = exact_limit(places)
    # the binade above the limit still has a spacing below 10**-places (one binade to spare) ...
    assert np.spacing(np.nextafter(2 * limit, 0.0)) < 10.0**-places
    # ... and every half-integer near v * 10**places is a double
    assert limit * 10.0**places <= 2.0**52


@pytest.mark.parametrize(
    ("columns", "separators", "decimal", "error", "match"),
    [
        pytest.param([], [], ".", ValueError, "at least one column", id="no-column"),
        pytest.param(
            [(np.ones(2), 9)], [";", ";"], ".", ValueError, "a separator per column", id="separators"
        ),
        pytest.param([(np.ones(2), 9)], ["\0"], ".", ValueError, "NUL", id="nul-separator"),
        pytest.param([(np.ones(2), 9)], [";"], ";", ValueError, "decimal mark", id="decimal-mark"),
        pytest.param([(np.ones((2, 2)), 9)], [";"], ".", ValueError, "1-D", id="two-dimensional"),
        pytest.param(
            [(np.ones(2), 9), (np.ones(3), 9)], [";", ";"], ".", ValueError, "one length", id="lengths"
        ),
        pytest.param([(np.ones(2), 16)], [";"], ".", ValueError, "0 to 15", id="places"),
        pytest.param([(np.ones(2), None)], [";"], ".", TypeError, "integer dtype", id="float-as-integer"),
        pytest.param(
            [(np.ones(2, dtype=np.uint64), None)], [";"], ".", TypeError, "Cannot cast", id="uint64-integer"
        ),
    ],
)
def test_bad_arguments_are_refused(columns, separators, decimal, error, match):
    with pytest.raises(error, match=match):
        format_number_rows(columns, separators, decimal=decimal)


def test_no_rows_give_no_bytes():
    assert format_number_rows([(np.array([]), 9), (np.array([], dtype=int), None)], [";", "\r\n"]) == b""
