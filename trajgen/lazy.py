"""Names resolved on use: package attributes imported on first use (PEP 562), and renamed attributes.

``import trajgen`` and ``import trajgen.cli`` load neither NumPy nor any solver: a name of the public
API is imported from the module that defines it when it is first used. :class:`RenamedAttribute`
keeps an attribute's old name working, with a ``DeprecationWarning``, for one release.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping

__all__ = ["RenamedAttribute", "lazy_attributes"]


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


class RenamedAttribute:
    """A class attribute's old name: reading it (on the class or an instance) warns and gives the new one.

    Parameters
    ----------
    new : str
        The attribute's name now.
    version : str
        The release that renamed it (for the warning).
    """

    def __init__(self, new: str, version: str) -> None:
        self.new = new
        self.version = version
        self.old = new

    def __set_name__(self, owner: type, name: str) -> None:
        self.old = name

    def __get__(self, instance: object, owner: type | None = None) -> object:
        source = owner if instance is None else instance
        warnings.warn(
            f"{type(source).__name__ if instance is not None else source.__name__}.{self.old} is deprecated "
            f"since trajgen {self.version}: use .{self.new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(source, self.new)
