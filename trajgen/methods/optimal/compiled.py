"""The compiled NLP of one shape with its solvers, and the bounded cache that keeps them.

A :class:`CompiledNlp` is built from its shape (transcription, then CasADi's derivatives and
fatrop's structure detection) or loaded from an :class:`~.store.NlpStore`, where a build is
kept for the next process. A :class:`SolverCache` keeps the most recently used ones in memory.
"""

from __future__ import annotations

import collections
import dataclasses
import enum
import logging
import threading
import time
from collections.abc import Callable

from trajgen.methods.optimal.output import casadi_output
from trajgen.methods.optimal.phases import NlpShape
from trajgen.methods.optimal.store import NlpStore, StoredNlp
from trajgen.methods.optimal.transcription import Transcription, transcribe

__all__ = [
    "BRAKING_FATROP_OPTIONS",
    "FATROP_OPTIONS",
    "IPOPT_POLISH_ITERATIONS",
    "SOLUTIONS_REMEMBERED",
    "CompiledNlp",
    "NlpOrigin",
    "RecentlyUsed",
    "Solver",
    "SolverCache",
]

logger = logging.getLogger(__name__)

#: Converged solutions a compiled NLP remembers (about 20 kB each on the benchmark shapes).
SOLUTIONS_REMEMBERED = 16
#: Iteration limit of the warm-started polish: it converges in < 20 when it is near a solution.
IPOPT_POLISH_ITERATIONS = 60

#: fatrop's options (besides the iteration limit, which is the shape's). Every solve is in the
#: problem's units (:mod:`~.units`), so these numbers mean the same on every track.
FATROP_OPTIONS: dict[str, float | int] = {
    "print_level": 0,
    # primal infeasibility stalls near 1e-8 with the h^3 terms; the separation is planned 1
    # micrometre clear and the verifier checks every result
    "tol": 1e-8,
    # 0.1 rather than 0.01: the first pass from the exact schedule's guess takes fewer iterations
    "mu_init": 1e-1,
}
#: What the braking rule's NLPs add. fatrop eliminates each stage's equality constraints (a
#: reversal's rest condition, a junction crossing, the goal's rest handed back from later stages)
#: by an LU factorization of their control block, accepting pivots down to its tolerance
#: (default 1e-5). Such a pivot can be tiny next to the rest of its row (a short interval's jerk
#: acting on a position or a velocity through h^3 j / 6 or h^2 j / 2); the reduced Hessian of
#: that stage then carries a rounding error that grows with the regularization itself. At some
#: iterates no regularization makes it positive definite: fatrop 1.1.8's inertia correction
#: (which has no upper limit) raises it until it overflows (measured: the same stage failing for
#: every value up to 1e293), the matrix turns NaN, BLASFEO's Cholesky takes a NaN pivot for a
#: non-positive one, and the loop never ends. That happened on 3 of 120 braking-rule plans of
#: the online campaign and 48 of about 140 of the wide one (``benchmarks/bench_braking_rule.py
#: --campaign 40 [--wide]``). At 1e-3 such constraints are handed to the stage before, whose
#: states they act on strongly: none of those plans hangs (1e-4 still hung on one). Without the
#: braking rule no plan hung at the default, and it stays there (1e-3 made fatrop fail on the
#: slower class of the 1000/800/1200 m track).
BRAKING_FATROP_OPTIONS: dict[str, float | int] = {"linsol_lu_fact_tol": 1e-3}


class Solver(enum.Enum):
    """The NLP solvers, in the order they are tried."""

    FATROP = "fatrop"  #: structure-exploiting interior point, from the initial guess
    IPOPT_POLISH = "ipopt-polish"  #: Ipopt warm-started from fatrop's last iterate and multipliers
    IPOPT = "ipopt"  #: Ipopt from the initial guess


class NlpOrigin(enum.Enum):
    """Where a compiled NLP came from."""

    BUILT = "built"  #: transcribed and differentiated in this process
    LOADED = "loaded"  #: deserialized from the disk store


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

    def values(self) -> list:
        """The values kept, least recently used first."""
        return list(self._entries.values())

    def pop(self, key) -> None:
        """Drop ``key`` if it is kept."""
        self._entries.pop(key, None)

    def clear(self) -> None:
        """Drop every entry."""
        self._entries.clear()


def fatrop_options(shape: NlpShape, equality: tuple[bool, ...]) -> dict:
    """The ``nlpsol`` options of the fatrop solver of ``shape``."""
    return {
        "structure_detection": "auto",
        "equality": list(equality),
        "print_time": False,
        "fatrop": {
            **FATROP_OPTIONS,
            **(BRAKING_FATROP_OPTIONS if shape.braking else {}),
            "max_iter": min(shape.max_iterations, shape.fatrop_iterations),
        },
    }


