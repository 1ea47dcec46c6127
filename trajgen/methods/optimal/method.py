"""The ``optimal`` method object: options, the pipeline from route to verified schedule, diagnostics."""

from __future__ import annotations

import concurrent.futures
import dataclasses
import enum
import logging
import math
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import Homotopy, Option, Route, WayRound, plan
from trajgen.analysis import class_lower_bound
from trajgen.errors import InputError, SolverError
from trajgen.methods.exact import Exact
from trajgen.methods.optimal.decode import sections, unpack
from trajgen.methods.optimal.guess import assemble, initial_guess
from trajgen.methods.optimal.mesh import refine, switch_spread
from trajgen.methods.optimal.phases import NlpShape, default_fractions, route_phases
from trajgen.methods.optimal.solve import Outcome, Solver, SolverAttempt, SolverCache, solve
from trajgen.methods.optimal.transcription import ParameterLayout
from trajgen.schedule import FallbackReason, MethodInfo, Schedule, TimingMethod, check_request
from trajgen.verify import verify

__all__ = ["DEFAULT_NODES", "ClassComparison", "HomotopyChoice", "Optimal", "OptimalInfo", "Source"]

logger = logging.getLogger(__name__)

#: Intervals per segment. 32: doubling it changes the benchmark makespans by at most 0.34 % (24 gave 0.55 %).
DEFAULT_NODES = 32
#: Smallest separation used when the scenario asks for 0 ("not the same point"), metres.
_POSITIVE_SEPARATION = 1e-3
#: Planned clearance above the minimum separation, metres: the solvers meet constraints to ~1e-8 m,
#: the verifier demands the minimum to 1e-9 m.
_SEPARATION_MARGIN = 1e-6
#: Where the separation (nearly) fills the shortest leg, the waiting vehicle must park at the very end
#: of a leg while the other passes the junction: no strict interior, and with the full margin no
#: solution. There the margin shrinks to this and the legs are planned this much longer (the verifier
#: allows 1e-6 m past a leg's end), so a thin interior exists.
_TIGHT_MARGIN = 2e-7
_LEG_SLACK = 5e-7
#: Mesh refinement stops once the intervals next to every jerk switch are at most this many of the
#: shortest jerk ramps long (a switch is then placed to within a fraction of a ramp) ...
_FINE_ENOUGH = 0.5
#: ... or once a pass shortens the makespan by less than this share.
_REFINEMENT_GAIN = 2e-4


class Source(enum.Enum):
    """Where the motion of an ``optimal`` schedule comes from."""

    NLP = "nlp"  #: the solver's solution
    EXACT = "exact"  #: the exact schedule, faster than the discretized optimum (or a fallback)


class HomotopyChoice(Option):
    """Which homotopy classes ``optimal`` solves."""

    FASTEST = "fastest"  #: the route's class and the other way round; the faster wins
    PAPER = "paper"  #: the route's class only (the paper's instruction, for a route from ``plan``)


@dataclass(frozen=True, slots=True)
class ClassComparison:
    """One homotopy class considered by ``optimal`` with ``homotopy="fastest"``.

    Attributes
    ----------
    homotopy : Homotopy
        Whether it is the paper's class or the other way round.
    way_round : WayRound
        Its direction round the boundary circle.
    lower_bound : float
        :func:`~trajgen.analysis.class_lower_bound`, seconds.
    makespan : float or None
        Its verified makespan, seconds; ``None`` when skipped (the lower bound
        could not beat the faster ``exact`` schedule).
    chosen : bool
        Whether the returned schedule is in this class.
    """

    homotopy: Homotopy
    way_round: WayRound
    lower_bound: float
    makespan: float | None
    chosen: bool

    def summary(self) -> dict:
        """JSON-ready fields."""
        return {
            "homotopy": self.homotopy.value,
            "way_round": self.way_round.value,
            "lower_bound_s": self.lower_bound,
            "makespan_s": self.makespan,
            "chosen": self.chosen,
        }


