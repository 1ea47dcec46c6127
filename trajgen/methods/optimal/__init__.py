"""The ``optimal`` method: time-optimal jerk-limited schedules in the two shortest homotopy classes.

Formulation (docs/planner.md, 'Homotopy classes'). The route's reduced region sequence
``R_1 ... R_P`` fixes the homotopy class. Phase ``p`` keeps the vehicles in
region ``R_p``: each vehicle on a fixed leg, tracked by its distance ``s``
from the junction, with state ``(s, v, a)`` and jerk as control, piecewise
constant on a grid of fixed fractions of free segment durations; the sum of
the durations is minimized. Between phases one vehicle changes leg at the
junction (``s = 0``), where its ``v`` and ``a`` change sign. Inside a region
the separation is linear in ``(s1, s2)``.

Modules: :mod:`~.phases` (phases from the route, the stage layout),
:mod:`~.transcription` (the NLP), :mod:`~.units` (the units it is solved in),
:mod:`~.compiled` (a compiled NLP and the cache of them), :mod:`~.store` (compiled NLPs on disk),
:mod:`~.solve` (the chain of solvers), :mod:`~.output` (CasADi's messages into logging),
:mod:`~.guess` (initial guess from ``exact``), :mod:`~.decode` (solution to
schedule), :mod:`~.mesh` (mesh refinement), :mod:`~.classes` (classes solved side by side),
:mod:`~.info` (diagnostics), :mod:`~.method` (the :class:`Optimal` method object).
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:  # imported when first used: the option enum alone loads no NLP code
    from trajgen.methods.optimal.choice import HomotopyChoice
    from trajgen.methods.optimal.compiled import NlpOrigin, Solver, SolverCache
    from trajgen.methods.optimal.info import ClassComparison, OptimalInfo, Source
    from trajgen.methods.optimal.method import (
        DEFAULT_NODES,
        DEFAULT_REFINEMENT_TOLERANCE,
        DEFAULT_TIME_LIMIT,
        Optimal,
    )
    from trajgen.methods.optimal.solve import Outcome, SolverAttempt
    from trajgen.methods.optimal.store import NlpStore
    from trajgen.methods.optimal.units import ProblemUnits

__all__ = [
    "DEFAULT_NODES",
    "DEFAULT_REFINEMENT_TOLERANCE",
    "DEFAULT_TIME_LIMIT",
    "ClassComparison",
    "HomotopyChoice",
    "NlpOrigin",
    "NlpStore",
    "Optimal",
    "OptimalInfo",
    "Outcome",
    "ProblemUnits",
    "Solver",
    "SolverAttempt",
    "SolverCache",
    "Source",
]

_SOURCES = {
    "DEFAULT_NODES": "trajgen.methods.optimal.method",
    "DEFAULT_REFINEMENT_TOLERANCE": "trajgen.methods.optimal.method",
    "DEFAULT_TIME_LIMIT": "trajgen.methods.optimal.method",
    "ClassComparison": "trajgen.methods.optimal.info",
    "HomotopyChoice": "trajgen.methods.optimal.choice",
    "NlpOrigin": "trajgen.methods.optimal.compiled",
    "NlpStore": "trajgen.methods.optimal.store",
    "Optimal": "trajgen.methods.optimal.method",
    "OptimalInfo": "trajgen.methods.optimal.info",
    "Outcome": "trajgen.methods.optimal.solve",
    "ProblemUnits": "trajgen.methods.optimal.units",
    "Solver": "trajgen.methods.optimal.compiled",
    "SolverAttempt": "trajgen.methods.optimal.solve",
    "SolverCache": "trajgen.methods.optimal.compiled",
    "Source": "trajgen.methods.optimal.info",
}
__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
