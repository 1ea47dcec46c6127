"""Corrupted copies of a schedule: every float array reachable from it, one entry at a time.

:func:`float_arrays` walks a schedule (dataclass fields, also those made in
``__post_init__``, tuples, lists) and yields every float array with its path
(``sections[0].kinematics.vehicles[1].times``). :func:`corrupted` returns a copy
of the schedule with one array replaced and nothing else rebuilt: caches and
other arrays stay as they were, as after a bug or a stray write.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import re
from collections.abc import Iterator

import numpy as np

__all__ = ["CORRUPTIONS", "corrupt_array", "corrupted", "float_arrays", "names"]

#: The corruptions applied to one entry (or a pair of adjacent entries) of an array.
CORRUPTIONS = ("nan", "+inf", "-inf", "swap", "move")

_STEP = re.compile(r"\.(\w+)|\[(\d+)\]")


def _fields(value: object) -> list[str]:
    """A dataclass's fields, but its caches (``compare=False``: made from the others when asked)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [f.name for f in dataclasses.fields(value) if f.compare]
    return []


def float_arrays(value: object, path: str = "") -> Iterator[tuple[str, np.ndarray]]:
    """Every float array reachable from ``value``, with its path from it, depth first."""
    seen: set[int] = set()

    def walk(item: object, where: str) -> Iterator[tuple[str, np.ndarray]]:
        if isinstance(item, np.ndarray):
            if item.dtype.kind == "f" and item.size:
                yield where, item
            return
        if isinstance(item, (str, bytes, int, float, bool, enum.Enum)) or item is None:
            return
        if id(item) in seen:
            return
        seen.add(id(item))
        if isinstance(item, (tuple, list)):
            for index, element in enumerate(item):
                yield from walk(element, f"{where}[{index}]")
            return
        for name in _fields(item):
            yield from walk(getattr(item, name), f"{where}.{name}" if where else name)

    yield from walk(value, path)


def _steps(path: str) -> list[str | int]:
    return [name if name else int(index) for name, index in _STEP.findall("." + path)]


def _replaced(item: object, steps: list[str | int], array: np.ndarray) -> object:
    """``item`` with the array at ``steps`` replaced; containers on the way are shallow copies."""
    if not steps:
        return array
    step, rest = steps[0], steps[1:]
    if isinstance(step, int):
        items = list(item)  # type: ignore[call-overload]
        items[step] = _replaced(items[step], rest, array)
        return type(item)(items) if isinstance(item, tuple) else items
    clone = copy.copy(item)
    object.__setattr__(clone, step, _replaced(getattr(item, step), rest, array))
    return clone


def corrupted(value: object, path: str, array: np.ndarray) -> object:
    """A copy of ``value`` whose array at ``path`` is ``array``; nothing is recomputed."""
    frozen = np.array(array, copy=True)
    frozen.flags.writeable = False
    return _replaced(value, _steps(path), frozen)


def corrupt_array(array: np.ndarray, kind: str, rng: np.random.Generator) -> np.ndarray | None:
    """``array`` with one corruption ``kind`` (:data:`CORRUPTIONS`) at a seeded place; ``None`` if none fits.

    ``swap`` exchanges two adjacent entries along the first axis that differ;
    ``move`` moves one nonzero entry by 1e-3 of its value.
    """
    out = np.array(array, dtype=float, copy=True)
    flat = out.reshape(-1)
    if kind in ("nan", "+inf", "-inf"):
        flat[rng.integers(flat.size)] = {"nan": np.nan, "+inf": np.inf, "-inf": -np.inf}[kind]
        return out
    if kind == "move":
        nonzero = np.flatnonzero(flat)
        if not nonzero.size:
            return None
        k = int(rng.choice(nonzero))
        flat[k] += 1e-3 * flat[k]
        return out
    if kind == "swap":
        if out.shape[0] < 2:
            return None
        rows = out.reshape(out.shape[0], -1)
        differ = np.flatnonzero(np.any(rows[1:] != rows[:-1], axis=1))
        if not differ.size:
            return None
        k = int(rng.choice(differ))
        rows[[k, k + 1]] = rows[[k + 1, k]]
        return out
    raise ValueError(f"unknown corruption {kind!r}: expected one of {CORRUPTIONS}")


def _braces(owner: str, field: str) -> str:
    """A pattern for ``owner.{a,field,b}``."""
    return re.escape(owner) + r"\.\{[^}]*\b" + re.escape(field) + r"\b[^}]*\}"


def names(message: str, path: str) -> bool:
    """Whether ``message`` names the array at ``path``: whole, or as ``owner.{..., field, ...}``.

    An array inside a list of objects (``path.blends[2].corner``) is also named by the list
    among its owner's arrays (``path.{vertices,blends}``).
    """
    owner, _, field = path.rpartition(".")
    if re.search(re.escape(path) + r"(?!\w)", message) or re.search(_braces(owner, field), message):
        return True
    inside = re.fullmatch(r"(.*)\.(\w+)\[\d+\]\.\w+", path)
    return bool(inside and re.search(_braces(inside.group(1), inside.group(2)), message))