@dataclass(frozen=True, slots=True)
class OptimalInfo(MethodInfo):
    """Diagnostics of one ``optimal`` solve.

    Attributes
    ----------
    solve_time : float
        Wall time of the NLP solve (and the build, if it was built), seconds.
    built : bool
        Whether the NLP had to be built (first query of its shape in the cache).
    attempts : tuple of SolverAttempt
        Every solver tried, in order.
    source : Source
        Whether the schedule's motion is the solver's or the exact schedule's.
    refinements : int
        Mesh-refinement passes solved after the first (see :mod:`~.mesh`).
    classes : tuple of ClassComparison
        The homotopy classes considered (empty when only the route's own was).
    """

    solve_time: float
    built: bool
    attempts: tuple[SolverAttempt, ...] = ()
    source: Source = Source.NLP
    refinements: int = 0
    classes: tuple[ClassComparison, ...] = ()

    @property
    def solver(self) -> Solver | None:
        """The solver that converged, if any."""
        if self.attempts and self.attempts[-1].outcome is Outcome.SOLVED:
            return self.attempts[-1].solver
        return None

    @property
    def iterations(self) -> int:
        """Iterations of the solver that converged (-1 if none did)."""
        return self.attempts[-1].iterations if self.solver is not None else -1

    @property
    def status(self) -> str:
        """What each solver tried reported, for people."""
        return "; ".join(str(attempt) for attempt in self.attempts)

    def summary(self) -> dict:
        """JSON-ready diagnostics."""
        return {
            "solve_time_s": self.solve_time,
            "built": self.built,
            "solver": None if self.solver is None else self.solver.value,
            "iterations": self.iterations,
            "status": self.status,
            "source": self.source.value,
            "refinements": self.refinements,
            "classes": [c.summary() for c in self.classes],
        }


