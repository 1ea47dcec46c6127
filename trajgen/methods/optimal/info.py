"""Diagnostics of ``optimal``: where its motion comes from, which classes it considered."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from topology import Homotopy, WayRound
from trajgen.methods.optimal.compiled import Solver
from trajgen.methods.optimal.solve import SolverAttempt
from trajgen.model.schedule import FallbackReason, MethodInfo

__all__ = ["ClassComparison", "OptimalInfo", "Source"]


class Source(enum.Enum):
    """Where the motion of an ``optimal`` schedule comes from."""

    NLP = "nlp"  #: the solver's solution
    EXACT = "exact"  #: the exact schedule, faster than the discretized optimum (or a fallback)


@dataclass(frozen=True, slots=True)
class ClassComparison:
    """One homotopy class considered by ``optimal`` with ``homotopy="fastest"``.

    Attributes
    ----------
    homotopy : Homotopy
        Whether it is the planner's class or the other (the other way round a Y's circle, the
        second-shortest route on ``G_k`` for more legs).
    way_round : WayRound
        Its direction round the boundary circle (``GRAPH`` for four or more legs).
    lower_bound : float
        :func:`~trajgen.model.analysis.class_lower_bound`, seconds.
    makespan : float or None
        Its best solved makespan, seconds (verified where ``chosen``; a class that another
        beat by more than refinement could gain keeps its first grid's); ``None`` when not
        solved (its lower bound could not beat the faster ``exact`` schedule).
    chosen : bool
        Whether the returned schedule is in this class.
    failure : FallbackReason or None
        Why the class has no makespan although it was to be solved (its solvers failed, ran
        out of time, or its setup raised); ``None`` otherwise.
    label : str or None
        Four or more legs: which route on ``G_k`` it is, for people
        (:func:`trajgen.model.summary.class_name`, e.g. ``second-shortest route on G_4``); ``None``
        for three legs, where ``way_round`` says it.
    """

    homotopy: Homotopy
    way_round: WayRound
    lower_bound: float
    makespan: float | None
    chosen: bool
    failure: FallbackReason | None = None
    label: str | None = None

    def summary(self) -> dict:
        """JSON-ready fields (``class`` too where there is a :attr:`label`)."""
        fields = {
            "homotopy": self.homotopy.value,
            "way_round": self.way_round.value,
            "lower_bound_s": self.lower_bound,
            "makespan_s": self.makespan,
            "chosen": self.chosen,
            "failure": None if self.failure is None else self.failure.value,
        }
        if self.label is not None:
            fields["class"] = self.label
        return fields


@dataclass(frozen=True, slots=True)
class OptimalInfo(MethodInfo):
    """Diagnostics of one ``optimal`` solve.

    Attributes
    ----------
    solve_time : float
        Wall time from the request to the end of the last solve, seconds: the ``exact`` schedules,
        every class's solves and refinement passes (concurrent), and the build if it was built;
        verification excluded.
    built : bool
        Whether an NLP had to be built (its shape was neither in memory nor in the disk store).
    attempts : tuple of SolverAttempt
        Every solver tried, in order (class by class).
    source : Source
        Whether the schedule's motion is the solver's or the exact schedule's.
    refinements : int
        Mesh-refinement passes solved after the first (see :mod:`~.mesh`), the most of any class.
    classes : tuple of ClassComparison
        The homotopy classes considered (empty when only the route's own was).
    solved_by : SolverAttempt or None
        The solver attempt that produced the returned solution (its class and pass).
    loaded : bool
        Whether an NLP was loaded from the disk store (:mod:`~.store`) for this request.
    time_limit_reached : bool
        Whether the time limit (a safety stop) ended a class's refinement early: the schedule
        may then be slower than on a machine that finished it.
    """

    solve_time: float
    built: bool
    attempts: tuple[SolverAttempt, ...] = ()
    source: Source = Source.NLP
    refinements: int = 0
    classes: tuple[ClassComparison, ...] = ()
    solved_by: SolverAttempt | None = None
    loaded: bool = False
    time_limit_reached: bool = False

    @property
    def solver(self) -> Solver | None:
        """The solver that converged on the returned solution (None if the motion is not the NLP's)."""
        if self.source is Source.NLP and self.solved_by is not None:
            return self.solved_by.solver
        return None

    @property
    def iterations(self) -> int:
        """Iterations of the solver that converged on the returned solution (-1 if none did)."""
        return self.solved_by.iterations if self.solver is not None else -1

    @property
    def status(self) -> str:
        """What each solver tried reported, for people."""
        return "; ".join(str(attempt) for attempt in self.attempts)

    def summary(self) -> dict:
        """JSON-ready diagnostics."""
        return {
            "solve_time_s": self.solve_time,
            "built": self.built,
            "loaded": self.loaded,
            "time_limit_reached": self.time_limit_reached,
            "solver": None if self.solver is None else self.solver.value,
            "iterations": self.iterations,
            "status": self.status,
            "source": self.source.value,
            "refinements": self.refinements,
            "classes": [c.summary() for c in self.classes],
        }
