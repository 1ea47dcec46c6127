"""The registry of timing methods: the one list the dispatcher, CLI, plots and benchmarks read."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from limits import Limits
from topology import Route
from trajgen.errors import OptionError
from trajgen.model.schedule import Schedule, TimingMethod

__all__ = ["MethodRegistry"]


class MethodRegistry:
    """Timing method classes by name, in a fixed order, with a default.

    Parameters
    ----------
    methods : sequence of TimingMethod subclasses
        Each must be constructible without arguments (its default options).
    default : str
        Name of the method used when none is given.

    Examples
    --------
    >>> from trajgen.methods import METHODS
    >>> METHODS.names
    ('exact', 'toppra', 'optimal')
    >>> METHODS.create("Exact")
    Exact(jerk=True)
    """

    __slots__ = ("_by_name", "default")

    def __init__(self, methods: Sequence[type[TimingMethod]], *, default: str) -> None:
        self._by_name: dict[str, type[TimingMethod]] = {}
        for method in methods:
            if method.name in self._by_name:
                raise ValueError(f"timing method name {method.name!r} is registered twice")
            self._by_name[method.name] = method
        if default not in self._by_name:
            raise ValueError(f"default method {default!r} is not among {list(self._by_name)!r}")
        #: Name of the default method.
        self.default = default

    @property
    def names(self) -> tuple[str, ...]:
        """Method names, in registration order."""
        return tuple(self._by_name)

    def __iter__(self) -> Iterator[type[TimingMethod]]:
        return iter(self._by_name.values())

    def __len__(self) -> int:
        return len(self._by_name)

    def lookup(self, name: object) -> type[TimingMethod]:
        """The method class named ``name`` (case-insensitive).

        Raises
        ------
        OptionError
            Naming the value and the accepted names.
        """
        key = str(name).strip().lower() if isinstance(name, str) else None
        if key not in self._by_name:
            text = repr(name) if len(repr(name)) <= 40 else repr(name)[:37] + "..."
            raise OptionError(f"method {text} is unknown: expected one of {list(self._by_name)!r}")
        return self._by_name[key]

    def create(self, method: TimingMethod | str | None = None) -> TimingMethod:
        """A method object: ``method`` itself, the named method with default options, or the default."""
        if isinstance(method, TimingMethod):
            return method
        return self.lookup(self.default if method is None else method)()

    def help(self) -> str:
        """One line per method for help texts: ``name: summary``."""
        return "\n".join(
            f"{name}: {cls.summary}" + (" (default)" if name == self.default else "")
            for name, cls in self._by_name.items()
        )

    def schedule(self, route: Route, limits: Limits, *, method: TimingMethod | str | None = None) -> Schedule:
        """Time-parameterize ``route`` with ``method`` (unverified; see :func:`trajgen.verification.certify`).

        Raises
        ------
        OptionError
            Unknown method name.
        InputError
            ``route`` or ``limits`` of the wrong type, or a route planned for a
            smaller separation than ``limits`` asks.
        """
        chosen = self.create(method)
        return chosen.schedule(route, limits)
