"""Helpers that make result objects honest values: read-only arrays, value equality and hashing."""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["ArrayValue", "frozen", "readonly", "sorted_unique"]


def sorted_unique(values) -> np.ndarray:
    """The distinct values of ``values``, sorted, shape (m,): :func:`numpy.unique` of finite floats.

    ``numpy.unique`` imports ``numpy.ma`` on its first call (to test for a masked array), a tenth of
    the command line's start; the numbers here are never masked.

    Examples
    --------
    >>> sorted_unique([3.0, 1.0, 3.0, 2.0]).tolist()
    [1.0, 2.0, 3.0]
    """
    ordered = np.sort(np.asarray(values).ravel())
    if ordered.size < 2:
        return ordered
    keep = np.empty(ordered.size, dtype=bool)
    keep[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=keep[1:])
    return ordered[keep]


def frozen(array: np.ndarray) -> np.ndarray:
    """``array`` itself if nothing can write to it any more, else a read-only copy.

    An array is safe when it and every array it is a view of are read-only
    (numpy then refuses to make it writeable again).
    """
    base = array
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return readonly(array)
        base = base.base
    return array


def readonly(values, dtype=None) -> np.ndarray:
    """A read-only copy of ``values`` as an array.

    Examples
    --------
    >>> a = readonly([1.0, 2.0])
    >>> a.flags.writeable
    False
    """
    array = np.array(values, dtype=dtype, copy=True)
    array.flags.writeable = False
    return array


def _same(a: object, b: object) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)) or a.dtype != b.dtype:
            return False
        return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    return bool(a == b)


def _hash_key(value: object) -> object:
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc":  # as equality sees them: -0.0 is 0.0, every NaN is one NaN
            value = np.where(np.isnan(value), np.nan, value + 0.0)
        return (value.shape, value.dtype.str, value.tobytes())
    return value


class ArrayValue:
    """Mixin for frozen dataclasses holding arrays: ``==`` compares values, ``hash`` agrees with it.

    Use with ``@dataclass(frozen=True, slots=True, eq=False)``; fields with
    ``compare=False`` are left out of both.
    """

    __slots__ = ()

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(
            _same(getattr(self, f.name), getattr(other, f.name))
            for f in dataclasses.fields(self)  # type: ignore[arg-type]
            if f.compare
        )

    def __hash__(self) -> int:
        return hash(
            tuple(
                _hash_key(getattr(self, f.name))
                for f in dataclasses.fields(self)  # type: ignore[arg-type]
                if f.compare
            )
        )