def _positive_int(value: object, name: str, minimum: int = 1) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(f"optimal option {name} must be an integer >= {minimum}, got {value!r}")


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
        Iteration limit of Ipopt (and of fatrop, with ``fatrop_iterations``).
    fatrop_iterations : int, optional
        Iteration limit of fatrop (default 500; it converges in < 150 when it converges).
    time_budget : float, optional
        Seconds the solvers may take (default 2.0): no solver starts after it is spent and Ipopt
        stops by itself; the verified ``exact`` schedule is returned then, flagged ``time-budget``.
    refinements : int, optional
        Most mesh-refinement passes (default 3): the grid's nodes move to the jerk switches of the
        previous pass and the same NLP is solved again, until the intervals around every switch
        are shorter than half the shortest jerk ramp or a pass gains less than 0.02 %.
    homotopy : HomotopyChoice or str, optional
        ``"fastest"`` (default): solve the route's class and the other way round the boundary
        circle, return the faster. ``"paper"``: the route's class only.
    cache : SolverCache or None, optional
        Where compiled NLPs are kept; ``None`` (default) uses the process-wide
        :meth:`shared_cache`.
    """

    name: ClassVar[str] = "optimal"
    summary: ClassVar[str] = (
        "time-optimal jerk-limited schedule, faster of the two shortest homotopy classes (CasADi)"
    )
    _shared: ClassVar[SolverCache] = SolverCache(maxsize=32)

    nodes: int = DEFAULT_NODES
    segments: int = 1
    max_iterations: int = 3000
    fatrop_iterations: int = 500
    time_budget: float = 2.0
    refinements: int = 3
    homotopy: HomotopyChoice = HomotopyChoice.FASTEST
    cache: SolverCache | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        _positive_int(self.nodes, "nodes")
        _positive_int(self.segments, "segments")
        _positive_int(self.max_iterations, "max_iterations")
        _positive_int(self.fatrop_iterations, "fatrop_iterations")
        _positive_int(self.refinements, "refinements", minimum=0)
        object.__setattr__(self, "homotopy", HomotopyChoice.lookup(self.homotopy))
        budget = self.time_budget
        if isinstance(budget, bool) or not isinstance(budget, (int, float)) or not 0.0 < budget < math.inf:
            raise InputError(
                f"optimal option time_budget must be a finite number of seconds > 0, got {budget!r}"
            )
        if self.cache is not None and not isinstance(self.cache, SolverCache):
            raise InputError(
                f"optimal option cache must be a SolverCache or None, got {type(self.cache).__name__}"
            )

    @classmethod
    def shared_cache(cls) -> SolverCache:
        """The process-wide solver cache used when no ``cache`` is given (32 shapes at most)."""
        return cls._shared

    @property
    def jerk_limited(self) -> bool:
        """Always True."""
        return True

    def _cache(self) -> SolverCache:
        return self.cache if self.cache is not None else Optimal.shared_cache()

    def shape(self, route: Route) -> NlpShape:
        """The NLP shape of ``route`` with these options (the cache key)."""
        return NlpShape.of(
            route_phases(route),
            nodes=self.nodes,
            segments=self.segments,
            max_iterations=self.max_iterations,
            fatrop_iterations=self.fatrop_iterations,
            time_budget=float(self.time_budget),
        )

    def warm_up(self, route: Route) -> bool:
        """Build the NLP of ``route``'s shape into the cache now; returns whether it was built."""
        if len(route.waypoints) == 1:
            return False
        return self._cache().get(self.shape(route))[1]

    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """The optimal schedule from ``route``'s start to its goal (verified), or the flagged ``exact`` one.

        With ``homotopy="fastest"`` the route's class and the other way round
        the boundary circle are both considered: a class whose lower bound
        (:func:`~trajgen.analysis.class_lower_bound`) cannot beat the faster
        of the two ``exact`` schedules is skipped, the others are solved
        concurrently, and the faster verified schedule is returned (the
        route's own class on a tie). Its ``route`` is the class's route.
        """
        check_request(route, limits)
        exact = Exact().schedule(route, limits)
        if len(route.waypoints) == 1:  # nothing moves: the exact schedule is optimal
            return self._as_optimal(exact, "start is the goal: nothing moves", None)
        if self.homotopy is HomotopyChoice.PAPER or route.arc_length == 0.0:
            return self._optimize(route, limits, exact, slot=0)
        began = time.perf_counter()
        other_homotopy = Homotopy.OTHER if route.homotopy is Homotopy.PAPER else Homotopy.PAPER
        other = plan(
            route.graph, route.start, route.goal, min_separation=route.min_separation, homotopy=other_homotopy
        )
        exacts = (exact, Exact().schedule(other, limits))
        incumbent = min(e.duration for e in exacts)
        bounds = tuple(class_lower_bound(r, limits) for r in (route, other))
        chosen = [k for k in range(2) if bounds[k] < incumbent or exacts[k].duration == incumbent]
        if len(chosen) == 1:
            results = {
                chosen[0]: self._optimize((route, other)[chosen[0]], limits, exacts[chosen[0]], slot=0)
            }
        else:
            with concurrent.futures.ThreadPoolExecutor(
                max_workers=2, thread_name_prefix="trajgen-class"
            ) as pool:
                futures = {
                    k: pool.submit(self._optimize, (route, other)[k], limits, exacts[k], slot=k)
                    for k in chosen
                }
                results = {k: future.result() for k, future in futures.items()}
        best = min(results, key=lambda k: (results[k].duration, k))
        comparisons = tuple(
            ClassComparison(
                homotopy=r.homotopy,
                way_round=r.way_round,
                lower_bound=bounds[k],
                makespan=results[k].duration if k in results else None,
                chosen=k == best,
            )
            for k, r in enumerate((route, other))
        )
        winner = results[best]
        info = (
            winner.info
            if isinstance(winner.info, OptimalInfo)
            else OptimalInfo(0.0, False, source=Source.EXACT)
        )
        info = dataclasses.replace(info, solve_time=time.perf_counter() - began, classes=comparisons)
        return dataclasses.replace(winner, info=info)

    def _optimize(self, route: Route, limits: Limits, exact: Schedule, *, slot: int) -> Schedule:
        """The optimal schedule in ``route``'s own class (``slot``: which compiled copy of the NLP to use)."""
        exact_method = Exact()
        began = time.perf_counter()
        phases = route_phases(route)
        shape = dataclasses.replace(self.shape(route), slot=slot)
        compiled, built = self._cache().get(shape)
        deadline = began + self.time_budget
        size = compiled.transcription.size
        try:
            fractions = default_fractions(shape)
            guess = initial_guess(exact, exact_method.waypoint_times(exact), phases, shape, size, fractions)
            parameters = _parameters(route, limits, phases, fractions)
        except Exception as error:  # a malformed guess is a bug, but must not leak an unverified schedule
            info = OptimalInfo(time.perf_counter() - began, built, source=Source.EXACT)
            return _fallback(exact, FallbackReason.SETUP_FAILED, f"{type(error).__name__}: {error}", info)
        result = solve(compiled, guess, parameters, deadline=deadline)
        attempts = list(result.attempts)
        if result.solution is None:
            info = OptimalInfo(time.perf_counter() - began, built, tuple(attempts), source=Source.EXACT)
            detail = "; ".join(str(a) for a in attempts)
            late = time.perf_counter() - began > self.time_budget
            reason = FallbackReason.TIME_BUDGET if late else FallbackReason.SOLVER_FAILED
            return _fallback(exact, reason, detail, info)
        passes = [(unpack(result.solution, phases, shape, fractions), result.attempts[-1])]
        jerks = tuple(v.max_jerk for v in limits.vehicles)
        ramp = min(v.max_acceleration / v.max_jerk for v in limits.vehicles)
        while (
            len(passes) <= self.refinements
            and switch_spread(passes[-1][0], ramp) > _FINE_ENOUGH
            and time.perf_counter() < deadline
        ):
            fractions, states = refine(passes[-1][0], shape, jerks)
            try:
                guess = assemble(states, shape, size)
            except SolverError:
                break
            result = solve(compiled, guess, _parameters(route, limits, phases, fractions), deadline=deadline)
            attempts += result.attempts
            if result.solution is None:
                break
            refined = unpack(result.solution, phases, shape, fractions)
            previous = _makespan(passes[-1][0])
            passes.append((refined, result.attempts[-1]))
            if _makespan(refined) > previous * (1.0 - _REFINEMENT_GAIN):
                break  # converged (or no better): stop refining
        info = OptimalInfo(time.perf_counter() - began, built, tuple(attempts), refinements=len(passes) - 1)
        grid = f"{len(phases)} phase(s) x {self.segments} segments x {self.nodes} intervals"
        # the fastest pass that verifies (a later pass is normally the faster)
        failures: list[str] = []
        schedule = None
        for solved, attempt in sorted(passes, key=lambda item: _makespan(item[0])):
            note = f"{grid}, {len(passes) - 1} refinement(s); {attempt}"
            candidate = Schedule(
                route,
                limits,
                self,
                sections(route, limits, phases, solved),
                jerk_limited=True,
                notes=(note,),
                info=info,
            )
            report = verify(candidate)
            if report.passed:
                schedule = candidate
                break
            failures += report.failures
        if schedule is None:
            return _fallback(
                exact,
                FallbackReason.VERIFICATION_FAILED,
                "; ".join(failures),
                dataclasses.replace(info, source=Source.EXACT),
            )
        if schedule.duration > exact.duration:
            # The NLP's grid can only approach an S-curve from above; where the exact schedule is
            # already optimal in the class (e.g. the vehicles never interact) it is faster. Both
            # are verified members of the class: return the faster, and say so.
            note = (
                f"the exact schedule ({exact.duration:.3f} s) is faster than the discretized optimum "
                f"({schedule.duration:.3f} s); returned it"
            )
            logger.info("optimal: %s", note)
            return self._as_optimal(exact, note, dataclasses.replace(info, source=Source.EXACT))
        return schedule

    def _as_optimal(self, exact: Schedule, note: str, info: OptimalInfo | None) -> Schedule:
        """The exact schedule, returned by this method because it is the fastest known."""
        return dataclasses.replace(exact, method=self, notes=(note,), info=info)


