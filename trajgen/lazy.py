"""Package attributes imported on first use (PEP 562), so that importing a package stays cheap.

``import trajgen`` and ``import trajgen.cli`` load neither NumPy nor any solver: a name of the public
API is imported from the module that defines it when it is first used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping

__all__ = ["lazy_attributes"]


def lazy_attributes(
    package: str, namespace: dict, sources: Mapping[str, str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package`` for the names of ``sources``.

    Parameters
    ----------
    package : str
        The package's dotted name (its ``__name__``).
    namespace : dict
        The package's ``globals()``: a name, once imported, is kept there.
    sources : mapping of str to str
        Each public name and the dotted name of the module that defines it.
    """

    def attribute(name: str) -> object:
        try:
            source = sources[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(source), name)
        namespace[name] = value
        return value

    def names() -> list[str]:
        return sorted(set(namespace) | set(sources))

    return attribute, names
