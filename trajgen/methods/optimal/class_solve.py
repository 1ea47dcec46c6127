"""Solving one homotopy class of the ``optimal`` method: the first grid, then mesh refinement.

:class:`~trajgen.methods.optimal.method.Optimal` decides which classes to solve and which verified
solution to return; this module solves one: its NLP's parameters (:func:`problem_parameters`), the
first grid from the exact schedule, and refinement passes until they converge, the class is beaten
(:class:`~trajgen.methods.optimal.classes.ClassRace`) or the time limit (a safety stop) is reached.
Each pass is kept unverified; the method verifies what it returns.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from limits import Limits
from topology import Route
from trajgen.errors import SolverError
from trajgen.methods.exact import Exact
from trajgen.methods.optimal.braking_constraints import BRAKING_CURVATURE, BRAKING_MARGIN
from trajgen.methods.optimal.classes import ClassRace, ClassSolve
from trajgen.methods.optimal.compiled import NlpOrigin
from trajgen.methods.optimal.decode import unpack
from trajgen.methods.optimal.guess import assemble, initial_guess
from trajgen.methods.optimal.mesh import refine
from trajgen.methods.optimal.phases import NlpShape, default_fractions, route_phases
from trajgen.methods.optimal.solve import solve
from trajgen.methods.optimal.transcription import ParameterLayout
from trajgen.methods.optimal.units import ProblemUnits
from trajgen.model.schedule import FallbackReason, Schedule, TimingMethod

__all__ = ["problem_parameters", "solve_class"]

logger = logging.getLogger(__name__)

#: Smallest separation used when the scenario asks for 0 ("not the same point"), metres.
_POSITIVE_SEPARATION = 1e-3
#: Planned clearance above the minimum separation, metres: the solvers meet constraints to ~1e-8 m,
#: the verifier demands the minimum to 1e-9 m.
_SEPARATION_MARGIN = 1e-6
#: Where the separation (nearly) fills the shortest leg, the waiting vehicle parks at a leg's very end
#: while the other passes (no strict interior): the margin shrinks to this and the legs are planned
#: this much longer (the verifier allows 1e-6 m past a leg's end), so a thin interior exists.
_TIGHT_MARGIN = 2e-7
_LEG_SLACK = 5e-7
#: Most that refinement can still gain after the first grid, as a share of its makespan: a class
#: whose first grid is slower than another class's by more is not refined (the largest total gain
#: measured is 1.8 %, 200/120/80 m at 24 nodes). After a pass, see ``_REMAINING_FACTOR``.
_FIRST_GRID_GAIN = 0.05
#: Within this share of its class lower bound a solution is near a single vehicle's own S-curve,
#: where refinement converges slowly (linearly): there it stops only below a 15x stricter gain.
_NEAR_BOUND = 0.01
_NEAR_BOUND_STRICTER = 15.0
#: After a refinement pass, what the class may still gain is taken as this many times the pass's gain.
_REMAINING_FACTOR = 4.0


def solve_class(
    method: TimingMethod,
    route: Route,
    limits: Limits,
    exact: Schedule,
    shape: NlpShape,
    *,
    slot: int,
    deadline: float,
    race: ClassRace,
    bound: float,
) -> ClassSolve:
    """Solve ``route``'s own class: the first grid, then refinement passes (unverified).

    ``shape``: the NLP to solve it on (its copy, see
    :func:`~trajgen.methods.optimal.method.class_copies`); ``slot``: this class's
    place in ``race``, through which a class that another beats by more than its refinement
    could still gain stops refining; ``bound`` its lower bound, seconds. The problem is solved
    in the units of :meth:`~.units.ProblemUnits.of` (its bound).
    """
    began = time.perf_counter()
    phases = route_phases(route)
    outcome = ClassSolve(route, limits, phases, shape, built=False)
    units = ProblemUnits.of(bound)
    try:
        preparing = time.perf_counter()
        compiled, prepared = method.solver_cache().get(shape)
        if prepared:  # the time limit is the solvers': a one-time build or load does not count
            outcome.origin = compiled.origin
            outcome.built = compiled.origin is NlpOrigin.BUILT
            deadline += time.perf_counter() - preparing
        _first_pass(method, outcome, compiled, exact, deadline, units)
    except Exception as error:  # a bug or a build failure must not lose the other class's result
        logger.exception("optimal: class %d could not be set up", slot)
        return outcome.failed(FallbackReason.SETUP_FAILED, f"{type(error).__name__}: {error}")
    finally:
        race.first_pass(slot, outcome.makespan, deadline)
    if outcome.passes:
        try:
            _refine(
                method, outcome, compiled, slot=slot, deadline=deadline, race=race, bound=bound, units=units
            )
        except Exception:  # keep the passes solved so far: each is verified before it is returned
            logger.exception("optimal: refinement of class %d raised; keeping its earlier passes", slot)
    logger.debug("optimal: class %d solved in %.3f s", slot, time.perf_counter() - began)
    return outcome


def _refine(
    method: TimingMethod,
    outcome: ClassSolve,
    compiled,
    *,
    slot: int,
    deadline: float,
    race: ClassRace,
    bound: float,
    units: ProblemUnits,
) -> None:
    """Mesh-refinement passes of one class until they converge or it is beaten.

    Deterministic: the passes depend on the solutions and the options only. The time limit
    (``deadline``) is a safety stop; a class it stops is marked ``cut_short``.
    """
    route, limits, phases, shape = outcome.route, outcome.limits, outcome.phases, outcome.shape
    jerks = tuple(v.max_jerk for v in limits.vehicles)
    remaining = _FIRST_GRID_GAIN
    while outcome.refinements < method.refinements:
        current = outcome.passes[-1][0]
        if race.beaten(slot, current, remaining):
            logger.debug("optimal: class %d not refined: another is faster by > %.3g", slot, remaining)
            return
        if time.perf_counter() > deadline:
            logger.warning(
                "optimal: the time limit (%g s, a safety stop) ended class %d's refinement",
                method.time_limit,
                slot,
            )
            outcome.cut_short = True
            return
        fractions, states = refine(outcome.passes[-1][1], shape, jerks)
        try:
            guess = assemble(states, shape, compiled.size)
        except SolverError:
            return
        parameters = problem_parameters(route, limits, phases, fractions)
        result = solve(
            compiled, guess, parameters, units=units, deadline=deadline, ipopt_wall_time=method.time_limit
        )
        outcome.attempts += result.attempts
        if result.solution is None:
            outcome.cut_short = time.perf_counter() > deadline
            return
        outcome.add(unpack(result.solution, phases, shape, fractions), result.attempts[-1])
        gain = (current - outcome.passes[-1][0]) / current
        logger.debug("optimal: refinement pass %d: %.6f s, gain %.3g", outcome.refinements, current, gain)
        near = outcome.passes[-1][0] - bound < _NEAR_BOUND * outcome.passes[-1][0]
        if gain < method.refinement_tolerance / (_NEAR_BOUND_STRICTER if near else 1.0):
            return  # converged: a further pass would gain a fraction of this one
        # what is left: a few times the last gain where convergence is slow, at most the first bound
        remaining = min(_FIRST_GRID_GAIN, _REMAINING_FACTOR * max(gain, 0.0))


def _first_pass(
    method: TimingMethod, outcome: ClassSolve, compiled, exact: Schedule, deadline: float, units: ProblemUnits
) -> None:
    """Solve ``outcome``'s class on the first grid, from the exact schedule; records a failure."""
    route, limits, phases, shape = outcome.route, outcome.limits, outcome.phases, outcome.shape
    try:
        fractions = default_fractions(shape)
        waypoint_times = Exact().waypoint_times(exact)
        guess = initial_guess(exact, waypoint_times, phases, shape, compiled.size, fractions)
        parameters = problem_parameters(route, limits, phases, fractions)
    except Exception as error:  # a malformed guess is a bug, but must not leak an unverified schedule
        outcome.failed(FallbackReason.SETUP_FAILED, f"{type(error).__name__}: {error}")
        return
    result = solve(
        compiled, guess, parameters, units=units, deadline=deadline, ipopt_wall_time=method.time_limit
    )
    outcome.attempts += result.attempts
    if result.solution is None:
        late = time.perf_counter() > deadline
        reason = FallbackReason.TIME_LIMIT if late else FallbackReason.SOLVER_FAILED
        outcome.failed(reason, "; ".join(str(a) for a in result.attempts))
        return
    outcome.add(unpack(result.solution, phases, shape, fractions), result.attempts[-1])


def problem_parameters(route: Route, limits: Limits, phases, fractions: np.ndarray) -> np.ndarray:
    """The NLP's parameter vector of ``route``'s class under ``limits`` on the grid ``fractions``, SI units.

    The layout is :class:`~.transcription.ParameterLayout`'s; the separation is planned a hair
    clear of the minimum (:data:`_SEPARATION_MARGIN`), and where it (nearly) fills the shortest leg
    the legs are planned a hair longer (:data:`_LEG_SLACK`).
    """
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
        emergency=[v.emergency_braking for v in vehicles],
        separation=separation,
        braking=[BRAKING_MARGIN, BRAKING_CURVATURE],
        start=[p.s for p in route.start],
        goal=[p.s for p in route.goal],
        fractions=fractions.ravel(),
    )
