"""String options as enums with a validating lookup."""

from __future__ import annotations

import enum
import re

from topology.errors import OptionError

__all__ = ["Option"]


class Option(enum.StrEnum):
    """Base of the package's string options; messages name the quantity by :meth:`label`."""

    @classmethod
    def label(cls) -> str:
        """The quantity's name in messages: the class name in words (``HomotopyChoice``: homotopy choice)."""
        return re.sub(r"(?<!^)(?=[A-Z])", " ", cls.__name__).lower()

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
