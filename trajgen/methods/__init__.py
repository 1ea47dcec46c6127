"""The timing methods, peers behind :class:`~trajgen.model.schedule.TimingMethod`, and their registry.

Adding a method: write its class (a frozen dataclass implementing
``TimingMethod``) and list it in :data:`METHODS` below; the dispatcher, the
command line, the plots and the benchmarks read the registry. Each method is
imported when first used, so naming the methods (``trajgen --help``) or using
``exact`` loads neither the optimal method's NLP code nor TOPPRA.

Examples
--------
>>> from trajgen.methods import METHODS, Optimal
>>> METHODS.create("optimal") == Optimal()
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from limits import Limits
from topology import Route
from trajgen.lazy import lazy_attributes
from trajgen.methods.registry import MethodRegistry, MethodSource
from trajgen.model.schedule import Schedule, TimingMethod

if TYPE_CHECKING:  # imported when first used
    from trajgen.methods.exact import Exact
    from trajgen.methods.optimal import ClassComparison, HomotopyChoice, Optimal, OptimalInfo, SolverCache
    from trajgen.methods.toppra import Toppra

__all__ = [
    "METHODS",
    "ClassComparison",
    "Exact",
    "HomotopyChoice",
    "MethodRegistry",
    "MethodSource",
    "Optimal",
    "OptimalInfo",
    "SolverCache",
    "Toppra",
    "make_schedule",
    "method_for",
]

_SOURCES = {
    "ClassComparison": "trajgen.methods.optimal",
    "Exact": "trajgen.methods.exact",
    "HomotopyChoice": "trajgen.methods.optimal.choice",
    "Optimal": "trajgen.methods.optimal",
    "OptimalInfo": "trajgen.methods.optimal",
    "SolverCache": "trajgen.methods.optimal",
    "Toppra": "trajgen.methods.toppra",
}
__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)

#: Every timing method, in display order; ``optimal`` is the default.
METHODS = MethodRegistry(
    (
        MethodSource(
            "exact",
            "the route exactly, one straight piece at a time, jerk-limited S-curves",
            "trajgen.methods.exact",
            "Exact",
        ),
        MethodSource(
            "toppra",
            "rounded corners where safe, TOPPRA velocity/acceleration timing (jerk not limited)",
            "trajgen.methods.toppra",
            "Toppra",
        ),
        MethodSource(
            "optimal",
            "time-optimal jerk-limited schedule, faster of the two shortest homotopy classes (CasADi)",
            "trajgen.methods.optimal",
            "Optimal",
        ),
    ),
    default="optimal",
)


#: The method a track graph is timed by when none is asked for.
GRAPH_DEFAULT = "exact"


def method_for(method: TimingMethod | str | None, track) -> TimingMethod:
    """The method object of ``method``, or for ``None`` the default for ``track``.

    The one rule every command follows: ``exact`` on a track graph (:data:`GRAPH_DEFAULT`; its
    optimal method can take minutes on a large layout), the registry's default (``optimal``) on a
    junction.

    Raises
    ------
    OptionError
        Unknown method name.
    """
    from topology import TrackGraph

    return METHODS.create(GRAPH_DEFAULT if method is None and isinstance(track, TrackGraph) else method)


def make_schedule(route: Route, limits: Limits, *, method: TimingMethod | str | None = None) -> Schedule:
    """Time-parameterize ``route`` with ``method`` (an object with options, a name, or the default).

    The result is not yet verified: see :func:`trajgen.verification.certify`.

    Raises
    ------
    OptionError
        Unknown method name.
    """
    return METHODS.schedule(route, limits, method=method)
