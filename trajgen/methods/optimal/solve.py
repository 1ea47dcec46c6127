"""Solvers of the optimal-control NLP, the chain they are tried in, and the bounded solver cache.

fatrop, the structure-exploiting interior-point solver shipped with CasADi,
solves most problems (about 3x faster per iteration than Ipopt with MUMPS
here). If it stalls short of its tolerance (it can, where a vehicle creeps up
to the end of its leg), Ipopt warm-started from fatrop's last iterate and
multipliers polishes it in about 10 iterations; Ipopt from the initial guess
is the last resort.
"""

from __future__ import annotations

import collections
import enum
import logging
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trajgen.methods.optimal.phases import NlpShape
from trajgen.methods.optimal.transcription import Transcription, transcribe

__all__ = [
    "CompiledNlp",
    "Outcome",
    "RecentlyUsed",
    "SolveResult",
    "Solver",
    "SolverAttempt",
    "SolverCache",
    "abandoned_solver_calls",
    "problem_key",
    "solve",
]

logger = logging.getLogger(__name__)

#: Longest wait for one fatrop call without a deadline, and the grace past a deadline, seconds.
_WATCHDOG_CAP = 60.0
_WATCHDOG_GRACE = 0.05
#: Iteration limit of the warm-started polish: it converges in < 20 when it is near a solution.
_POLISH_MAX_ITER = 60
#: Seconds an Ipopt run may take by default: half the optimal method's default time budget.
DEFAULT_IPOPT_WALL_TIME = 1.0
#: Converged solutions a compiled NLP remembers (about 20 kB each on the benchmark shapes).
SOLUTIONS_REMEMBERED = 16


class Solver(enum.Enum):
    """The NLP solvers, in the order they are tried."""

    FATROP = "fatrop"  #: structure-exploiting interior point, from the initial guess
    IPOPT_POLISH = "ipopt-polish"  #: Ipopt warm-started from fatrop's last iterate and multipliers
    IPOPT = "ipopt"  #: Ipopt from the initial guess


class Outcome(enum.Enum):
    """How one solver attempt ended."""

    SOLVED = "solved"
    NOT_CONVERGED = "not-converged"
    RAISED = "raised"
    OUT_OF_TIME = "out-of-time"  #: not tried: the time budget was spent
    ABANDONED = "abandoned"  #: started, but not back by the deadline: left running, its result unused


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


class RecentlyUsed:
    """A mapping that keeps its ``size`` most recently used entries, dropping the least recently used.

    Not thread-safe: its owner holds a lock (:class:`SolverCache`, a :class:`CompiledNlp`'s).

    Examples
    --------
    >>> kept = RecentlyUsed(1)
    >>> kept.put(b"a", "first"); kept.put(b"b", "second")
    >>> kept.get(b"a") is None, kept.get(b"b"), len(kept)
    (True, 'second', 1)
    """

    __slots__ = ("_entries", "size")

    def __init__(self, size: int) -> None:
        self.size = size
        self._entries: collections.OrderedDict = collections.OrderedDict()

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, key: object) -> bool:
        return key in self._entries

    def get(self, key):
        """The value kept for ``key`` (now the most recently used), or ``None``."""
        value = self._entries.get(key)
        if value is not None:
            self._entries.move_to_end(key)
        return value

    def put(self, key, value) -> None:
        """Keep ``value`` for ``key``, dropping the least recently used beyond :attr:`size`."""
        self._entries[key] = value
        self._entries.move_to_end(key)
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)

    def pop(self, key) -> None:
        """Drop ``key`` if it is kept."""
        self._entries.pop(key, None)

    def clear(self) -> None:
        """Drop every entry."""
        self._entries.clear()


