"""A progress bar for long batch work, shown only when stderr is a terminal."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

__all__ = ["progress"]

Item = TypeVar("Item")


def progress(items: Iterable[Item], *, total: int | None = None, description: str = "") -> Iterator[Item]:
    """Iterate over ``items`` with a progress bar on stderr, or silently when stderr is no terminal.

    Parameters
    ----------
    items : iterable
    total : int, optional
        Number of items, when ``items`` has no length.
    description : str, optional
        Label shown before the bar.

    Examples
    --------
    >>> list(progress(range(3), description="demo"))  # silent under pytest: stderr is no terminal
    [0, 1, 2]
    """
    shown = sys.stderr is not None and sys.stderr.isatty()
    if not shown:
        yield from items
        return
    from tqdm import tqdm  # a bar only on a terminal: batch runs and the command line start without it

    yield from tqdm(items, total=total, desc=description or None, file=sys.stderr, leave=False)
