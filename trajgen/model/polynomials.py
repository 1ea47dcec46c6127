"""Vectorized extrema of many low-degree polynomials, each on its own interval.

Coefficients are in increasing powers, one row per polynomial: ``c[:, 0] +
c[:, 1] t + ... + c[:, d] t^d`` on ``0 <= t <= h``, ``d <= 4``. The extrema
are exact up to round-off: the critical points are the roots of the
derivative, found by safeguarded Newton steps (bisection where Newton's point
leaves the bracket) on intervals where the derivative is monotone (split at
the roots of the second derivative, in closed form), so no extremum is missed
however close two of them are. For cubics and below (the schedules' pieces) the
derivative is a quadratic: its roots are taken in closed form, polished by one
Newton step (see :func:`_quadratic_critical_points`); the search would spend up
to 64 steps on a double root, where Newton's steps only halve the distance.
"""

from __future__ import annotations

import numpy as np

__all__ = ["derivative", "evaluate", "extrema", "root_in"]

#: Most steps of the root search: 64 bisections shrink any bracket here below a double's resolution.
_BISECTIONS = 64
#: Where the root search stops, relative to the bracket's larger end: a few units of round-off.
_ROOT_RESOLUTION = 4.0 * np.finfo(float).eps


def evaluate(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Values at ``t`` (shape (n,) or (n, k)) of the polynomials ``c`` (shape (n, d + 1))."""
    t = np.asarray(t, dtype=float)
    shape = (-1,) + (1,) * (t.ndim - 1)
    out = np.zeros(np.broadcast_shapes(t.shape, (c.shape[0],) + (1,) * (t.ndim - 1)))
    for power in range(c.shape[1] - 1, -1, -1):
        out = out * t + c[:, power].reshape(shape)
    return out


def derivative(c: np.ndarray) -> np.ndarray:
    """Coefficients of the derivatives, shape (n, d) (a column of zeros for constants)."""
    if c.shape[1] == 1:
        return np.zeros_like(c)
    return c[:, 1:] * np.arange(1, c.shape[1])


def _quadratic_roots(c: np.ndarray) -> np.ndarray:
    """Real roots of ``c0 + c1 t + c2 t^2``, shape (n, 2), NaN where there are none."""
    c = np.pad(c, ((0, 0), (0, max(0, 3 - c.shape[1]))))[:, :3]
    c0, c1, c2 = c[:, 0], c[:, 1], c[:, 2]
    out = np.full((c.shape[0], 2), np.nan)
    # an infinite root lies outside every interval, where it is discarded
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        linear = c2 == 0.0
        out[:, 0] = np.where(linear & (c1 != 0.0), -c0 / c1, np.nan)
        disc = c1 * c1 - 4.0 * c2 * c0
        root = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = -0.5 * (c1 + np.where(c1 >= 0.0, root, -root))  # the stable form
        first = np.where(q != 0.0, c0 / q, 0.0)
        second = np.where(c2 != 0.0, q / c2, np.nan)
        out[:, 0] = np.where(linear, out[:, 0], first)
        out[:, 1] = np.where(linear, np.nan, second)
    return out


def _horner(columns: list[np.ndarray], x: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Values at ``x`` of the polynomials whose coefficient columns, highest power first, are ``columns``."""
    out[...] = columns[0]
    for column in columns[1:]:
        out *= x
        out += column
    return out


def root_in(c: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """A root of each polynomial between ``low`` and ``high`` where the values there differ in sign, else NaN.

    Safeguarded Newton: each step keeps a bracket on which the sign changes, takes Newton's point
    where it lies inside the bracket and at least halves the step before, else bisects. A row is
    done when its value is 0, its Newton step or its bracket is below
    :data:`_ROOT_RESOLUTION` of ``max(|low|, |high|)``: then the root found is within a few
    times that of a true root (within the step's size times the root's multiplicity, at most 4).
    Most rows take 5 to 10 steps; none more than :data:`_BISECTIONS`.
    """
    f_low, f_high = evaluate(c, low), evaluate(c, high)
    bracketed = np.isfinite(f_low) & np.isfinite(f_high) & (np.sign(f_low) * np.sign(f_high) <= 0.0)
    a, b = np.where(bracketed, low, np.nan), np.where(bracketed, high, np.nan)
    rising = f_high >= f_low
    degree = c.shape[1] - 1
    columns = [np.ascontiguousarray(c[:, power]) for power in range(degree, -1, -1)]
    slopes = [c[:, power] * power for power in range(degree, 0, -1)] or [np.zeros(c.shape[0])]
    resolution = _ROOT_RESOLUTION * np.maximum(np.abs(low), np.abs(high))
    x = 0.5 * (a + b)
    width = b - a  # the step before: Newton's point must at least halve it
    value, slope, newton, step = (np.empty_like(a) for _ in range(4))
    above, accept = np.empty(a.shape, dtype=bool), np.empty(a.shape, dtype=bool)
    active = bracketed.copy()
    # in place on preallocated arrays: every verification runs this on every piece
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(_BISECTIONS):
            _horner(columns, x, value)
            _horner(slopes, x, slope)
            np.less(value, 0.0, out=above)
            np.equal(above, rising, out=above)  # the root lies above x
            np.copyto(a, x, where=above)
            np.logical_not(above, out=above)
            np.copyto(b, x, where=above)
            np.divide(value, slope, out=newton)
            np.abs(newton, out=step)
            np.subtract(x, newton, out=newton)
            active &= ~((value == 0.0) | (step <= resolution) | (b - a <= resolution))
            if not active.any():
                break
            np.less_equal(step, 0.5 * width, out=accept)
            accept &= newton > a
            accept &= newton < b
            middle = 0.5 * (a + b)
            np.multiply(b - a, 0.5, out=width)
            np.copyto(width, step, where=accept)
            np.copyto(middle, newton, where=accept)
            np.copyto(x, middle, where=active)
    return np.where(bracketed, x, np.nan)


def _quadratic_critical_points(first: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Critical points inside ``[0, h]`` of polynomials of degree <= 3 from their derivatives ``first``.

    The derivative's roots in closed form (the stable formula), each polished by a Newton step where
    that brings the derivative nearer zero, and its vertex: where the two roots nearly meet, round-off
    may leave none real, and there the polynomial is flat, so its values at the vertex are those at
    the roots up to round-off. Extra points of the interval never change a minimum or maximum found
    among them. Shape (n, 3), NaN where fewer lie inside. No search: a double root costs nothing.
    """
    first = np.pad(first, ((0, 0), (0, 3 - first.shape[1])))
    slope = derivative(first)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        vertex = np.where(first[:, 2] != 0.0, -first[:, 1] / (2.0 * first[:, 2]), np.nan)
        points = np.column_stack([_quadratic_roots(first), vertex])
        value = evaluate(first, points)
        polished = points - value / evaluate(slope, points)
        better = np.isfinite(polished) & (np.abs(evaluate(first, polished)) < np.abs(value))
        points = np.where(better, polished, points)
        inside = (points > 0.0) & (points < h[:, None])
    return np.where(inside, points, np.nan)


def _critical_points(c: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Roots of the derivative inside ``[0, h]``, shape (n, 3), NaN where there are fewer."""
    first = derivative(c)
    if first.shape[1] <= 3:
        return _quadratic_critical_points(first, h)
    second = derivative(first)
    splits = _quadratic_roots(second[:, :3]) if second.shape[1] <= 3 else None
    if splits is None:  # degree above 4 is not used
        raise ValueError("polynomials of degree above 4 are not supported")
    splits = np.where((splits > 0.0) & (splits < h[:, None]), splits, np.nan)
    bounds = np.sort(np.column_stack([np.zeros_like(h), splits, h]), axis=1)  # NaN sort last
    bounds = np.where(np.isnan(bounds), h[:, None], bounds)
    # the three monotone stretches of every polynomial in one vectorized bisection
    repeated = np.repeat(first, 3, axis=0)
    roots = root_in(repeated, bounds[:, :3].ravel(), bounds[:, 1:].ravel())
    return roots.reshape(-1, 3)


def extrema(c: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Minimum and maximum of each polynomial on ``[0, h]``, and where they are.

    Parameters
    ----------
    c : ndarray, shape (n, d + 1), d <= 4
        Coefficients in increasing powers.
    h : ndarray, shape (n,)
        Interval lengths (>= 0).

    Returns
    -------
    (low, t_low, high, t_high) : ndarrays, shape (n,)
        NaN where a coefficient or ``h`` is not finite.
    """
    c = np.asarray(c, dtype=float)
    h = np.asarray(h, dtype=float)
    candidates = np.column_stack([np.zeros_like(h), h, _critical_points(c, h)])
    values = evaluate(c, candidates)
    values = np.where(np.isnan(candidates), np.nan, values)
    finite = np.all(np.isfinite(c), axis=1) & np.isfinite(h)
    with np.errstate(invalid="ignore"):
        k_low = np.nanargmin(np.where(np.isnan(values), np.inf, values), axis=1)
        k_high = np.nanargmax(np.where(np.isnan(values), -np.inf, values), axis=1)
    rows = np.arange(c.shape[0])
    low = np.where(finite, values[rows, k_low], np.nan)
    high = np.where(finite, values[rows, k_high], np.nan)
    return low, candidates[rows, k_low], high, candidates[rows, k_high]