class CompiledNlp:
    """The NLP of one shape with its solvers; fatrop built at once, the Ipopt backups on first need.

    Calls are serialized by a lock: a CasADi solver object is not reentrant. The last
    :data:`SOLUTIONS_REMEMBERED` converged solves are remembered by their guess and parameters:
    the solvers are deterministic, so the same problem asked again (a replan from the same
    state, a service answering the same request) gets the same answer without solving.
    """

    __slots__ = ("_lock", "_solvers", "abandoned", "shape", "solutions", "transcription")

    def __init__(self, shape: NlpShape) -> None:
        import casadi as ca

        self.shape = shape
        self.transcription: Transcription = transcribe(shape)
        self._lock = threading.Lock()
        #: Set when a solver call on this NLP never returned: its solver object stays busy in the
        #: abandoned call, so the cache builds the shape afresh rather than reuse it.
        self.abandoned = False
        #: converged solves by :func:`problem_key` (use with the lock held)
        self.solutions = RecentlyUsed(SOLUTIONS_REMEMBERED)
        nlp = self.transcription.nlp
        self._solvers: dict[Solver | tuple[Solver, float], object] = {
            Solver.FATROP: ca.nlpsol(
                "trajgen_optimal_fatrop",
                "fatrop",
                nlp,
                {
                    "structure_detection": "auto",
                    "equality": list(self.transcription.equality),
                    "print_time": False,
                    # tol 1e-8: primal infeasibility stalls near 1e-8 (round-off of the h^3 terms);
                    # the separation is planned 1 micrometre clear and the verifier checks every result
                    "fatrop": {
                        "print_level": 0,
                        "max_iter": min(shape.max_iterations, shape.fatrop_iterations),
                        "tol": 1e-8,
                        # 0.1 rather than 0.01: the first pass from the exact schedule's guess takes
                        # 20-60 % fewer iterations (103 -> 43 on 200/120/80 m), refinement passes the same
                        "mu_init": 1e-1,
                    },
                },
            )
        }

    def solver(self, which: Solver, *, ipopt_wall_time: float = DEFAULT_IPOPT_WALL_TIME):
        """The CasADi solver ``which``, built on first use (call with the lock held).

        ``ipopt_wall_time``: seconds after which an Ipopt run stops by itself (an Ipopt option, so
        each value is a solver of its own; fatrop ignores it).
        """
        key = which if which is Solver.FATROP else (which, ipopt_wall_time)
        if key not in self._solvers:
            self._solvers[key] = self._ipopt(warm=which is Solver.IPOPT_POLISH, wall_time=ipopt_wall_time)
        return self._solvers[key]

    def _ipopt(self, *, warm: bool, wall_time: float):
        """Ipopt on the same NLP; ``warm``: polish a nearby iterate, starting from its multipliers."""
        import casadi as ca

        options = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": min(self.shape.max_iterations, _POLISH_MAX_ITER)
            if warm
            else self.shape.max_iterations,
            "ipopt.tol": 1e-9,
            "ipopt.constr_viol_tol": 1e-10,
            "ipopt.mu_strategy": "monotone",
            "ipopt.mu_init": 1e-2,
            "ipopt.max_wall_time": wall_time,
        }
        if warm:
            options.update(
                {
                    "ipopt.warm_start_init_point": "yes",
                    "ipopt.mu_init": 1e-8,
                    "ipopt.warm_start_bound_push": 1e-9,
                    "ipopt.warm_start_mult_bound_push": 1e-9,
                    "ipopt.warm_start_slack_bound_push": 1e-9,
                }
            )
        name = "trajgen_optimal_ipopt" + ("_polish" if warm else "")
        return ca.nlpsol(name, "ipopt", self.transcription.nlp, options)

    @property
    def lock(self) -> threading.Lock:
        """Held while a solver of this NLP runs."""
        return self._lock


class SolverCache:
    """Compiled NLPs by shape: bounded (least recently used dropped first) and thread-safe.

    Parameters
    ----------
    maxsize : int, optional
        Most shapes kept (default 32). Each holds compiled CasADi functions of about 7 MB
        (measured on the benchmark shapes).

    Examples
    --------
    >>> cache = SolverCache(maxsize=4)
    >>> len(cache), cache.maxsize
    (0, 4)
    """

    __slots__ = ("_building", "_entries", "_lock")

    def __init__(self, maxsize: int = 32) -> None:
        if isinstance(maxsize, bool) or not isinstance(maxsize, int) or maxsize < 1:
            raise ValueError(f"solver cache maxsize must be an integer >= 1, got {maxsize!r}")
        self._entries = RecentlyUsed(maxsize)
        self._building: dict[NlpShape, threading.Lock] = {}
        self._lock = threading.Lock()

    @property
    def maxsize(self) -> int:
        """Most shapes kept."""
        return self._entries.size

    def __len__(self) -> int:
        with self._lock:
            return len(self._entries)

    def __contains__(self, shape: object) -> bool:
        with self._lock:
            return shape in self._entries

    def clear(self) -> None:
        """Drop every compiled NLP."""
        with self._lock:
            self._entries.clear()

    def _cached(self, shape: NlpShape) -> CompiledNlp | None:
        with self._lock:
            entry = self._entries.get(shape)
            if entry is not None and getattr(entry, "abandoned", False):
                self._entries.pop(shape)
                return None
            return entry

    def get(
        self, shape: NlpShape, *, build: Callable[[NlpShape], CompiledNlp] = CompiledNlp
    ) -> tuple[CompiledNlp, bool]:
        """The compiled NLP of ``shape`` and whether this call built it (each shape is built once)."""
        entry = self._cached(shape)
        if entry is not None:
            return entry, False
        with self._lock:
            building = self._building.setdefault(shape, threading.Lock())
        with building:  # one thread builds a shape; the others wait for it
            entry = self._cached(shape)
            if entry is not None:
                return entry, False
            try:
                entry = build(shape)
            finally:
                with self._lock:
                    self._building.pop(shape, None)
            logger.info("built the optimal-control NLP for %d phase(s)", shape.phase_count)
            with self._lock:
                self._entries.put(shape, entry)
            return entry, True


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
_ABANDONED = "did not return by the deadline; abandoned (its NLP is rebuilt for the next solve)"


