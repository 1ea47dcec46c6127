"""The chain of solvers an optimal-control NLP is tried with, and the watchdog of a stalled call.

fatrop, the structure-exploiting interior-point solver shipped with CasADi,
solves most problems (about 3x faster per iteration than Ipopt with MUMPS
here). If it stalls short of its tolerance (it can, where a vehicle creeps up
to the end of its leg), Ipopt warm-started from fatrop's last iterate and
multipliers polishes it in about 10 iterations; Ipopt from the initial guess
is the last resort. Every solver runs in the problem's units (:mod:`~.units`).

How much effort a solve takes is fixed by iteration limits, never by the clock: the same
problem gets the same answer on an idle and on a loaded machine. The one wall-clock limit is a
safety stop far above the usual solve time (the method's ``time_limit``), for a solver that
does not come back; whoever hits it is told (:attr:`Outcome.ABANDONED`,
:attr:`Outcome.OUT_OF_TIME`).
"""

from __future__ import annotations

import enum
import logging
import math
import os
import threading
import time
from dataclasses import dataclass

import numpy as np

from trajgen.methods.optimal.compiled import CompiledNlp, Solver
from trajgen.methods.optimal.output import casadi_output
from trajgen.methods.optimal.transcription import ParameterLayout
from trajgen.methods.optimal.units import ProblemUnits

__all__ = [
    "Outcome",
    "SolveResult",
    "SolverAttempt",
    "abandoned_solver_calls",
    "problem_key",
    "solve",
]

logger = logging.getLogger(__name__)

#: Grace past the deadline before a fatrop call is abandoned, seconds.
_WATCHDOG_GRACE = 0.05


class Outcome(enum.Enum):
    """How one solver attempt ended."""

    SOLVED = "solved"
    NOT_CONVERGED = "not-converged"
    RAISED = "raised"
    OUT_OF_TIME = "out-of-time"  #: not tried: the method's time limit (a safety stop) was reached
    ABANDONED = "abandoned"  #: started, but not back by the time limit: left running, its result unused


@dataclass(frozen=True, slots=True)
class SolverAttempt:
    """One solver's try.

    Attributes
    ----------
    solver : Solver
    outcome : Outcome
    iterations : int
        Iterations it took (-1 if it raised).
    status : str
        The solver's own return status or error text (for people, not for branching).
    """

    solver: Solver
    outcome: Outcome
    iterations: int
    status: str

    def __str__(self) -> str:
        if self.outcome is Outcome.SOLVED:
            return f"{self.solver.value} solved in {self.iterations} iterations"
        if self.outcome is Outcome.RAISED:
            return f"{self.solver.value} raised: {self.status}"
        if self.outcome is Outcome.ABANDONED:
            return f"{self.solver.value} {self.status}"
        if self.outcome is Outcome.OUT_OF_TIME:
            return f"{self.solver.value} not tried: {self.status}"
        return f"{self.solver.value} did not converge ({self.status}, {self.iterations} iterations)"


@dataclass(frozen=True, slots=True)
class SolveResult:
    """What the solver chain delivered.

    Attributes
    ----------
    solution : ndarray or None
        The variables of the first solver that converged, shape (size,); ``None`` if none did.
    attempts : tuple of SolverAttempt
        Every solver tried, in order.
    """

    solution: np.ndarray | None
    attempts: tuple[SolverAttempt, ...]

    @property
    def solver(self) -> Solver | None:
        """The solver that converged, if any."""
        return self.attempts[-1].solver if self.solution is not None else None


#: Threads of solver calls abandoned by the watchdog that are still running.
_ABANDONED_THREADS: list[threading.Thread] = []
#: Status of a fatrop call that did not return by the deadline.
_ABANDONED = "did not return within the time limit; abandoned (its NLP is rebuilt for the next solve)"


def _call_with_watchdog(
    solver, start: dict, parameters, bounds: dict, compiled: CompiledNlp, deadline: float
):
    """Run ``solver`` in a daemon thread; its ``(result, stats)``, or ``None`` if not back by the deadline.

    The last defence against a solver that never returns (fatrop 1.1.8's inertia correction has
    no upper limit; :data:`~.compiled.FATROP_OPTIONS` avoids what made it loop). CasADi releases
    the GIL while it solves, so the caller goes on; the abandoned call keeps its thread until the
    process ends, and ``compiled`` is marked so that no later solve waits on it.
    """
    box: dict = {}

    def run() -> None:
        try:
            with casadi_output():
                box["result"] = solver(**start, p=parameters, **bounds)
            box["stats"] = solver.stats()
        except BaseException as error:  # handed to the caller's thread
            box["error"] = error

    thread = threading.Thread(target=run, name="trajgen-fatrop", daemon=True)
    thread.start()
    wait = deadline - time.perf_counter()
    thread.join(None if math.isinf(wait) else max(wait, 0.0) + _WATCHDOG_GRACE)
    if thread.is_alive():
        compiled.abandoned = True
        _ABANDONED_THREADS.append(thread)
        _lowest_priority(thread)
        logger.warning("optimal: fatrop %s", _ABANDONED)
        return None
    if "error" in box:
        raise box["error"]
    return box["result"], box["stats"]


