"""The ``optimal`` method: time-optimal jerk-limited schedules inside the route's homotopy class.

Formulation (ALGORITHM.md section 6). The route's reduced region sequence
``R_1 ... R_P`` fixes the homotopy class. Phase ``p`` keeps the vehicles in
region ``R_p``: each vehicle on a fixed leg, tracked by its distance ``s``
from the junction, with state ``(s, v = ds/dt, a)`` and jerk as control,
piecewise constant on ``N`` intervals (fixed fractions of ``T_p``, denser
near the phase ends, :func:`_grid_fractions`); the phase
durations ``T_p`` are free and their sum is minimized. Between phases one
vehicle changes leg: it is at the junction (``s = 0``) and its ``v`` and
``a`` change sign (it leaves one leg and enters another, moving on
smoothly). Inside a region the separation is linear in ``(s1, s2)``.

Constraints hold between nodes, not only at them: the dynamics are
integrated exactly, and the velocity (quadratic) and position (cubic) on each
interval are bounded through their Bernstein coefficients, whose convex hull
contains the polynomial. So ``|v| <= v_max``, ``0 <= s <= L`` and the
separation hold for all time; ``|a|`` (linear) and ``|j|`` (constant) hold
exactly. Every result is still checked by the independent verifier at 1 ms.

The NLP is built with CasADi (SX, ``nlpsol``) once per *shape* of the region
sequence (phase count, which vehicle changes leg at each switch, shared-leg
order, nodes) and reused with parameters (leg lengths, limits, separation,
start, goal) for every later query of that shape; each kind of control
interval is one small CasADi function, inlined into every NLP. It is laid out
stage by stage so that fatrop, the structure-exploiting interior-point solver
shipped with CasADi, solves it (about 3x faster per iteration than Ipopt with
MUMPS here). No inequality is tied to an equality: bounds on a position that
an equality pins (start, goal, junction crossing) are dropped, and so are the
between-node bounds of the first and last interval, which the rest conditions
make redundant; otherwise the solvers would have no strict interior and crawl.
If fatrop stalls short of its tolerance, Ipopt warm-started from fatrop's
last iterate and multipliers polishes it; Ipopt from the initial guess is the
last resort. The initial guess is the ``exact`` schedule. If the solvers fail
or the result fails verification, the ``exact`` schedule is returned, flagged
as a fallback with the reason, and the event is logged.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import time
from dataclasses import dataclass

import numpy as np

from limits import Limits
from topology import Route
from topology.arrays import region_keys
from topology.errors import InputError, SolverError
from topology.route import reduce_regions_indexed
from trajgen.profiles import PiecewiseCubic, rest_to_rest_time
from trajgen.schedule import (
    AxisMap,
    CubicKinematics,
    Method,
    Schedule,
    Section,
    exact_schedule,
)

__all__ = ["DEFAULT_NODES", "DEFAULT_SEGMENTS", "OptimalInfo", "lower_bound", "optimal_schedule"]

logger = logging.getLogger(__name__)

#: Intervals per segment (each phase has DEFAULT_SEGMENTS segments of free duration). 32: doubling
#: it changes the benchmark makespans by at most 0.34 % (24 gave 0.55 %).
DEFAULT_NODES = 32
#: Smallest separation used when the scenario asks for 0 ("not the same point"), metres.
_POSITIVE_SEPARATION = 1e-3
#: Weight of the jerk regularization relative to the makespan (keeps the solver away from chattering).
_JERK_WEIGHT = 1e-4
_MIN_PHASE = 1e-3
_MIN_SEGMENT = 1e-4
#: Segments of free duration per phase.
DEFAULT_SEGMENTS = 1
#: Weight of cosine (end-dense) spacing in the grid, 0 for uniform.
_END_DENSITY = 0.35
_SEPARATION_MARGIN = 1e-6
#: fatrop converges in < 150 iterations when it converges; past this the Ipopt backup takes over.
_FATROP_MAX_ITER = 500

_SOLVERS: dict[tuple, dict] = {}
#: Solvers tried in turn. fatrop exploits the stage structure (fast). Where it stalls short of its
#: tolerance (it can, where a vehicle creeps up to the end of its leg), Ipopt warm-started from
#: fatrop's last iterate and multipliers polishes it in about 10 iterations; Ipopt from the initial
#: guess is the last resort.
_SOLVER_ORDER = ("fatrop", "ipopt-polish", "ipopt")
#: Iteration limit of the warm-started polish: it converges in < 20 when it is near a solution.
_POLISH_MAX_ITER = 60


@dataclass(frozen=True, slots=True)
class _Phase:
    legs: tuple[int, int]  # leg index of each vehicle (-1 for a vehicle pinned at the junction)
    nearer: int  # 0: different legs; 1 or 2: vehicle nearer the junction on a shared leg
    switching: int  # vehicle (0 or 1) that changes leg at the end of the phase; -1 for the last


@dataclass(frozen=True, slots=True)
class OptimalInfo:
    """Diagnostics of one ``optimal`` solve.

    Attributes
    ----------
    solve_time : float
        Wall time of the NLP solve (and the build, if it was built), seconds.
    built : bool
        Whether the NLP had to be built (first query of its shape).
    iterations : int
        Iterations of the solver that succeeded (-1 if none did).
    status : str
        What each solver tried (fatrop first, then Ipopt) reported.
    solver : str
        The solver that succeeded: ``"fatrop"``, ``"ipopt-polish"`` (Ipopt
        warm-started from fatrop's last iterate), ``"ipopt"``; ``""`` if none did.
    source : str
        ``"nlp"`` when the schedule is the solver's; ``"exact"`` when the exact
        schedule was faster than the discretized optimum and was returned.
    """

    solve_time: float
    built: bool
    iterations: int
    status: str
    solver: str = ""
    source: str = "nlp"


def lower_bound(route: Route, limits: Limits) -> float:
    """The larger of the vehicles' own jerk-limited rest-to-rest times over their shortest paths, s.

    Ignores the other vehicle entirely, so no schedule can be faster.
    """
    graph = route.graph
    times = []
    for vehicle, (start, goal) in enumerate(zip(route.start, route.goal, strict=True)):
        vehicle_limits = limits.vehicles[vehicle]
        times.append(
            rest_to_rest_time(
                graph.distance(start, goal),
                vehicle_limits.max_velocity,
                vehicle_limits.max_acceleration,
                vehicle_limits.max_jerk,
            )
        )
    return max(times)


def _phases(route: Route) -> list[_Phase]:
    graph = route.graph
    regions = [(graph.index(r.first_leg), graph.index(r.second_leg), r.nearer or 0) for r in route.regions]
    if not regions:  # the whole route lies on one ray: one vehicle parked at the junction
        start = route._tuples[0]
        parked = 0 if start[0] == -1 else 1
        moving_leg = start[2 * (1 - parked)]
        legs = (-1, moving_leg) if parked == 0 else (moving_leg, -1)
        return [_Phase(legs, 0, -1)]
    phases = []
    for k, (leg1, leg2, nearer) in enumerate(regions):
        # the vehicle whose leg differs in the next region changes leg at the end of this phase
        following = regions[k + 1] if k + 1 < len(regions) else None
        switching = -1 if following is None else (0 if following[0] != leg1 else 1)
        phases.append(_Phase((leg1, leg2), nearer, switching))
    return phases


def _shape(phases: list[_Phase], nodes: int, segments: int, max_iterations: int) -> tuple:
    return (
        nodes,
        segments,
        max_iterations,
        tuple((p.legs[0] == -1, p.legs[1] == -1, p.nearer, p.switching) for p in phases),
    )


def _bernstein_cubic(s, v, a, h):
    """Inner Bernstein coefficients of s(t) on [0, h] (the outer ones are the node values)."""
    return s + h * v / 3.0, s + 2.0 * h * v / 3.0 + h * h * a / 6.0


_STATE = 7  # s1, v1, a1, s2, v2, a2, T (the phase duration, carried as a state)


def _grid_fractions(nodes: int) -> np.ndarray:
    """Interval lengths of a segment as fractions of its duration, shape (nodes,), summing to 1.

    A fixed blend of uniform and cosine spacing: denser at the ends, where the
    vehicles start, stop and pass the junction, so the short jerk ramps there
    are resolved without making the grid itself a variable.
    """
    i = np.arange(nodes + 1) / nodes
    grid = (1.0 - _END_DENSITY) * i + _END_DENSITY * 0.5 * (1.0 - np.cos(np.pi * i))
    return np.diff(grid)


def _phase_bounds(phase: _Phase) -> tuple[list[float], list[float]]:
    low, high = [-np.inf] * _STATE, [np.inf] * _STATE
    for vehicle in range(2):
        if phase.legs[vehicle] == -1:  # parked at the junction for the whole phase
            low[3 * vehicle : 3 * vehicle + 3] = [0.0, 0.0, 0.0]
            high[3 * vehicle : 3 * vehicle + 3] = [0.0, 0.0, 0.0]
        else:
            low[3 * vehicle] = 0.0
    low[6] = _MIN_SEGMENT
    return low, high


@dataclass(frozen=True, slots=True)
class _Stage:
    """One control interval as a CasADi function, with the bounds of its path constraints."""

    function: object  # casadi.Function (x, w, fraction, limits) -> (next 6 states, path, between, cost)
    path_bounds: tuple[np.ndarray, np.ndarray]
    between_bounds: tuple[np.ndarray, np.ndarray]


@functools.cache
def _stage(parked: tuple[bool, bool], nearer: int, switching: int, *, path: bool, between: bool) -> _Stage:
    """The interval function of one kind of stage, built once and inlined into every NLP.

    Inputs: ``x`` (7,) the node state, ``w`` (2,) jerk / max jerk, ``fraction``
    the interval's share of the segment duration, ``limits`` (9,) the two leg
    lengths, max velocities, accelerations, jerks and the separation. Outputs:
    the exactly integrated next state (6,) (``v`` and ``a`` of the ``switching``
    vehicle negated: it enters its new leg), the node constraints, the
    between-node (Bernstein) constraints and the jerk regularization.
    """
    import casadi as ca

    x, w, fraction, limits = ca.SX.sym("x", _STATE), ca.SX.sym("w", 2), ca.SX.sym("f"), ca.SX.sym("q", 9)
    lengths, v_max, a_max, j_max, separation = limits[0:2], limits[2:4], limits[4:6], limits[6:8], limits[8]
    h = x[6] * fraction
    following, cost = [], 0
    path_terms, between_terms = [], []  # (expression, low, high)
    inner: list[list] = [[], []]
    for vehicle in range(2):
        s, v, a = x[3 * vehicle], x[3 * vehicle + 1], x[3 * vehicle + 2]
        jerk = j_max[vehicle] * w[vehicle]
        # exact integration of constant jerk over h
        s_next = s + h * (v + h * (a / 2.0 + h * jerk / 6.0))
        v_next = v + h * (a + h * jerk / 2.0)
        a_next = a + h * jerk
        if switching == vehicle:
            v_next, a_next = -v_next, -a_next
        following += [s_next, v_next, a_next]
        if parked[vehicle]:
            continue
        cost += _JERK_WEIGHT * h * w[vehicle] ** 2
        if path:
            path_terms += [
                (s - lengths[vehicle], -np.inf, 0.0),
                (v / v_max[vehicle], -1.0, 1.0),
                (a / a_max[vehicle], -1.0, 1.0),
            ]
        if between:
            # Between nodes: the velocity (quadratic) and the position (cubic) on the interval
            # lie in the convex hull of their Bernstein coefficients, so bounding those bounds
            # them for all time (the end coefficients are the node values, bounded above).
            between_terms.append(((v + h * a / 2.0) / v_max[vehicle], -1.0, 1.0))
            for c in _bernstein_cubic(s, v, a, h):
                between_terms += [(c, 0.0, np.inf), (c - lengths[vehicle], -np.inf, 0.0)]
                inner[vehicle].append(c)
    if path:
        path_terms.append((_gap(nearer, x[0], x[3]) - separation, 0.0, np.inf))
    if inner[0] and inner[1]:
        for c_first, c_second in zip(inner[0], inner[1], strict=True):
            between_terms.append((_gap(nearer, c_first, c_second) - separation, 0.0, np.inf))
    elif inner[0] or inner[1]:  # the other vehicle is parked at the junction (s = 0)
        between_terms += [(c - separation, 0.0, np.inf) for c in inner[0] or inner[1]]

    def stacked(terms):
        expression = ca.vertcat(*[t[0] for t in terms]) if terms else ca.SX(0, 1)
        return expression, (np.array([t[1] for t in terms]), np.array([t[2] for t in terms]))

    path_expression, path_bounds = stacked(path_terms)
    between_expression, between_bounds = stacked(between_terms)
    function = ca.Function(
        "trajgen_stage",
        [x, w, fraction, limits],
        [ca.vertcat(*following), path_expression, between_expression, cost],
    )
    return _Stage(function, path_bounds, between_bounds)


def _build(phases: list[_Phase], nodes: int, segments: int, max_iterations: int):
    """Build the parametric NLP of a region-sequence shape, stage by stage.

    Each phase is split into ``segments`` segments of free duration, each of
    ``nodes`` intervals (fixed fractions of it, :func:`_grid_fractions`), so
    that jerk switching instants need not fall on a fixed grid. Stage ``k``
    has state ``x_k = (s1, v1, a1, s2, v2, a2, T)``
    (``T`` the current segment's duration) and control ``u_k = (w1, w2)``
    (jerk / max jerk), plus the next segment's duration on the last interval
    of a segment. Variables are ordered ``x_0, u_0, x_1, ...`` and
    each stage's constraints are its gap-closing dynamics ``x_{k+1} - F(x_k, u_k)``
    followed by its path constraints: the layout fatrop's structure detection needs.

    Returns
    -------
    dict
        ``solvers`` (fatrop), ``builders`` of the Ipopt backups on the same NLP,
        ``bounds`` (``lbx``, ``ubx``, ``lbg``, ``ubg``) and ``size``.
    """
    import casadi as ca

    count = len(phases)
    parameters = ca.SX.sym("p", 2 * count + 11)
    lengths = [parameters[2 * p : 2 * p + 2] for p in range(count)]
    offset = 2 * count
    v_max = parameters[offset : offset + 2]
    a_max = parameters[offset + 2 : offset + 4]
    j_max = parameters[offset + 4 : offset + 6]
    separation = parameters[offset + 6]
    start = parameters[offset + 7 : offset + 9]
    goal = parameters[offset + 9 : offset + 11]

    variables, lower, upper = [], [], []
    constraints, g_lower, g_upper, equality = [], [], [], []
    objective = 0

    def constrain(expression, low, high):
        size = int(expression.numel())
        low, high = np.broadcast_to(low, size), np.broadcast_to(high, size)
        constraints.append(expression)
        g_lower.extend(low)
        g_upper.extend(high)
        equality.extend(low == high)

    def at_rest(x, phase: _Phase, positions):
        for vehicle in range(2):
            if phase.legs[vehicle] != -1:
                constrain(x[3 * vehicle] - positions[vehicle], 0.0, 0.0)
                constrain(x[3 * vehicle + 1 : 3 * vehicle + 3], 0.0, 0.0)

    def add_state(name: str, phase: _Phase, pinned: tuple[int, ...] = ()):
        x = ca.SX.sym(name, _STATE)
        low, high = _phase_bounds(phase)
        for vehicle in pinned:  # an equality pins its s: a bound as well would leave no strict interior
            if phase.legs[vehicle] != -1:
                low[3 * vehicle] = -np.inf
        variables.append(x)
        lower.extend(low)
        upper.extend(high)
        return x

    x = add_state("x0", phases[0], (0, 1))
    objective += x[6]
    intervals = segments * nodes
    fractions = _grid_fractions(nodes)
    for p, phase in enumerate(phases):
        limits = ca.vertcat(lengths[p], v_max, a_max, j_max, separation)
        for k in range(intervals):
            first, last = k == 0 and p == 0, p == count - 1 and k == intervals - 1
            # the duration of the current segment rides in the state; a new one starts every `nodes` intervals
            boundary = (k + 1) % nodes == 0 and not last
            phase_end = k == intervals - 1 and p < count - 1
            u = ca.SX.sym(f"u{p}_{k}", 3 if boundary else 2)
            variables.append(u)
            lower.extend([-1.0, -1.0] + ([_MIN_SEGMENT] if boundary else []))
            upper.extend([1.0, 1.0] + ([np.inf] if boundary else []))
            # The first and last intervals need no between-node bounds: from or to rest under
            # constant jerk, s, v and the gap there are monotone (all of the form c + d t^3), so
            # the node values bound them. Stating them anyway would tie inequalities to the rest
            # equalities (at a leg end, say) and leave the interior point solvers no strict interior.
            stage = _stage(
                tuple(leg == -1 for leg in phase.legs),
                phase.nearer,
                phase.switching if phase_end else -1,
                path=not first,
                between=not (first or last),
            )
            following, node_path, between, cost = stage.function(x, u[:2], fractions[k % nodes], limits)
            x_next = add_state(
                f"x{p}_{k + 1}",
                phases[p + 1] if phase_end else phase,
                (phase.switching,) if phase_end else (0, 1) if last else (),
            )
            constrain(x_next - ca.vertcat(following, u[2] if boundary else x[6]), 0.0, 0.0)
            # path constraints of this stage
            if k == 0 and p > 0:  # the vehicle that changed leg is at the junction
                constrain(x[3 * phases[p - 1].switching], 0.0, 0.0)
            if first:  # rest at the start, which the planner has checked: no node constraints
                at_rest(x, phase, start)
            if node_path.numel():
                constrain(node_path, *stage.path_bounds)
            if between.numel():
                constrain(between, *stage.between_bounds)
            objective += cost
            if boundary:
                objective += u[2]
            x = x_next
    at_rest(x, phases[-1], goal)  # the goal, which the planner has checked: no node constraints

    nlp = {"x": ca.vertcat(*variables), "p": parameters, "f": objective, "g": ca.vertcat(*constraints)}
    fatrop = ca.nlpsol(
        "trajgen_optimal_fatrop",
        "fatrop",
        nlp,
        {
            "structure_detection": "auto",
            "equality": equality,
            "print_time": False,
            # tol 1e-8: primal infeasibility stalls near 1e-8 (round-off of the h^3 terms); the
            # separation is planned 1 micrometre clear and the verifier checks every result
            "fatrop": {
                "print_level": 0,
                "max_iter": min(max_iterations, _FATROP_MAX_ITER),
                "tol": 1e-8,
                "mu_init": 1e-2,
            },
        },
    )

    def ipopt(warm: bool):
        """Ipopt on the same NLP; ``warm``: polish a nearby iterate, starting from its multipliers."""
        options = {
            "print_time": False,
            "ipopt.print_level": 0,
            "ipopt.sb": "yes",
            "ipopt.max_iter": min(max_iterations, _POLISH_MAX_ITER) if warm else max_iterations,
            "ipopt.tol": 1e-9,
            "ipopt.constr_viol_tol": 1e-10,
            "ipopt.mu_strategy": "monotone",
            "ipopt.mu_init": 1e-2,
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
        return ca.nlpsol("trajgen_optimal_ipopt" + ("_polish" if warm else ""), "ipopt", nlp, options)

    return {
        "solvers": {"fatrop": fatrop},
        # the Ipopt solvers are built on first need (most shapes never need them)
        "builders": {"ipopt-polish": lambda: ipopt(True), "ipopt": lambda: ipopt(False)},
        "bounds": {
            "lbx": np.array(lower, dtype=float),
            "ubx": np.array(upper, dtype=float),
            "lbg": np.array(g_lower, dtype=float),
            "ubg": np.array(g_upper, dtype=float),
        },
        "size": int(nlp["x"].numel()),
    }


def _gap(nearer: int, s1, s2):
    """Separation inside a region, linear in s1, s2 (``nearer``: 0 on different legs, else the nearer one)."""
    if nearer == 1:
        return s2 - s1
    if nearer == 2:
        return s1 - s2
    return s1 + s2


def _phase_windows(schedule: Schedule, phases: list[_Phase]) -> list[tuple[float, float]]:
    """Time windows of the exact schedule that the reduced region sequence attributes to each phase."""
    state = schedule.sample(min(0.01, schedule.duration / 200 or 0.01))
    entered = reduce_regions_indexed(region_keys(state.leg[0], state.s[0], state.leg[1], state.s[1]))
    if len(entered) != len(phases):  # the ray-only route, or a sampling corner case: share time evenly
        edges = np.linspace(0.0, schedule.duration, len(phases) + 1)
    else:
        edges = np.array([0.0] + [float(state.t[index]) for _, index in entered[1:]] + [schedule.duration])
        # a phase starts when its region is entered; keep the windows positive
        edges = np.maximum.accumulate(edges)
    return [(float(edges[p]), float(max(edges[p + 1], edges[p] + _MIN_PHASE))) for p in range(len(phases))]


def _initial_guess(
    schedule: Schedule, phases: list[_Phase], nodes: int, segments: int, size: int
) -> np.ndarray:
    """Stage-ordered initial guess from the exact schedule, in leg coordinates."""
    intervals = nodes * segments
    states = []  # per phase, shape (intervals + 1, 7)
    for phase, (begin, end) in zip(phases, _phase_windows(schedule, phases), strict=True):
        fractions = np.tile(_grid_fractions(nodes), segments) / segments
        times = begin + (end - begin) * np.concatenate([[0.0], np.cumsum(fractions)])
        state = schedule.state(times)
        columns = []
        for vehicle in range(2):
            if phase.legs[vehicle] == -1:
                columns += [np.zeros(intervals + 1)] * 3
                continue
            s = np.where(state.leg[vehicle] == phase.legs[vehicle], state.s[vehicle], 0.0)
            v = np.gradient(s, times)
            columns += [s, v, np.gradient(v, times)]
        states.append(np.column_stack([*columns, np.full(intervals + 1, (end - begin) / segments)]))
    guess = states[0][0].tolist()
    for p in range(len(phases)):
        for k in range(intervals):
            last = p == len(phases) - 1 and k == intervals - 1
            boundary = (k + 1) % nodes == 0 and not last
            following = states[p + 1][0] if k == intervals - 1 and not last else states[p][k + 1]
            guess += [0.0, 0.0] + ([float(following[6])] if boundary else [])
            guess += following.tolist()
    guess_array = np.array(guess)
    if guess_array.size != size:
        raise SolverError(f"initial guess has {guess_array.size} values, the NLP {size}")
    return guess_array


def _parameters(route: Route, limits: Limits, phases: list[_Phase]) -> np.ndarray:
    graph = route.graph
    values = []
    for phase in phases:
        values += [graph.lengths[leg] if leg >= 0 else 0.0 for leg in phase.legs]
    values += [v.max_velocity for v in limits.vehicles]
    values += [v.max_acceleration for v in limits.vehicles]
    values += [v.max_jerk for v in limits.vehicles]
    # plan 1 micrometre clear of the minimum: the solvers meet constraints to ~1e-8 m, the verifier
    # demands the minimum to 1e-9 m
    values.append(max(limits.min_separation, route.min_separation, _POSITIVE_SEPARATION) + _SEPARATION_MARGIN)
    values += [p.s for p in route.start]
    values += [p.s for p in route.goal]
    return np.array(values, dtype=float)


def _unpack(solution: np.ndarray, phases: list[_Phase], nodes: int, segments: int):
    """Breakpoint times, node states and controls of each phase, from the stage layout.

    Returns
    -------
    list of (times (m + 1,), states (m + 1, 6), controls (m, 2))
        One entry per phase, ``m = nodes * segments``; times from 0 at the
        phase start. The last node of a phase is the junction crossing, rebuilt
        from the next phase's first node by undoing the sign change of the
        vehicle that changed leg.
    """
    count = len(phases)
    intervals = nodes * segments
    fractions = _grid_fractions(nodes)
    out = []
    k = 0
    x = solution[k : k + _STATE]
    k += _STATE
    for p, phase in enumerate(phases):
        times = np.zeros(intervals + 1)
        states = np.zeros((intervals + 1, 6))
        controls = np.zeros((intervals, 2))
        states[0] = x[:6]
        for i in range(intervals):
            last = p == count - 1 and i == intervals - 1
            boundary = (i + 1) % nodes == 0 and not last
            times[i + 1] = times[i] + x[6] * fractions[i % nodes]
            controls[i] = solution[k : k + 2]
            k += 3 if boundary else 2
            x = solution[k : k + _STATE]
            k += _STATE
            states[i + 1] = x[:6]
        if p < count - 1:
            states[-1, 3 * phase.switching + 1 : 3 * phase.switching + 3] *= -1.0
        out.append((times, states, controls))
    return out


def _to_schedule(
    route: Route,
    limits: Limits,
    phases: list[_Phase],
    nodes: int,
    segments: int,
    solution: np.ndarray,
    notes: tuple[str, ...],
) -> Schedule:
    """Turn the NLP solution into a Schedule on the vehicles' signed axes."""
    pieces_of_phases = _unpack(solution, phases, nodes, segments)
    j_max = np.array([v.max_jerk for v in limits.vehicles])
    goal = [p.s for p in route.goal]
    # outward[v]: ds/daxis of vehicle v in the current phase; flips when it changes leg
    outward = [1, 1]
    axis = [0.0, 0.0]
    pieces = []
    for p, phase in enumerate(phases):
        times, states, controls = pieces_of_phases[p]
        profiles, maps = [], []
        for vehicle in range(2):
            sign = outward[vehicle]
            node = states[:-1, 3 * vehicle : 3 * vehicle + 3].copy()
            if p == 0 and phase.legs[vehicle] != -1:
                # the solver meets the start to ~1e-8 m: spread the residual linearly over the
                # first phase so the start is exact (adds ~1e-9 m/s)
                residual = route.start[vehicle].s - node[0, 0]
                node[:, 0] += residual * (1.0 - times[:-1] / times[-1])
                node[:, 1] -= residual / times[-1]
            s0 = node[0, 0]
            initial = np.column_stack(
                [axis[vehicle] + sign * (node[:, 0] - s0), sign * node[:, 1], sign * node[:, 2]]
            )
            jerk = sign * j_max[vehicle] * controls[:, vehicle]
            profile = PiecewiseCubic(times, initial, jerk)
            if p == len(phases) - 1 and phase.legs[vehicle] != -1:
                # likewise the goal: spread the residual (~1e-8 m) linearly over the last phase
                end_s = s0 + sign * (profile.end_state()[0] - axis[vehicle])
                drift = sign * (goal[vehicle] - end_s)
                corrected = initial.copy()
                corrected[:, 0] += drift * times[:-1] / times[-1]
                corrected[:, 1] += drift / times[-1]
                profile = PiecewiseCubic(times, corrected, jerk)
            end_axis = profile.end_state()[0]
            leg = phase.legs[vehicle]
            maps.append(
                AxisMap(
                    np.array([axis[vehicle]]),
                    np.array([end_axis]),
                    np.array([leg]),
                    np.array([s0 if leg >= 0 else 0.0]),
                    np.array([sign if leg >= 0 else 0]),
                )
            )
            profiles.append(profile)
            axis[vehicle] = end_axis
        pieces.append((profiles, maps))
        if phase.switching >= 0:
            outward[phase.switching] = -outward[phase.switching]
    # the signed axis is positive in the direction of each vehicle's first move
    flip = [1.0, 1.0]
    for vehicle in range(2):
        velocities = np.concatenate([profiles[vehicle].initial[:, 1] for profiles, _ in pieces])
        moving = np.nonzero(np.abs(velocities) > 1e-9)[0]
        if moving.size and velocities[moving[0]] < 0:
            flip[vehicle] = -1.0
    sections = []
    clock = 0.0
    for profiles, maps in pieces:
        flipped_profiles = tuple(
            PiecewiseCubic(profile.times, profile.initial * flip[v], profile.jerk * flip[v])
            for v, profile in enumerate(profiles)
        )
        flipped_maps = tuple(
            AxisMap(
                m.axis_start * flip[v],
                m.axis_end * flip[v],
                m.legs,
                m.s_start,
                (m.outward * flip[v]).astype(int),
            )
            for v, m in enumerate(maps)
        )
        kinematics = CubicKinematics(flipped_profiles)  # type: ignore[arg-type]
        sections.append(Section(clock, kinematics, flipped_maps))  # type: ignore[arg-type]
        clock += kinematics.duration
    return Schedule(route, limits, Method.OPTIMAL, tuple(sections), jerk_limited=True, notes=notes)


def optimal_schedule(
    route: Route,
    limits: Limits,
    *,
    nodes: int = DEFAULT_NODES,
    segments: int = DEFAULT_SEGMENTS,
    max_iterations: int = 3000,
) -> Schedule:
    """The fastest jerk-limited schedule in the route's homotopy class, verified; else ``exact``.

    Parameters
    ----------
    route : Route
    limits : Limits
    nodes : int, optional
        Equal control intervals per segment (default :data:`DEFAULT_NODES`).
    segments : int, optional
        Segments of free duration per phase (default :data:`DEFAULT_SEGMENTS`).
    max_iterations : int, optional
        Iteration limit of each solver (fatrop, then Ipopt).

    Returns
    -------
    Schedule
        Method ``optimal``, verified; or the ``exact`` schedule with
        ``fallback_reason`` set if the solver failed or its result did not verify.
        ``Schedule.info`` holds an :class:`OptimalInfo`.
    """
    from trajgen.verify import verify

    if not isinstance(nodes, int) or nodes < 1:
        raise InputError(f"nodes per segment must be an integer >= 1, got {nodes!r}")
    if not isinstance(segments, int) or segments < 1:
        raise InputError(f"segments per phase must be an integer >= 1, got {segments!r}")
    if not isinstance(max_iterations, int) or max_iterations < 1:
        raise InputError(f"max_iterations must be an integer >= 1, got {max_iterations!r}")
    exact = exact_schedule(route, limits)
    if len(route.waypoints) == 1:  # nothing moves: the exact schedule is optimal
        return _exact_as_optimal(exact, "start is the goal: nothing moves")
    phases = _phases(route)
    key = _shape(phases, nodes, segments, max_iterations)
    began = time.perf_counter()
    built = key not in _SOLVERS
    if built:
        _SOLVERS[key] = _build(phases, nodes, segments, max_iterations)
        logger.info("built the optimal-control NLP for shape %s", key)
    layout = _SOLVERS[key]
    try:
        guess = _initial_guess(exact, phases, nodes, segments, layout["size"])
        parameters = _parameters(route, limits, phases)
    except Exception as error:  # a malformed guess is a bug, but must not leak an unverified schedule
        return _fallback(exact, f"initial guess failed: {type(error).__name__}: {error}", began, built)
    attempts = []
    solution, solved_by = None, ""
    solvers = layout["solvers"]
    previous = None  # the last solver's result, to warm-start the polish
    for name in _SOLVER_ORDER:
        if name == "ipopt-polish":
            if previous is None:
                continue
            start = {"x0": previous["x"], "lam_x0": previous["lam_x"], "lam_g0": previous["lam_g"]}
        else:
            start = {"x0": guess}
        solver = solvers.get(name)
        if solver is None:
            solver = solvers[name] = layout["builders"][name]()
        try:
            result = solver(**start, p=parameters, **layout["bounds"])
            stats = solver.stats()
        except RuntimeError as error:  # CasADi reports evaluation and solver errors as RuntimeError
            attempts.append(f"{name} raised: {error}")
            previous = None
            continue
        status = str(stats.get("return_status", stats.get("success")))
        iterations = int(stats.get("iter_count", -1))
        if stats.get("success", False):
            solution, solved_by = np.array(result["x"]).ravel(), name
            attempts.append(f"{name} solved in {iterations} iterations")
            break
        previous = result if np.all(np.isfinite(np.array(result["x"]))) else None
        attempts.append(f"{name} did not converge ({status}, {iterations} iterations)")
        logger.info("optimal: %s did not converge (%s); trying the next solver", name, status)
    elapsed = time.perf_counter() - began
    info = OptimalInfo(
        elapsed, built, iterations if solution is not None else -1, "; ".join(attempts), solver=solved_by
    )
    if solution is None:
        return _fallback(exact, "; ".join(attempts), began, built, info)
    schedule = _to_schedule(
        route,
        limits,
        phases,
        nodes,
        segments,
        solution,
        (
            f"{len(phases)} phase(s) x {segments} segments x {nodes} intervals; {attempts[-1]}; "
            f"{elapsed * 1e3:.0f} ms",
        ),
    )
    schedule = dataclasses.replace(schedule, info=info)
    report = verify(schedule)
    if not report.passed:
        return _fallback(
            exact, "optimal schedule failed verification: " + "; ".join(report.failures), began, built, info
        )
    if schedule.duration > exact.duration:
        # The NLP's grid can only approach an S-curve from above; where the exact schedule
        # is already optimal in the class (e.g. the vehicles never interact) it is faster.
        # Both are verified members of the class: return the faster, and say so.
        note = (
            f"the exact schedule ({exact.duration:.3f} s) is faster than the discretized optimum "
            f"({schedule.duration:.3f} s); returned it"
        )
        logger.info("optimal: %s", note)
        return _exact_as_optimal(exact, note, dataclasses.replace(info, source="exact"))
    return schedule


def _exact_as_optimal(exact: Schedule, note: str, info: OptimalInfo | None = None) -> Schedule:
    """The exact schedule, returned by the optimal method because it is the fastest known."""
    return dataclasses.replace(exact, method=Method.OPTIMAL, notes=(note,), info=info)


def _fallback(exact: Schedule, reason: str, began: float, built: bool, info: OptimalInfo | None = None):
    logger.warning("optimal schedule fell back to exact: %s", reason)
    info = info or OptimalInfo(time.perf_counter() - began, built, -1, "exception")
    return dataclasses.replace(
        exact, notes=(f"fallback to exact: {reason}",), fallback_reason=reason, info=info
    )
