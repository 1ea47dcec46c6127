"""The ``optimal`` method object: options, the pipeline from route to verified schedule, diagnostics."""

from __future__ import annotations

import concurrent.futures
import dataclasses
import logging
import math
import threading
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar

from limits import Limits
from topology import Homotopy, OptionError, Route, plan
from trajgen.errors import InputError
from trajgen.methods.exact import Exact
from trajgen.methods.graph_classes import solve_graph
from trajgen.methods.optimal.choice import HomotopyChoice
from trajgen.methods.optimal.class_solve import problem_parameters, solve_class
from trajgen.methods.optimal.classes import ClassRace, ClassSolve
from trajgen.methods.optimal.compiled import NlpOrigin, SolverCache
from trajgen.methods.optimal.info import ClassComparison, OptimalInfo, Source
from trajgen.methods.optimal.phases import NlpShape, route_phases
from trajgen.methods.optimal.store import default_store
from trajgen.model.analysis import class_lower_bound
from trajgen.model.schedule import FallbackReason, Schedule, TimingMethod, check_request
from trajgen.model.summary import class_label, class_name
from trajgen.verification import verify

__all__ = [
    "DEFAULT_NODES",
    "DEFAULT_REFINEMENT_TOLERANCE",
    "DEFAULT_TIME_LIMIT",
    "Optimal",
    "problem_parameters",
]

logger = logging.getLogger(__name__)

#: Intervals per segment. 32: with fewer, mesh refinement converges slowly where the optimum is one
#: vehicle's own S-curve (24 nodes: 0.02 % a pass, still 0.24 % over after the tolerance stopped it).
DEFAULT_NODES = 32
#: Default of ``Optimal.time_limit``, seconds: a safety stop, about 20 times the slowest usual
#: solve (a braking-rule plan of two classes, 1.5 s on the benchmark machine).
DEFAULT_TIME_LIMIT = 30.0
#: Default of ``Optimal.refinement_tolerance``: far from a vehicle's own S-curve successive passes gain
#: a quarter or less of the one before (benchmark sets), so stopping after a pass that gained less
#: than 0.15 % leaves well under issue 10's 0.2 %; near a vehicle's own S-curve it stops later
#: (:mod:`~trajgen.methods.optimal.class_solve`).
DEFAULT_REFINEMENT_TOLERANCE = 1.5e-3
#: Relative makespan difference below which two classes tie (the route's own class is kept).
_TIE = 1e-6


def _positive_int(value: object, name: str, minimum: int = 1) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(f"optimal option {name} must be an integer >= {minimum}, got {value!r}")


def class_copies(shapes: list[NlpShape]) -> list[NlpShape]:
    """``shapes``, a second copy (slot) where classes solved at once share one (one solve per NLP)."""
    return [dataclasses.replace(shape, slot=shapes[:k].count(shape)) for k, shape in enumerate(shapes)]


