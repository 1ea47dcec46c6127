"""Exact extrema of low-degree polynomials on intervals: the verifier's closed form."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from trajgen.model.polynomials import evaluate, extrema, root_in

coefficient = st.floats(-10.0, 10.0, allow_nan=False)


@given(st.lists(coefficient, min_size=1, max_size=5), st.floats(0.01, 20.0))
def test_extrema_bound_a_dense_sampling_and_are_attained(coefficients, length):
    c = np.array([coefficients])
    h = np.array([length])
    low, t_low, high, t_high = extrema(c, h)
    dense = evaluate(c, np.linspace(0.0, length, 20001)[None, :])[0]
    # never better than any instant (certified), and attained where it says (exact)
    assert low[0] <= dense.min() + 1e-9 * max(1.0, abs(dense.min()))
    assert high[0] >= dense.max() - 1e-9 * max(1.0, abs(dense.max()))
    assert evaluate(c, t_low)[0] == pytest.approx(low[0], rel=1e-12, abs=1e-12)
    assert 0.0 <= t_low[0] <= length
    assert 0.0 <= t_high[0] <= length


def test_a_dip_between_two_samples_is_found():
    # 1e10 (t - 0.5005)^2 - 1 dips to -1 at 0.5005 s, but is +2499 at the samples 0.500 s and 0.501 s
    c = np.array([[1e10 * 0.5005**2 - 1.0, -2e10 * 0.5005, 1e10, 0.0, 0.0]])
    samples = evaluate(c, np.linspace(0.0, 1.0, 1001)[None, :])[0]
    assert samples.min() > 0.0
    low, t_low, _, _ = extrema(c, np.array([1.0]))
    assert low[0] == pytest.approx(-1.0, abs=1e-4)
    assert t_low[0] == pytest.approx(0.5005, abs=1e-12)


def test_closed_form_cases():
    # 1 + t - t^2 on [0, 2]: maximum 1.25 at 0.5, minimum -1 at 2; a constant; a line
    c = np.array([[1.0, 1.0, -1.0, 0.0, 0.0], [3.0, 0.0, 0.0, 0.0, 0.0], [0.0, -2.0, 0.0, 0.0, 0.0]])
    low, t_low, high, t_high = extrema(c, np.array([2.0, 5.0, 1.0]))
    assert high[0] == pytest.approx(1.25)
    assert t_high[0] == pytest.approx(0.5)
    assert low[0] == pytest.approx(-1.0)
    assert (low[1], high[1]) == (3.0, 3.0)
    assert (low[2], t_low[2], high[2]) == (-2.0, 1.0, 0.0)


def test_non_finite_coefficients_give_nan():
    low, _, high, _ = extrema(np.array([[1.0, np.nan, 0.0]]), np.array([1.0]))
    assert np.isnan(low[0])
    assert np.isnan(high[0])


@pytest.mark.parametrize(
    "kind",
    ["random-quartics", "double-roots", "triple-roots", "tiny-and-huge-scales"],
)
def test_a_root_found_has_a_sign_change_within_a_few_units_of_round_off(kind):
    """Seeded: every bracketed root is a true root to round-off, whatever the method takes to find it."""
    rng = np.random.default_rng(11)
    n = 400
    if kind == "random-quartics":
        c = rng.normal(size=(n, 5))
    elif kind == "double-roots":  # (t - r)^2 (t - q)
        r, q = rng.uniform(0.0, 2.0, n), rng.uniform(-1.0, 3.0, n)
        c = np.column_stack([-r * r * q, r * r + 2.0 * r * q, -(2.0 * r + q), np.ones(n)])
    elif kind == "triple-roots":  # (t - r)^3
        r = rng.uniform(0.0, 2.0, n)
        c = np.column_stack([-(r**3), 3.0 * r * r, -3.0 * r, np.ones(n)])
    else:
        c = rng.normal(size=(n, 4)) * 10.0 ** rng.integers(-12, 6, size=(n, 1))
    low, high = np.zeros(n), rng.uniform(0.01, 3.0, n)
    roots = root_in(c, low, high)
    f_low, f_high = evaluate(c, low), evaluate(c, high)
    bracketed = np.sign(f_low) * np.sign(f_high) <= 0.0
    assert np.array_equal(np.isnan(roots), ~bracketed)
    assert bracketed.sum() > n // 4  # the property is exercised
    r = roots[bracketed]
    assert np.all((r >= low[bracketed]) & (r <= high[bracketed]))
    # the sign changes (or the value vanishes) within 16 units of round-off of the bracket's end
    delta = 16.0 * np.finfo(float).eps * high[bracketed]
    cb = c[bracketed]
    before = evaluate(cb, np.maximum(r - delta, low[bracketed]))
    after = evaluate(cb, np.minimum(r + delta, high[bracketed]))
    at = evaluate(cb, r)
    assert np.all((np.sign(before) * np.sign(after) <= 0.0) | (at == 0.0))


def _cubics_with_double_roots(seed: int, count: int) -> np.ndarray:
    """Random cubics, a third with a derivative's double root and a third with two roots 1e-9 apart."""
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(count, 4))
    third = count // 3
    r, a = rng.uniform(0.0, 2.0, third), rng.normal(size=third)
    c[:third] = np.column_stack([1.0 - a * r**3, 3.0 * a * r**2, -3.0 * a * r, a])  # a (t - r)^3 + 1
    d = 1e-9
    # derivative 3 a (t - r)(t - r - d): roots r and r + d
    c[third : 2 * third] = np.column_stack(
        [np.ones(third), 3.0 * a * r * (r + d), -1.5 * a * (2.0 * r + d), a]
    )
    return c


@pytest.mark.parametrize("seed", [0, 1, 2], ids=["seed-0", "seed-1", "seed-2"])
def test_the_closed_form_of_cubics_agrees_with_the_bracketed_search(seed):
    c = _cubics_with_double_roots(seed, 3000)
    h = np.random.default_rng(seed + 100).uniform(0.1, 3.0, c.shape[0])
    closed = extrema(c, h)  # degree 3: the derivative's roots in closed form
    searched = extrema(np.pad(c, ((0, 0), (0, 1))), h)  # as a quartic: the safeguarded Newton search
    scale = np.maximum(1.0, np.abs(searched[0]))
    np.testing.assert_allclose(closed[0], searched[0], rtol=0.0, atol=1e-13 * scale.max())
    np.testing.assert_allclose(closed[2], searched[2], rtol=0.0, atol=1e-13 * scale.max())
    for value, where in ((closed[0], closed[1]), (closed[2], closed[3])):
        np.testing.assert_allclose(evaluate(c, where), value, rtol=1e-12, atol=1e-12)  # attained there
        assert np.all((where >= 0.0) & (where <= h))


def test_a_cubic_flat_at_its_inflection_has_its_extrema_at_the_ends():
    # (t - 1)^3 on [0, 2]: the derivative's double root at 1 is no extremum
    low, t_low, high, t_high = extrema(np.array([[-1.0, 3.0, -3.0, 1.0]]), np.array([2.0]))
    assert (low[0], t_low[0], high[0], t_high[0]) == (-1.0, 0.0, 1.0, 2.0)
    # 2t - t^2 on [0, 3]: maximum 1 at 1, minimum -3 at 3
    low, t_low, high, t_high = extrema(np.array([[0.0, 2.0, -1.0, 0.0]]), np.array([3.0]))
    assert (high[0], t_high[0], low[0], t_low[0]) == (1.0, 1.0, -3.0, 3.0)