def store_description(shape: NlpShape) -> str:
    """What a stored NLP of ``shape`` depends on, as text (the store hashes it)."""
    return repr((dataclasses.replace(shape, slot=0), sorted(fatrop_options(shape, ())["fatrop"].items())))


#: Held while CasADi builds, loads or serializes a function: its symbolic objects are reference
#: counted without atomics, and two threads building at once crashed (a segmentation fault in
#: nlpsol, seen in CI). Solves, which only evaluate, run in parallel.
CONSTRUCTION_LOCK = threading.RLock()
#: Seconds a serialization for the disk store waits for the NLP's current solve to end.
SERIALIZATION_WAIT_S = 60.0


class CompiledNlp:
    """The NLP of one shape with its solvers; fatrop at once, the Ipopt backups on first need.

    Calls are serialized by a lock: a CasADi solver object is not reentrant. The last
    :data:`SOLUTIONS_REMEMBERED` converged solves are remembered by their guess and parameters:
    the solvers are deterministic, so the same problem asked again (a replan from the same
    state, a service answering the same request) gets the same answer without solving.

    Parameters
    ----------
    shape : NlpShape
    stored : StoredNlp, optional
        A solver loaded from the disk store; without it the NLP is built.

    Attributes
    ----------
    origin : NlpOrigin
        Built here, or loaded from the store.
    seconds : float
        Wall time the build or the load took.
    size : int
        Number of variables.
    bounds : dict of str to ndarray
        ``lbx``, ``ubx``, ``lbg``, ``ubg`` in SI units.
    """

    __slots__ = (
        "_lock",
        "_solvers",
        "_transcription",
        "abandoned",
        "bounds",
        "equality",
        "origin",
        "seconds",
        "shape",
        "size",
        "solutions",
    )

    def __init__(self, shape: NlpShape, stored: StoredNlp | None = None) -> None:
        import casadi as ca

        began = time.perf_counter()
        self.shape = shape
        self._lock = threading.Lock()
        #: Set when a solver call on this NLP never returned: its solver object stays busy in the
        #: abandoned call, so the cache builds the shape afresh rather than reuse it.
        self.abandoned = False
        #: converged solves by :func:`~.solve.problem_key` (use with the lock held)
        self.solutions = RecentlyUsed(SOLUTIONS_REMEMBERED)
        with CONSTRUCTION_LOCK, casadi_output():
            if stored is None:
                self._transcription: Transcription | None = transcribe(shape)
                self.bounds = self._transcription.bounds
                self.equality = self._transcription.equality
                fatrop = ca.nlpsol(
                    "trajgen_optimal_fatrop",
                    "fatrop",
                    self._transcription.nlp,
                    fatrop_options(shape, self.equality),
                )
                self.origin = NlpOrigin.BUILT
            else:
                self._transcription = None
                self.bounds, self.equality = stored.bounds, stored.equality
                fatrop = ca.Function.deserialize(stored.solver)
                self.origin = NlpOrigin.LOADED
        self.size = int(self.bounds["lbx"].size)
        self._solvers: dict[Solver | tuple[Solver, float], object] = {Solver.FATROP: fatrop}
        self.seconds = time.perf_counter() - began

    @property
    def transcription(self) -> Transcription:
        """The symbolic NLP (built now if this one was loaded: only the Ipopt backups need it)."""
        if self._transcription is None:
            with CONSTRUCTION_LOCK, casadi_output():
                self._transcription = transcribe(self.shape)
        return self._transcription

    def serialization(self, *, wait: float = SERIALIZATION_WAIT_S) -> str | None:
        """The fatrop solver, CasADi-serialized (what the disk store keeps); ``None`` if it stays busy.

        Taken between solves (with :attr:`lock`): serializing a function while it is being called
        crashed CasADi (seen in CI). ``wait``: seconds to wait for a solve to end (an abandoned one
        never does).
        """
        if not self._lock.acquire(timeout=wait):
            return None
        try:
            with CONSTRUCTION_LOCK:
                return self._solvers[Solver.FATROP].serialize()
        finally:
            self._lock.release()

    def solver(self, which: Solver, *, ipopt_wall_time: float):
        """The CasADi solver ``which``, built on first use (call with the lock held).

        ``ipopt_wall_time``: seconds after which an Ipopt run stops by itself, a safety stop (an
        Ipopt option, so each value is a solver of its own; fatrop ignores it).
        """
        key = which if which is Solver.FATROP else (which, ipopt_wall_time)
        if key not in self._solvers:
            with CONSTRUCTION_LOCK, casadi_output():
                self._solvers[key] = self._ipopt(warm=which is Solver.IPOPT_POLISH, wall_time=ipopt_wall_time)
        return self._solvers[key]

    def _ipopt(self, *, warm: bool, wall_time: float):
        """Ipopt on the same NLP; ``warm``: polish a nearby iterate, starting from its multipliers."""
        import casadi as ca

        options = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": min(self.shape.max_iterations, IPOPT_POLISH_ITERATIONS)
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
        Most shapes kept in memory (default 32). Each holds compiled CasADi functions of about
        7 MB (measured on the benchmark shapes).
    store : NlpStore or None, optional
        Where built NLPs are kept across processes and looked up before building (default
        ``None``: build in this process only). :meth:`Optimal.shared_cache` uses the user's
        store (:func:`~.store.default_store`).

    Examples
    --------
    >>> cache = SolverCache(maxsize=4)
    >>> len(cache), cache.maxsize, cache.store is None
    (0, 4, True)
    """

    __slots__ = ("_building", "_entries", "_lock", "store")

    def __init__(self, maxsize: int = 32, *, store: NlpStore | None = None) -> None:
        if isinstance(maxsize, bool) or not isinstance(maxsize, int) or maxsize < 1:
            raise ValueError(f"solver cache maxsize must be an integer >= 1, got {maxsize!r}")
        if store is not None and not isinstance(store, NlpStore):
            raise ValueError(f"solver cache store must be an NlpStore or None, got {type(store).__name__}")
        self._entries = RecentlyUsed(maxsize)
        self._building: dict[NlpShape, threading.Lock] = {}
        self._lock = threading.Lock()
        self.store = store

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

    def compiled(self) -> list[CompiledNlp]:
        """The compiled NLPs kept in memory, least recently used first (for diagnostics)."""
        with self._lock:
            return list(self._entries.values())

    def clear(self) -> None:
        """Drop every compiled NLP kept in memory (the store keeps its files)."""
        with self._lock:
            self._entries.clear()

    def forget_solutions(self) -> None:
        """Drop the solves each compiled NLP remembers (the NLPs stay): the next solves run the solvers.

        For timing the solvers alone (``benchmarks/bench_optimal.py``'s warm pass).
        """
        for entry in self.compiled():
            with entry.lock:
                entry.solutions.clear()

    def _cached(self, shape: NlpShape) -> CompiledNlp | None:
        with self._lock:
            entry = self._entries.get(shape)
            if entry is not None and getattr(entry, "abandoned", False):
                self._entries.pop(shape)
                return None
            return entry

    def _prepare(self, shape: NlpShape) -> CompiledNlp:
        """Load ``shape``'s NLP from the store, else build it (and store it in the background)."""
        description = store_description(shape)
        if self.store is not None:
            stored = self.store.load(description)
            if stored is not None:
                try:
                    compiled = CompiledNlp(shape, stored)
                except RuntimeError as error:  # written by an incompatible build: build it anew
                    logger.warning("optimal: the stored NLP could not be loaded (%s); building it", error)
                else:
                    logger.info(
                        "loaded the optimal-control NLP for %d phase(s) in %.2f s",
                        shape.phase_count,
                        compiled.seconds,
                    )
                    return compiled
        compiled = CompiledNlp(shape)
        logger.info(
            "built the optimal-control NLP for %d phase(s) in %.2f s", shape.phase_count, compiled.seconds
        )
        if self.store is not None:
            self.store.save_later(description, compiled.serialization, compiled.bounds, compiled.equality)
        return compiled

    def get(
        self, shape: NlpShape, *, build: Callable[[NlpShape], CompiledNlp] | None = None
    ) -> tuple[CompiledNlp, bool]:
        """The compiled NLP of ``shape`` and whether this call prepared it (built or loaded it).

        Each shape is prepared once; threads asking for a shape being prepared wait for it.
        ``build`` replaces the preparation (tests).
        """
        entry = self._cached(shape)
        if entry is not None:
            return entry, False
        with self._lock:
            building = self._building.setdefault(shape, threading.Lock())
        with building:  # one thread prepares a shape; the others wait for it
            entry = self._cached(shape)
            if entry is not None:
                return entry, False
            try:
                entry = (build or self._prepare)(shape)
            finally:
                with self._lock:
                    self._building.pop(shape, None)
            with self._lock:
                self._entries.put(shape, entry)
            return entry, True
