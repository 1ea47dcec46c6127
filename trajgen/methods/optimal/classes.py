"""Solving homotopy classes side by side: each class's passes, and the race that stops a beaten one.

:class:`ClassSolve` holds what one class delivered (its passes, unverified, and how the
solvers fared); :class:`ClassRace` lets concurrently solved classes tell each other their
first-grid makespans, so that a class another clearly beats stops refining.
"""

from __future__ import annotations

import threading
import time

from limits import Limits
from topology import Route
from trajgen.methods.optimal.compiled import NlpOrigin
from trajgen.methods.optimal.decode import PhaseSolution, sections
from trajgen.methods.optimal.info import OptimalInfo
from trajgen.methods.optimal.phases import NlpShape, Phase
from trajgen.methods.optimal.solve import SolverAttempt
from trajgen.model.schedule import FallbackReason, Schedule, TimingMethod

__all__ = ["ClassRace", "ClassSolve", "makespan"]


def makespan(solution: list[PhaseSolution]) -> float:
    """Duration of a decoded solution, seconds."""
    return float(sum(phase.times[-1] for phase in solution))


class ClassRace:
    """The classes solved at once, telling each other their first-grid makespans (thread-safe).

    Every class reports its first grid (``None`` if it failed) and waits until all have; later
    decisions compare with those values only, which are fixed by then, so whether a class refines
    does not depend on which thread was quicker.
    """

    __slots__ = ("_best", "_changed", "_count", "_reported")

    def __init__(self, classes: list[int]) -> None:
        self._count = len(classes)
        self._best: dict[int, float] = {}
        self._reported: set[int] = set()
        self._changed = threading.Condition()

    def first_pass(self, slot: int, makespan: float | None, deadline: float) -> None:
        """Report class ``slot``'s first-grid makespan (``None``: failed); wait for the others' reports."""
        with self._changed:
            self._reported.add(slot)
            if makespan is not None:
                self._best[slot] = makespan
            self._changed.notify_all()
            wait = max(0.0, deadline - time.perf_counter())
            self._changed.wait_for(lambda: len(self._reported) >= self._count, timeout=wait)

    def beaten(self, slot: int, makespan: float, remaining: float) -> bool:
        """Whether another class's first grid beats ``makespan`` even after a gain of ``remaining``."""
        with self._changed:
            others = [m for k, m in self._best.items() if k != slot]
        return bool(others) and min(others) < makespan * (1.0 - remaining)


class ClassSolve:
    """What solving one homotopy class delivered: its passes, unverified, and how the solvers fared."""

    __slots__ = (
        "attempts",
        "built",
        "cut_short",
        "detail",
        "failure",
        "limits",
        "origin",
        "passes",
        "phases",
        "route",
        "shape",
    )

    def __init__(
        self, route: Route, limits: Limits, phases: tuple[Phase, ...], shape: NlpShape, *, built: bool
    ) -> None:
        self.route, self.limits, self.phases, self.shape, self.built = route, limits, phases, shape, built
        self.attempts: tuple[SolverAttempt, ...] = ()
        #: (makespan, solution, attempt) of each solved pass, the first grid first
        self.passes: list[tuple[float, list[PhaseSolution], SolverAttempt]] = []
        self.failure: FallbackReason | None = None
        self.detail = ""
        #: where its compiled NLP came from, when this solve prepared it (None: it was in memory)
        self.origin: NlpOrigin | None = None
        #: whether the time limit (a safety stop) ended its refinement
        self.cut_short = False

    @property
    def refinements(self) -> int:
        """Refinement passes solved after the first."""
        return max(len(self.passes) - 1, 0)

    @property
    def makespan(self) -> float | None:
        """The fastest pass's makespan, seconds (None if nothing was solved)."""
        return min(m for m, _, _ in self.passes) if self.passes else None

    def add(self, solution: list[PhaseSolution], attempt: SolverAttempt) -> None:
        """Record a solved pass."""
        self.passes.append((makespan(solution), solution, attempt))

    def failed(self, reason: FallbackReason, detail: str) -> ClassSolve:
        """Record why the class has no solution; returns itself."""
        self.failure, self.detail = reason, detail
        return self

    def schedule(self, method: TimingMethod, index: int, *, segments: int, nodes: int) -> Schedule:
        """Pass ``index`` as an (unverified) schedule of ``method`` (``segments`` x ``nodes`` a phase)."""
        _, solution, attempt = self.passes[index]
        grid = f"{len(self.phases)} phase(s) x {segments} segments x {nodes} intervals"
        note = f"{grid}, pass {index + 1} of {len(self.passes)} (mesh refinement); {attempt}"
        info = OptimalInfo(0.0, self.built, self.attempts, refinements=self.refinements, solved_by=attempt)
        return Schedule(
            self.route,
            self.limits,
            method,
            sections(self.route, self.limits, self.phases, solution),
            jerk_limited=True,
            notes=(note,),
            info=info,
        )
