"""The timing methods, peers behind :class:`~trajgen.model.schedule.TimingMethod`, and their registry.

Adding a method: write its class (a frozen dataclass implementing
``TimingMethod``) and list it in :data:`METHODS` below; the dispatcher, the
command line, the plots and the benchmarks read the registry.

Examples
--------
>>> from trajgen.methods import METHODS, Optimal
>>> METHODS.create("optimal") == Optimal()
True
"""

from __future__ import annotations

from limits import Limits
from topology import Route
from trajgen.methods.exact import Exact
from trajgen.methods.optimal import ClassComparison, HomotopyChoice, Optimal, OptimalInfo, SolverCache
from trajgen.methods.registry import MethodRegistry
from trajgen.methods.toppra import Toppra
from trajgen.model.schedule import Schedule, TimingMethod

__all__ = [
    "METHODS",
    "ClassComparison",
    "Exact",
    "HomotopyChoice",
    "MethodRegistry",
    "Optimal",
    "OptimalInfo",
    "SolverCache",
    "Toppra",
    "make_schedule",
]

#: Every timing method, in display order; ``optimal`` is the default.
METHODS = MethodRegistry((Exact, Toppra, Optimal), default=Optimal.name)


def make_schedule(route: Route, limits: Limits, *, method: TimingMethod | str | None = None) -> Schedule:
    """Time-parameterize ``route`` with ``method`` (an object with options, a name, or the default).

    The result is not yet verified: see :func:`trajgen.verification.certify`.

    Raises
    ------
    OptionError
        Unknown method name.
    """
    return METHODS.schedule(route, limits, method=method)