def _makespan(solution) -> float:
    """Duration of a decoded solution, seconds."""
    return float(sum(phase.times[-1] for phase in solution))


def _parameters(route: Route, limits: Limits, phases, fractions: np.ndarray) -> np.ndarray:
    graph = route.graph
    required = max(limits.min_separation, route.min_separation)
    separation = max(required, _POSITIVE_SEPARATION) + _SEPARATION_MARGIN
    slack = 0.0
    if separation > graph.shortest_leg - _SEPARATION_MARGIN:  # degenerate: see _TIGHT_MARGIN
        separation = max(required, min(_POSITIVE_SEPARATION, 0.5 * graph.shortest_leg)) + _TIGHT_MARGIN
        slack = _LEG_SLACK
    lengths = [
        graph.lengths[leg] + slack if not phase.parked(v) else 0.0
        for phase in phases
        for v, leg in enumerate(phase.legs)
    ]
    vehicles = limits.vehicles
    return ParameterLayout(*fractions.shape).pack(
        lengths=lengths,
        max_velocity=[v.max_velocity for v in vehicles],
        max_acceleration=[v.max_acceleration for v in vehicles],
        max_jerk=[v.max_jerk for v in vehicles],
        separation=separation,
        start=[p.s for p in route.start],
        goal=[p.s for p in route.goal],
        fractions=fractions.ravel(),
    )


def _fallback(exact: Schedule, reason: FallbackReason, detail: str, info: OptimalInfo) -> Schedule:
    logger.warning("optimal schedule fell back to exact (%s): %s", reason.value, detail)
    return dataclasses.replace(
        exact, notes=(f"fallback to exact ({reason.value}): {detail}",), fallback_reason=reason, info=info
    )