@dataclass(frozen=True, slots=True)
class Optimal(TimingMethod):
    """The fastest jerk-limited schedule of the two shortest homotopy classes, verified; else ``exact``.

    A multi-phase optimal-control problem along the route's region sequence
    (CasADi: fatrop, then Ipopt), built once per region-sequence shape and
    reused from ``cache``. The result is verified; if the solvers fail or the
    result does not verify, the ``exact`` schedule is returned with
    ``fallback_reason`` set. Where ``exact`` is faster (vehicles that never
    interact), it is returned, with ``info.source`` ``Source.EXACT``.

    Parameters
    ----------
    nodes : int, optional
        Control intervals per segment (default :data:`DEFAULT_NODES`).
    segments : int, optional
        Segments of free duration per phase (default 1).
    max_iterations : int, optional
        Iteration limit of Ipopt (default 500; and of fatrop, with ``fatrop_iterations``). With the
        time limit only a safety stop, the iteration limits bound a failing solve: Ipopt from
        scratch converges in 40-150 iterations where it converges (benchmark and campaign sets),
        and 500 of them take 2-10 s.
    fatrop_iterations : int, optional
        Iteration limit of fatrop (default 500; < 150 where it converges).
    time_limit : float, optional
        A safety stop, seconds (default :data:`DEFAULT_TIME_LIMIT`, 30 s, about 20 times the
        slowest usual solve; the one-time build or load of an NLP is not counted). The effort is
        fixed by iteration limits, refinement passes and the tolerance, never by the clock, so
        the same request gives the same schedule on an idle and on a loaded machine; only a
        solver that does not come back meets this limit: no solver starts after it, a fatrop run
        not back by then is abandoned and an Ipopt run stops. The result then says so:
        ``fallback_reason`` ``time-limit`` if no class was solved, else
        ``info.time_limit_reached`` and a note (the passes solved before it are kept).
    time_budget : float, optional
        Deprecated name of ``time_limit`` (0.7).
    braking_rule : bool, optional
        State the braking rule (:mod:`trajgen.verification.braking_rule`) in the problem (default
        ``False``), so that the plan can be executed by the order-keeping :class:`~trajgen.execution.Executor`
        without holds; verify then checks it. Slower (its NLP takes 1.2 s to build, 0.2 s to
        load from the disk store, and about 0.25 s a solve); the executor's
        :func:`~trajgen.execution.schedule_for_execution` turns it on.
    refinements : int, optional
        Most mesh-refinement passes after the first solve (default 6): the grid's nodes move to the
        jerk switches of the previous pass and the same compiled NLP is solved again (see
        :mod:`~.mesh`), until a pass shortens the makespan by less than ``refinement_tolerance``.
        0 keeps the first grid.
    refinement_tolerance : float, optional
        Relative makespan gain below which refinement stops (default
        :data:`DEFAULT_REFINEMENT_TOLERANCE`, 0.15 %), in (0, 1); 15 times smaller for a
        solution within 1 % of its class lower bound, where refinement converges slowly.
    homotopy : HomotopyChoice or str, optional
        ``"fastest"`` (default): solve the route's class and the other one, return the faster:
        the other way round the boundary circle (three legs), or the second-shortest route on
        ``G_k`` (four to eight legs, ``plan(..., homotopy="other")``). ``"planned"``: the route's
        class only.
    cache : SolverCache or None, optional
        Where compiled NLPs are kept; ``None`` (default): the process-wide :meth:`shared_cache`.
        On a track graph: :mod:`trajgen.methods.graph_optimal`'s problem, no cache.
    """

    name: ClassVar[str] = "optimal"
    description: ClassVar[str] = (
        "time-optimal jerk-limited schedule, faster of the two shortest homotopy classes (CasADi)"
    )
    _shared: ClassVar[list[SolverCache]] = []
    _shared_lock: ClassVar[threading.Lock] = threading.Lock()

    nodes: int = DEFAULT_NODES
    segments: int = 1
    max_iterations: int = 500
    fatrop_iterations: int = 500
    time_limit: float = DEFAULT_TIME_LIMIT
    refinements: int = 6
    refinement_tolerance: float = DEFAULT_REFINEMENT_TOLERANCE
    homotopy: HomotopyChoice = HomotopyChoice.FASTEST
    cache: SolverCache | None = field(default=None, compare=False, repr=False)
    braking_rule: bool = False
    time_budget: float | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        _positive_int(self.nodes, "nodes")
        _positive_int(self.segments, "segments")
        _positive_int(self.max_iterations, "max_iterations")
        _positive_int(self.fatrop_iterations, "fatrop_iterations")
        _positive_int(self.refinements, "refinements", minimum=0)
        object.__setattr__(self, "homotopy", HomotopyChoice.lookup(self.homotopy))
        tolerance = self.refinement_tolerance
        if (
            isinstance(tolerance, bool)
            or not isinstance(tolerance, (int, float))
            or not 0.0 < tolerance < 1.0
        ):
            raise InputError(
                f"optimal option refinement_tolerance must be a number in (0, 1), got {tolerance!r}"
            )
        if self.time_budget is not None:
            warnings.warn(
                "Optimal(time_budget=...) is deprecated: the effort is fixed by iterations and passes; "
                "use time_limit, a safety stop",
                DeprecationWarning,
                stacklevel=3,
            )
            object.__setattr__(self, "time_limit", self.time_budget)
            object.__setattr__(self, "time_budget", None)
        limit = self.time_limit
        if isinstance(limit, bool) or not isinstance(limit, (int, float)) or not 0.0 < limit < math.inf:
            raise InputError(
                f"optimal option time_limit must be a finite number of seconds > 0, got {limit!r}"
            )
        if self.cache is not None and not isinstance(self.cache, SolverCache):
            raise InputError(
                f"optimal option cache must be a SolverCache or None, got {type(self.cache).__name__}"
            )

    @classmethod
    def shared_cache(cls) -> SolverCache:
        """The process-wide solver cache used when no ``cache`` is given (32 shapes at most).

        Created on first use, with the disk store of :func:`~.store.default_store`
        (``$TRAJGEN_CACHE_DIR`` or the user's cache folder) as it is configured then.
        """
        with cls._shared_lock:
            if not cls._shared:
                cls._shared.append(SolverCache(maxsize=32, store=default_store()))
            return cls._shared[0]

    @property
    def jerk_limited(self) -> bool:
        """Always True."""
        return True

    def solver_cache(self) -> SolverCache:
        """The cache of NLPs this method solves on (its own, else the shared one)."""
        return self.cache if self.cache is not None else Optimal.shared_cache()

    def shape(self, route: Route) -> NlpShape:
        """The NLP shape of ``route`` with these options (the cache key)."""
        return NlpShape.of(
            route_phases(route),
            nodes=self.nodes,
            segments=self.segments,
            max_iterations=self.max_iterations,
            fatrop_iterations=self.fatrop_iterations,
            braking=self.braking_rule,
        )

    @property
    def plans_for_execution(self) -> bool:
        """Whether its schedules obey the braking rule: with ``braking_rule``."""
        return self.braking_rule

    def for_execution(self) -> Optimal:
        """The same method with the braking rule in its problem."""
        return self if self.braking_rule else dataclasses.replace(self, braking_rule=True)

    def warm_up(self, route: Route) -> bool:
        """Prepare the NLPs ``route``'s classes need in the cache now (built, or loaded from its store).

        Returns whether any was prepared (``False``: all were in memory already).
        """
        if len(route.waypoints) == 1:
            return False
        shapes = class_copies([self.shape(r) for r in self.class_routes(route)])
        return any([self.solver_cache().get(shape)[1] for shape in shapes])

    def class_routes(self, route: Route) -> list[Route]:
        """The routes of the classes this method considers: ``route``'s own first, then the other.

        The other is the other way round the boundary circle (three legs) or the other of the
        planner's shortest and second-shortest routes on ``G_k`` (four to eight legs). With
        ``homotopy="planned"``, or where start and goal retract to one boundary point (the other
        way would be a full turn), only ``route``.
        """
        if self.homotopy is HomotopyChoice.PLANNED or route.arc_length == 0.0:
            return [route]
        other = Homotopy.OTHER if route.homotopy is Homotopy.PLANNED else Homotopy.PLANNED
        graph, start, goal, separation = route.graph, route.start, route.goal, route.min_separation
        try:
            return [route, plan(graph, start, goal, min_separation=separation, homotopy=other)]
        except OptionError:  # start and goal retract to one boundary point up to round-off
            return [route]

    schedule_graph = solve_graph  # on a track graph (verified), or the flagged ``exact`` one

    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """The optimal schedule from ``route``'s start to its goal (verified), or the flagged ``exact`` one.

        With ``homotopy="fastest"`` the route's class and the other
        (:meth:`class_routes`) are both considered: a class whose lower bound
        (:func:`~trajgen.model.analysis.class_lower_bound`) cannot beat the faster
        of the two ``exact`` schedules is skipped, the others are solved
        concurrently, and the fastest solution that verifies is returned
        (the route's own class on a tie). Its ``route`` is its class's route.
        """
        check_request(route, limits)
        began = time.perf_counter()
        exact = Exact().schedule(route, limits)
        if len(route.waypoints) == 1:  # nothing moves: the exact schedule is optimal
            return self._as_optimal(exact, "start is the goal: nothing moves", None)
        routes = self.class_routes(route)
        exacts = [exact, *(Exact().schedule(r, limits) for r in routes[1:])]
        bounds = [class_lower_bound(r, limits) for r in routes]
        fastest_exact = min(exacts, key=lambda e: e.duration)
        # a class whose bound reaches the fastest exact schedule cannot beat it: not solved
        wanted = [k for k, bound in enumerate(bounds) if bound < fastest_exact.duration * (1.0 - 1e-9)]
        deadline = began + self.time_limit  # a safety stop: the effort is fixed by iterations and passes
        race = ClassRace(wanted)
        shapes = dict(zip(wanted, class_copies([self.shape(routes[k]) for k in wanted]), strict=True))

        def solve_one(k: int) -> ClassSolve:
            return solve_class(
                self,
                routes[k],
                limits,
                exacts[k],
                shapes[k],
                slot=k,
                deadline=deadline,
                race=race,
                bound=bounds[k],
            )

        if len(wanted) > 1:
            with concurrent.futures.ThreadPoolExecutor(
                len(wanted), thread_name_prefix="trajgen-class"
            ) as pool:
                futures = {k: pool.submit(solve_one, k) for k in wanted}
                solved = {k: future.result() for k, future in futures.items()}
        else:
            solved = {k: solve_one(k) for k in wanted}
        solve_time = time.perf_counter() - began
        attempts = tuple(a for k in wanted for a in solved[k].attempts)
        info = OptimalInfo(
            solve_time,
            any(solved[k].origin is NlpOrigin.BUILT for k in wanted),
            attempts,
            refinements=max((solved[k].refinements for k in wanted), default=0),
            loaded=any(solved[k].origin is NlpOrigin.LOADED for k in wanted),
            time_limit_reached=any(solved[k].cut_short for k in wanted),
        )

        def comparisons(winner: Route) -> tuple[ClassComparison, ...]:
            if len(routes) == 1:
                return ()
            return tuple(
                ClassComparison(
                    homotopy=r.homotopy,
                    way_round=r.way_round,
                    lower_bound=bounds[k],
                    makespan=solved[k].makespan if k in solved else None,
                    chosen=r is winner,
                    failure=solved[k].failure if k in solved else None,
                    label=None if r.graph.cycle is not None else class_name(r),
                )
                for k, r in enumerate(routes)
            )

        unsolved_notes = tuple(
            f"class {class_label(routes[k])} not solved ({solved[k].failure.value}): {solved[k].detail}"
            for k in wanted
            if solved[k].failure is not None
        ) + tuple(
            f"class {class_label(routes[k])}: the time limit "
            f"({self.time_limit:g} s, a safety stop) ended its refinement after pass {len(solved[k].passes)}"
            for k in wanted
            if solved[k].cut_short and solved[k].passes
        )
        # each candidate carries the whole call's diagnostics before it is verified: the object
        # verified is the object returned (a schedule is verified once)
        chosen, failures = self._fastest_verified(
            solved,
            fastest_exact.duration,
            lambda candidate: dataclasses.replace(
                candidate,
                notes=candidate.notes + unsolved_notes,
                info=dataclasses.replace(
                    info, classes=comparisons(candidate.route), solved_by=candidate.info.solved_by
                ),
            ),
        )
        if chosen is not None:
            return chosen
        unsolved = [solved[k] for k in wanted if not solved[k].passes]
        if wanted and (failures or len(unsolved) == len(wanted)):
            # no solution verified, or no class was solved: the route's own exact schedule, flagged
            info = dataclasses.replace(info, source=Source.EXACT, classes=comparisons(route))
            if failures:
                return _fallback(exact, FallbackReason.VERIFICATION_FAILED, "; ".join(failures), info)
            late = any(c.failure is FallbackReason.TIME_LIMIT for c in unsolved)
            reason = FallbackReason.TIME_LIMIT if late else unsolved[0].failure
            return _fallback(exact, reason, "; ".join(c.detail for c in unsolved), info)
        # The NLP's grid can only approach an S-curve from above; where an exact schedule is already
        # optimal in its class (e.g. the vehicles never interact) it is faster. Both are members of
        # their class: return the faster, and say so.
        best = min((c.makespan for c in solved.values() if c.passes), default=math.inf)
        note = (
            f"the exact schedule ({fastest_exact.duration:.3f} s) is at least as fast as "
            + ("every class's lower bound" if not wanted else f"the discretized optimum ({best:.3f} s)")
            + "; returned it"
        )
        logger.info("optimal: %s", note)
        info = dataclasses.replace(info, source=Source.EXACT, classes=comparisons(fastest_exact.route))
        return self._as_optimal(fastest_exact, note, info)

    def _fastest_verified(
        self,
        solved: dict[int, ClassSolve],
        exact_duration: float,
        finish: Callable[[Schedule], Schedule],
    ) -> tuple[Schedule | None, list[str]]:
        """The fastest solution of any class that verifies and beats ``exact_duration``, and the failures.

        ``finish`` gives a candidate its final form (diagnostics) before it is verified.
        """
        failures: list[str] = []
        # the route's own class (k = 0) wins a tie within round-off: symmetric classes solve alike
        ranked = sorted(
            ((makespan, k, p) for k, c in solved.items() for p, (makespan, _, _) in enumerate(c.passes)),
            key=lambda item: (item[0] * (1.0 + _TIE if item[1] else 1.0), item[1]),
        )
        for makespan, k, p in ranked:
            if makespan >= exact_duration:
                break
            try:
                candidate = finish(solved[k].schedule(self, p, segments=self.segments, nodes=self.nodes))
            except InputError as error:  # numbers no schedule can hold (e.g. not finite): not a result
                failures.append(f"class {k} pass {p + 1} does not form a schedule: {error}")
                continue
            report = verify(candidate)
            if report.passed:
                return candidate, failures
            failures += report.failures
        return None, failures

    def _as_optimal(self, exact: Schedule, note: str, info: OptimalInfo | None) -> Schedule:
        """The exact schedule, returned by this method because it is the fastest known."""
        return dataclasses.replace(exact, method=self, notes=(note,), info=info)


#: Why a fallback happened, in a few words for the warning (the note lists every solver attempt).
_FALLBACK_WHY = {
    FallbackReason.SOLVER_FAILED: "no solver converged (fatrop, then Ipopt)",
    FallbackReason.TIME_LIMIT: "a solver did not come back within the time limit (a safety stop)",
    FallbackReason.SETUP_FAILED: "the problem could not be set up",
}


def _fallback(exact: Schedule, reason: FallbackReason, detail: str, info: OptimalInfo) -> Schedule:
    # the reason in a few words, not every attempt again: the schedule's note, printed with the
    # summary, lists them; a verification failure is named (its first line, shortened)
    why = _FALLBACK_WHY.get(reason) or (detail if len(detail) <= 200 else detail[:197] + "...")
    logger.warning("optimal: fell back to the exact schedule (%s): %s", reason.value, why)
    logger.debug("optimal fallback: %s", detail)
    return dataclasses.replace(
        exact, notes=(f"fallback to exact ({reason.value}): {detail}",), fallback_reason=reason, info=info
    )
