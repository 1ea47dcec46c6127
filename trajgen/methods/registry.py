"""The registry of timing methods: the one list the dispatcher, CLI, plots and benchmarks read."""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from limits import Limits
from topology import GraphRoute, Route
from trajgen.errors import InputError, OptionError
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.schedule import Schedule, TimingMethod

__all__ = ["MethodRegistry", "MethodSource"]


@dataclass(frozen=True, slots=True)
class MethodSource:
    """A timing method registered by where it lives, imported when first created or listed.

    A command that only names the methods (``--help``) or uses one of them then loads none of
    the others' dependencies (the optimal method's NLP code, TOPPRA).

    Attributes
    ----------
    name : str
        The method's name, as its class's ``name``.
    description : str
        One line for help texts, as its class's ``description``.
    module : str
        Dotted name of the module that defines the class.
    class_name : str
        The class's name in that module.
    """

    name: str
    description: str
    module: str
    class_name: str

    def load(self) -> type[TimingMethod]:
        """The class, imported; its ``name`` and ``description`` must be the registered ones.

        Raises
        ------
        RuntimeError
            The class's ``name`` or ``description`` differs from the registered one.
        """
        method = getattr(importlib.import_module(self.module), self.class_name)
        if (method.name, method.description) != (self.name, self.description):
            raise RuntimeError(
                f"timing method {self.module}.{self.class_name} is named {method.name!r} "
                f"({method.description!r}), registered as {self.name!r} ({self.description!r})"
            )
        return method


class MethodRegistry:
    """Timing method classes by name, in a fixed order, with a default.

    Parameters
    ----------
    methods : sequence of TimingMethod subclasses or MethodSource
        Each class must be constructible without arguments (its default options); a
        :class:`MethodSource` is imported when the method is first created or iterated over.
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

    __slots__ = ("_by_name", "_descriptions", "default")

    def __init__(self, methods: Sequence[type[TimingMethod] | MethodSource], *, default: str) -> None:
        self._by_name: dict[str, type[TimingMethod] | MethodSource] = {}
        for method in methods:
            if method.name in self._by_name:
                raise ValueError(f"timing method name {method.name!r} is registered twice")
            self._by_name[method.name] = method
        if default not in self._by_name:
            raise ValueError(f"default method {default!r} is not among {list(self._by_name)!r}")
        self._descriptions = {name: method.description for name, method in self._by_name.items()}
        #: Name of the default method.
        self.default = default

    @property
    def names(self) -> tuple[str, ...]:
        """Method names, in registration order."""
        return tuple(self._by_name)

    def __iter__(self) -> Iterator[type[TimingMethod]]:
        return (self._load(name) for name in self._by_name)

    def __len__(self) -> int:
        return len(self._by_name)

    def _load(self, name: str) -> type[TimingMethod]:
        method = self._by_name[name]
        if isinstance(method, MethodSource):
            method = self._by_name[name] = method.load()
        return method

    def canonical(self, name: object) -> str:
        """The registered name ``name`` means (case-insensitive), without loading the method.

        Raises
        ------
        OptionError
            Naming the value and the accepted names.
        """
        key = str(name).strip().lower() if isinstance(name, str) else None
        if key not in self._by_name:
            text = repr(name) if len(repr(name)) <= 40 else repr(name)[:37] + "..."
            raise OptionError(f"method {text} is unknown: expected one of {list(self._by_name)!r}")
        return key

    def lookup(self, name: object) -> type[TimingMethod]:
        """The method class named ``name`` (case-insensitive).

        Raises
        ------
        OptionError
            Naming the value and the accepted names.
        """
        return self._load(self.canonical(name))

    def create(self, method: TimingMethod | str | None = None) -> TimingMethod:
        """A method object: ``method`` itself, the named method with default options, or the default."""
        if isinstance(method, TimingMethod):
            return method
        return self.lookup(self.default if method is None else method)()

    def help(self) -> str:
        """One line per method for help texts: ``name: description``."""
        return "\n".join(
            f"{name}: {description}" + (" (default)" if name == self.default else "")
            for name, description in self._descriptions.items()
        )

    def schedule(
        self, route: Route | GraphRoute, limits: Limits, *, method: TimingMethod | str | None = None
    ) -> Schedule | GraphSchedule:
        """Time-parameterize ``route`` with ``method`` (unverified; see :func:`trajgen.verification.certify`).

        Raises
        ------
        OptionError
            Unknown method name.
        InputError
            ``route`` or ``limits`` of the wrong type, a route planned for a smaller separation than
            ``limits`` asks, or limits of another number of vehicles than the route moves.
        """
        chosen = self.create(method)
        count = len(tuple(getattr(route, "start", ())))
        if isinstance(limits, Limits) and count and limits.count != count:
            raise InputError(
                f"limits of {limits.count} vehicle(s) for a route of {count}: expected one per vehicle"
            )
        if isinstance(route, GraphRoute):
            return chosen.schedule_graph(route, limits)
        return chosen.schedule(route, limits)
