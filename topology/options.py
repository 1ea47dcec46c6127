"""String options as enums with a validating lookup."""

from __future__ import annotations

import enum

from topology.errors import OptionError

__all__ = ["Option"]


class Option(enum.StrEnum):
    """Base of the package's string options; the quantity's name is the class name, lower case."""

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
                f"{cls.__name__.lower()} {name!r} is unknown: expected one of {[m.value for m in cls]!r}"
            ) from None
