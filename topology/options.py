"""String options as enums with a validating lookup."""

from __future__ import annotations

import enum
import re
import warnings

from topology.errors import OptionError

__all__ = ["Option", "rename_values"]

#: Each option class's renamed values: old value -> (new value, the release that renamed it).
_RENAMED: dict[type, dict[str, tuple[str, str]]] = {}


def rename_values(option: type[Option], renamed: dict[str, str], version: str) -> None:
    """Let ``option`` take each old value of ``renamed`` (old -> new) for one release, with a warning."""
    _RENAMED.setdefault(option, {}).update({old: (new, version) for old, new in renamed.items()})


class Option(enum.StrEnum):
    """Base of the package's string options; messages name the quantity by :meth:`label`."""

    @classmethod
    def label(cls) -> str:
        """The quantity's name in messages: the class name in words (``HomotopyChoice``: homotopy choice)."""
        return re.sub(r"(?<!^)(?=[A-Z])", " ", cls.__name__).lower()

    @classmethod
    def _missing_(cls, value: object):
        """An old value of :func:`rename_values`: its new member, with a ``DeprecationWarning``."""
        new, version = _RENAMED.get(cls, {}).get(value, (None, None))
        if new is None:
            return None
        warnings.warn(
            f"{cls.label()} {value!r} is deprecated since trajgen {version}: use {new!r}",
            DeprecationWarning,
            stacklevel=3,
        )
        return cls(new)

    @classmethod
    def lookup(cls, name: object):
        """The member named ``name`` (case-insensitive).

        Raises
        ------
        OptionError
            Naming the option, the value and the accepted names.
        """
        try:
            return cls(str(name).lower())
        except ValueError:
            raise OptionError(
                f"{cls.label()} {name!r} is unknown: expected one of {[m.value for m in cls]!r}"
            ) from None