def _call_with_watchdog(
    solver, start: dict, parameters, bounds: dict, compiled: CompiledNlp, deadline: float
):
    """Run ``solver`` in a daemon thread; its ``(result, stats)``, or ``None`` if not back by the deadline.

    fatrop 1.1.8 can loop forever in its inertia correction (seen on an NLP with the braking rule:
    no iteration limit stops it). CasADi releases the GIL while it solves, so the caller goes on;
    the abandoned call keeps its thread until the process ends, and ``compiled`` is marked so that
    no later solve waits on it.
    """
    box: dict = {}

    def run() -> None:
        try:
            box["result"] = solver(**start, p=parameters, **bounds)
            box["stats"] = solver.stats()
        except BaseException as error:  # handed to the caller's thread
            box["error"] = error

    thread = threading.Thread(target=run, name="trajgen-fatrop", daemon=True)
    thread.start()
    wait = deadline - time.perf_counter()
    thread.join(min(max(wait, 0.0), _WATCHDOG_CAP) + _WATCHDOG_GRACE)
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
    deadline: float = float("inf"),
    ipopt_wall_time: float = DEFAULT_IPOPT_WALL_TIME,
) -> SolveResult:
    """Try fatrop, then the warm Ipopt polish of its last iterate, then Ipopt from ``guess``.

    No solver is started after ``deadline`` (a ``time.perf_counter()`` value);
    each Ipopt run stops by itself after ``ipopt_wall_time`` seconds. A problem that ``compiled``
    solved before (same ``guess`` and ``parameters``) gets its remembered result at once.
    """
    attempts: list[SolverAttempt] = []
    previous = None  # the last solver's finite result, to warm-start the polish
    bounds = compiled.transcription.bounds
    key = problem_key(guess, parameters)
    with compiled.lock:
        known = compiled.solutions.get(key)
        if known is not None:
            logger.debug("optimal: this problem was solved before; its solution is reused")
            return known
        for which in Solver:
            if time.perf_counter() > deadline:
                attempts.append(SolverAttempt(which, Outcome.OUT_OF_TIME, 0, "the time budget is spent"))
                break
            if which is Solver.IPOPT_POLISH:
                if previous is None:
                    continue
                start = {"x0": previous["x"], "lam_x0": previous["lam_x"], "lam_g0": previous["lam_g"]}
            else:
                start = {"x0": guess}
            solver = compiled.solver(which, ipopt_wall_time=ipopt_wall_time)
            try:
                if which is Solver.FATROP:
                    call = _call_with_watchdog(solver, start, parameters, bounds, compiled, deadline)
                    if call is None:
                        attempts.append(SolverAttempt(which, Outcome.ABANDONED, -1, _ABANDONED))
                        break
                    result, stats = call
                else:
                    result = solver(**start, p=parameters, **bounds)
                    stats = solver.stats()
            except RuntimeError as error:  # CasADi reports evaluation and solver errors as RuntimeError
                attempts.append(SolverAttempt(which, Outcome.RAISED, -1, str(error)[:200]))
                previous = None
                continue
            iterations = int(stats.get("iter_count", -1))
            status = str(stats.get("return_status", stats.get("success")))
            if stats.get("success", False):
                attempts.append(SolverAttempt(which, Outcome.SOLVED, iterations, status))
                solution = np.array(result["x"]).ravel()
                solution.flags.writeable = False
                solved = SolveResult(solution, tuple(attempts))
                compiled.solutions.put(key, solved)
                return solved
            previous = result if np.all(np.isfinite(np.array(result["x"]))) else None
            attempts.append(SolverAttempt(which, Outcome.NOT_CONVERGED, iterations, status))
            logger.info("optimal: %s did not converge (%s); trying the next solver", which.value, status)
    return SolveResult(None, tuple(attempts))


def problem_key(guess: np.ndarray, parameters: np.ndarray) -> bytes:
    """The bytes that tell one problem on a compiled NLP from another: its guess and parameters."""
    return (
        np.ascontiguousarray(guess, dtype=float).tobytes()
        + b"|"
        + np.ascontiguousarray(parameters, dtype=float).tobytes()
    )