def abandoned_solver_calls() -> int:
    """How many solver calls the watchdog abandoned are still running in this process."""
    return sum(thread.is_alive() for thread in _ABANDONED_THREADS)


def _lowest_priority(thread: threading.Thread) -> None:
    """Give an abandoned solver thread the lowest CPU priority, where the OS allows it per thread.

    A thread cannot be stopped from outside; at ``nice 19`` it only takes otherwise idle CPU time.
    """
    try:
        os.setpriority(os.PRIO_PROCESS, thread.native_id, 19)
    except (AttributeError, OSError, TypeError):  # not Linux, or no native id: it keeps its priority
        logger.debug("optimal: could not lower the priority of an abandoned solver thread")


def solve(
    compiled: CompiledNlp,
    guess: np.ndarray,
    parameters: np.ndarray,
    *,
    units: ProblemUnits,
    deadline: float = float("inf"),
    ipopt_wall_time: float = 60.0,
) -> SolveResult:
    """Try fatrop, then the warm Ipopt polish of its last iterate, then Ipopt from ``guess``.

    ``guess`` (size,) and ``parameters`` are in SI units; the solvers see them in ``units``
    and the solution is returned in SI units. No solver is started after ``deadline`` (a
    ``time.perf_counter()`` value, the safety stop), and a fatrop call not back by then is
    abandoned; each Ipopt run stops by itself after ``ipopt_wall_time`` seconds. A problem that
    ``compiled`` solved before (same ``guess``, ``parameters`` and ``units``) gets its remembered
    result at once.
    """
    attempts: list[SolverAttempt] = []
    previous = None  # the last solver's finite result, to warm-start the polish
    bounds = dict(compiled.bounds)
    if units.is_identity:  # seconds and metres: nothing to convert
        scale, scaled_parameters = 1.0, parameters
    else:
        shape = compiled.shape
        scale = units.variables(shape)
        layout = ParameterLayout(shape.phase_count, shape.intervals)
        scaled_parameters = parameters / units.scale(*layout.dimensions)
        bounds["lbx"], bounds["ubx"] = bounds["lbx"] / scale, bounds["ubx"] / scale
    key = problem_key(guess, parameters, units)
    with compiled.lock:
        known = compiled.solutions.get(key)
        if known is not None:
            logger.debug("optimal: this problem was solved before; its solution is reused")
            return known
        for which in Solver:
            if time.perf_counter() > deadline:
                attempts.append(SolverAttempt(which, Outcome.OUT_OF_TIME, 0, "the time limit was reached"))
                break
            if which is Solver.IPOPT_POLISH:
                if previous is None:
                    continue
                start = {"x0": previous["x"], "lam_x0": previous["lam_x"], "lam_g0": previous["lam_g"]}
            else:
                start = {"x0": guess / scale}
            solver = compiled.solver(which, ipopt_wall_time=ipopt_wall_time)
            try:
                if which is Solver.FATROP:
                    call = _call_with_watchdog(solver, start, scaled_parameters, bounds, compiled, deadline)
                    if call is None:
                        attempts.append(SolverAttempt(which, Outcome.ABANDONED, -1, _ABANDONED))
                        break
                    result, stats = call
                else:
                    with casadi_output():
                        result = solver(**start, p=scaled_parameters, **bounds)
                    stats = solver.stats()
            except RuntimeError as error:  # CasADi reports evaluation and solver errors as RuntimeError
                attempts.append(SolverAttempt(which, Outcome.RAISED, -1, str(error)[:200]))
                previous = None
                continue
            iterations = int(stats.get("iter_count", -1))
            status = str(stats.get("return_status", stats.get("success")))
            if stats.get("success", False):
                attempts.append(SolverAttempt(which, Outcome.SOLVED, iterations, status))
                solution = np.array(result["x"]).ravel() * scale
                solution.flags.writeable = False
                solved = SolveResult(solution, tuple(attempts))
                compiled.solutions.put(key, solved)
                return solved
            previous = result if np.all(np.isfinite(np.array(result["x"]))) else None
            attempts.append(SolverAttempt(which, Outcome.NOT_CONVERGED, iterations, status))
            logger.info("optimal: %s did not converge (%s); trying the next solver", which.value, status)
    return SolveResult(None, tuple(attempts))


def problem_key(guess: np.ndarray, parameters: np.ndarray, units: ProblemUnits) -> bytes:
    """The bytes that tell one problem on a compiled NLP from another: its guess, parameters and units."""
    return b"|".join(
        [
            np.ascontiguousarray(guess, dtype=float).tobytes(),
            np.ascontiguousarray(parameters, dtype=float).tobytes(),
            np.array([units.length, units.time], dtype=float).tobytes(),
        ]
    )
