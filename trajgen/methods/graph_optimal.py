"""The ``optimal`` method on a track graph: the jerk-limited time-optimal schedule within the route's class.

In the plane of both vehicles' travel, a pair of path segments (one per vehicle, each on one edge)
is a rectangle, a **cell**. On a cell the track distance is the least of at most five affine
functions of the two travels (through each pair of edge ends, and along one edge), so the safe part
of the cell, where every one of them is at least the separation (on one edge, on the side the route
keeps), is convex. A motion that visits a
given sequence of cells is therefore in one homotopy class, and keeping it safe is linear.

The problem (a CasADi SX NLP, solved by IPOPT): phases, one per cell of the sequence the ``toppra``
schedule of the route visits (its hand-overs already overlapped), each of free duration (zero: a
corner passed in an instant) with :data:`NODES` control intervals of constant jerk per vehicle, at
fixed shares of it, denser at its ends (:data:`ATTEMPTS`, tried in turn); the state of each
vehicle is its travel, velocity and acceleration, integrated exactly. Between the nodes the
constraints hold too: travel (a cubic) and velocity (a quadratic) through their Bernstein
coefficients, whose convex hull contains the curve, so the cell's bounds and its separation
constraints hold on the whole interval. Travel never decreases; where a path turns back the vehicle's
velocity is zero and the acceleration along its axis goes on (a smooth reversal). The makespan is
minimised (with a small jerk regularization). The result is integrated again from its jerks, each
stretch up to a cusp or the goal corrected to end there exactly (so position, velocity and
acceleration are continuous by construction), and verified by the caller
(:mod:`trajgen.methods.graph_classes`), which falls back to ``exact`` where it fails.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from limits import Limits
from topology import GraphRoute
from trajgen.methods.graph_timing import check_graph_request, moves_one_at_a_time, overlapped_moves
from trajgen.model.graph_cells import cell_ways
from trajgen.model.graph_paths import GraphPath
from trajgen.model.graph_schedule import GraphSchedule, GraphSection
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.schedule import CubicKinematics

__all__ = ["ATTEMPTS", "NODES", "optimal_graph_schedule"]

logger = logging.getLogger(__name__)

#: The problems tried in turn, each to its iteration limit: the weight of cosine (end-dense) spacing in
#: each cell's grid (0: uniform), and whether MUMPS scales the KKT systems. Measured on 40 seeded
#: random graphs and the examples: without its scaling MUMPS factors most systems 2 to 6 times faster,
#: with it a few more converge; the end-dense grid resolves the jerk ramps at the cells' ends.
ATTEMPTS = ((0.8, False), (0.8, True), (0.0, True))
#: Control intervals per phase (cell).
NODES = 16
#: Metres a position may stray past its cell's bounds (a strict interior for the solver; the path's
#: own equalities at the cell's ends keep it inside).
_MARGIN = 1e-4
#: Share of the velocity and acceleration limits the problem plans with (the re-integration's round-off).
_HEADROOM = 1.0 - 1e-5
#: A cell passed in less than this is passed in an instant (its intervals are dropped), seconds.
_INSTANT = 1e-9
#: Share of the jerk limit the problem plans with: room for the corrections of :func:`_ending_exactly`.
_JERK_HEADROOM = 1.0 - 1e-5
#: Weight of the jerk regularization relative to the makespan.
_JERK_WEIGHT = 1e-5
#: Samples of the initial guess per second when finding the cells it visits (and at least this many).
_GUESS_SAMPLES = 4000


@dataclasses.dataclass(frozen=True, slots=True)
class _Cell:
    """One phase: each vehicle's path segment, and what happens when it ends."""

    segments: tuple[int, int]
    end_time: float  # in the initial guess, seconds
    inside: tuple[float, float]  # both travels at a moment of the guess in the cell, metres


def _segments_at(paths: tuple[GraphPath, GraphPath], travel: np.ndarray) -> np.ndarray:
    """Path segment of each vehicle at travel samples (2, n); a vehicle at a boundary is in the later one."""
    return np.stack([paths[v].segment(travel[v]) for v in range(2)])


def _cells(guess: GraphSchedule) -> list[_Cell]:
    """The cells the guess visits, in order, each with the guess's time at its end."""
    samples = max(_GUESS_SAMPLES, int(20 * guess.duration))
    t = np.linspace(0.0, guess.duration, samples + 1)
    travel = guess.travel(t)[:, 0]
    segments = _segments_at(guess.paths, travel)
    cells: list[_Cell] = []
    current = (int(segments[0, 0]), int(segments[1, 0]))
    entered = 0
    for k in range(1, t.size):
        here = (int(segments[0, k]), int(segments[1, k]))
        if here == current:
            continue
        middle = (entered + k) // 2
        inside = (float(travel[0, middle]), float(travel[1, middle]))
        # one boundary at a time: a jump of both (or over a segment) passes the corners in order
        while here != current:
            step = list(current)
            for vehicle in range(2):
                if here[vehicle] != current[vehicle]:
                    step[vehicle] += 1
                    break
            cells.append(_Cell(current, float(t[k]), inside))
            current = (step[0], step[1])
        entered = k
    middle = (entered + t.size - 1) // 2
    cells.append(_Cell(current, guess.duration, (float(travel[0, middle]), float(travel[1, middle]))))
    return cells


def _ways(route: GraphRoute, paths: tuple[GraphPath, GraphPath], cell: _Cell) -> list:
    """The safe part of a cell as rows ``(c1, c2, c0)``: ``c1 p1 + c2 p2 + c0 >= d`` for each.

    Every way through the edges' ends; on one edge also ``|s1 - s2|``, on the side the guess keeps
    there (the vehicles do not pass each other on an edge).
    """
    ways, along = cell_ways(route.track, paths, cell.segments)
    if along is not None:
        a, b, c = along
        f = 1.0 if a * cell.inside[0] + b * cell.inside[1] + c >= 0.0 else -1.0  # f (s1 - s2) >= d
        ways.append((f * a, f * b, f * c))
    return ways


def _cusp_after(path: GraphPath, segment: int) -> bool:
    """Whether the path turns back at the end of ``segment``."""
    return segment + 1 < path.headings.size and path.headings[segment + 1] != path.headings[segment]


def _cusp_nodes(paths, cells: list[_Cell]) -> list[set[int]]:
    """Per vehicle, the nodes where its path turns back.

    Its velocity is 0 there and its travel's acceleration changes sign: the acceleration along its
    axis goes on (a smooth reversal).
    """
    cusps: list[set[int]] = [set(), set()]
    for c in range(len(cells) - 1):
        for v in range(2):
            segment = cells[c].segments[v]
            if cells[c + 1].segments[v] != segment and _cusp_after(paths[v], segment):
                cusps[v].add((c + 1) * NODES)
    return cusps


class _Nlp:
    """The problem as a CasADi SX NLP: variables with bounds, constraints with bounds, an objective."""

    def __init__(self) -> None:
        self.variables: list = []
        self.lower: list[float] = []
        self.upper: list[float] = []
        self.constraints: list = []
        self.constraint_lower: list[float] = []
        self.constraint_upper: list[float] = []

    def variable(self, name: str, shape: tuple[int, int], low: float, high: float):
        import casadi as ca

        symbol = ca.SX.sym(name, *shape)
        self.variables.append(ca.vec(symbol))
        self.lower += [low] * (shape[0] * shape[1])
        self.upper += [high] * (shape[0] * shape[1])
        return symbol

    def bound(self, offset: int, low: float, high: float) -> None:
        """Bound the variable at ``offset`` of the stacked vector."""
        self.lower[offset], self.upper[offset] = low, high

    def subject_to(self, expression, low: float, high: float) -> None:
        self.constraints.append(expression)
        self.constraint_lower.append(low)
        self.constraint_upper.append(high)


def _fractions(density: float) -> np.ndarray:
    """Each interval's share of its cell's duration, shape (NODES,): denser at the cell's ends.

    A fixed blend of uniform and cosine spacing (as on a junction,
    :func:`trajgen.methods.optimal.phases.grid_fractions`): the vehicles start, stop, turn back and
    pass nodes at a cell's ends, where the short jerk ramps need the nodes.
    """
    i = np.arange(NODES + 1) / NODES
    return np.diff((1.0 - density) * i + density * 0.5 * (1.0 - np.cos(np.pi * i)))


def _problem(route: GraphRoute, limits: Limits, paths, cells: list[_Cell], *, density: float):
    """The problem of the module's docstring as an SX NLP.

    Each cell has one duration, its intervals the shares :func:`_fractions` of it (``density``).
    Returns the NLP, its objective, and its variables: durations, state (6, count + 1), jerk (2, count).

    Bounds, rest and boundary conditions are bounds of the variables (a variable an equality fixes
    is fixed); no inequality is tied to an equality (the interior-point solver needs a strict
    interior): the velocity's inner Bernstein coefficient next to the start and goal, zero by the rest
    conditions, is left out.
    """
    import casadi as ca

    phases, n = len(cells), NODES
    count = phases * n
    nlp = _Nlp()
    inf = math.inf
    durations = nlp.variable("T", (phases, 1), 0.0, inf)  # a corner of two boundaries: in an instant
    state = nlp.variable("x", (6, count + 1), -inf, inf)  # p1 v1 a1 p2 v2 a2, column-major
    jerk = nlp.variable("j", (2, count), -inf, inf)
    offset_state = len(nlp.lower) - 6 * (count + 1) - 2 * count
    offset_jerk = offset_state + 6 * (count + 1)

    def fix(row: int, node: int, low: float, high: float | None = None) -> None:
        nlp.bound(offset_state + 6 * node + row, low, low if high is None else high)

    v_max = [limits.vehicles[v].max_velocity * _HEADROOM for v in range(2)]
    a_max = [limits.vehicles[v].max_acceleration * _HEADROOM for v in range(2)]
    j_max = [limits.vehicles[v].max_jerk * _JERK_HEADROOM for v in range(2)]
    # no margin: the planner parks a vehicle exactly at the separation from where the other passes
    required = max(limits.min_separation, route.min_separation)
    cusps = _cusp_nodes(paths, cells)
    fractions = _fractions(density)
    for v in range(2):
        for k in range(count):
            nlp.bound(offset_jerk + 2 * k + v, -j_max[v], j_max[v])
        for k in range(count + 1):
            fix(3 * v + 1, k, 0.0, v_max[v])
            fix(3 * v + 2, k, -a_max[v], a_max[v])
        for k in cusps[v]:
            fix(3 * v + 1, k, 0.0)
        for k in (0, count):
            fix(3 * v + 1, k, 0.0)
            fix(3 * v + 2, k, 0.0)
        fix(3 * v, 0, 0.0)
        fix(3 * v, count, float(paths[v].length))
    objective = ca.sum1(durations)
    for c, cell in enumerate(cells):
        ways = _ways(route, paths, cell)
        bounds = [
            (float(paths[v].starts[cell.segments[v]]), float(paths[v].starts[cell.segments[v] + 1]))
            if paths[v].edges.size
            else (0.0, 0.0)
            for v in range(2)
        ]
        for k in range(c * n, (c + 1) * n):
            h = durations[c] * float(fractions[k - c * n])
            x, x_next = state[:, k], state[:, k + 1]
            control_points = []
            for v in range(2):
                p, vel, acc = x[3 * v], x[3 * v + 1], x[3 * v + 2]
                if k in cusps[v]:  # it turned back: its travel's acceleration changes sign
                    acc = -acc
                j = jerk[v, k]
                nlp.subject_to(x_next[3 * v] - (p + h * (vel + h * (acc / 2 + h * j / 6))), 0.0, 0.0)
                nlp.subject_to(x_next[3 * v + 1] - (vel + h * (acc + h * j / 2)), 0.0, 0.0)
                nlp.subject_to(x_next[3 * v + 2] - (acc + h * j), 0.0, 0.0)
                if 0 < k < count - 1:  # next to the start and goal the rest conditions imply it
                    nlp.subject_to(vel + h * acc / 2, 0.0, v_max[v])  # the quadratic's inner coefficient
                points = [p, p + h * vel / 3, p + 2 * h * vel / 3 + h * h * acc / 6, x_next[3 * v]]
                if paths[v].edges.size:
                    for point in points[1:3]:
                        nlp.subject_to(point, bounds[v][0] - _MARGIN, bounds[v][1] + _MARGIN)
                control_points.append(points)
                objective += _JERK_WEIGHT * h * (j / j_max[v]) ** 2
            for c1, c2, c0 in ways:
                for m in range(1, 4):
                    nlp.subject_to(c1 * control_points[0][m] + c2 * control_points[1][m] + c0, required, inf)
        following = cells[c + 1].segments if c + 1 < phases else cell.segments
        node = (c + 1) * n
        for v in range(2):
            if not paths[v].edges.size or node == count:
                continue
            if following[v] != cell.segments[v]:
                fix(3 * v, node, bounds[v][1])
            else:
                fix(3 * v, node, bounds[v][0] - _MARGIN, bounds[v][1] + _MARGIN)
    return nlp, objective, (durations, state, jerk)


def _run(nlp: _Nlp, objective, initial: np.ndarray, method, iterations: int, *, scaling: bool) -> np.ndarray:
    """Solve with IPOPT from ``initial``; the stacked solution, or RuntimeError naming IPOPT's status."""
    import casadi as ca

    solver = ca.nlpsol(
        "graph_optimal",
        "ipopt",
        {"x": ca.vertcat(*nlp.variables), "f": objective, "g": ca.vertcat(*nlp.constraints)},
        {
            "print_time": False,
            "error_on_fail": False,
            "ipopt": {
                "print_level": 0,
                "sb": "yes",
                "max_iter": iterations,
                "max_wall_time": float(method.time_limit),
                "tol": 1e-9,
                "constr_viol_tol": 1e-10,  # the dynamics to round-off: the motion is integrated again
                "mumps_mem_percent": 2000,  # MUMPS re-allocating memory again and again took most of the time
                # MUMPS' own scaling (its default) made some KKT systems slow to factor (the H: 75 ms an
                # iteration against 12 ms): see ATTEMPTS
                **({} if scaling else {"mumps_permuting_scaling": 0, "mumps_scaling": 0}),
                "acceptable_iter": 0,
                "bound_relax_factor": 0.0,
                # measured on the examples and the star as a graph: adaptive stalls on some, and a
                # small first barrier parameter halves the iterations (the guess is nearly feasible)
                "mu_strategy": "monotone",
                "mu_init": 1e-3,
            },
        },
    )
    result = solver(
        x0=initial, lbx=nlp.lower, ubx=nlp.upper, lbg=nlp.constraint_lower, ubg=nlp.constraint_upper
    )
    status = solver.stats()["return_status"]
    logger.debug("IPOPT: %s after %d iterations", status, solver.stats()["iter_count"])
    if not solver.stats()["success"]:
        raise RuntimeError(f"IPOPT: {status}")
    return np.asarray(result["x"], dtype=float).ravel()


def _solve(route: GraphRoute, limits: Limits, paths, cells: list[_Cell], guess: GraphSchedule, method):
    """Solve the problem from the ``toppra`` schedule: interval durations (count,), jerks (2, count).

    The problems of :data:`ATTEMPTS` are tried in turn (the end-dense grid resolves the jerk ramps
    at the cells' ends better, the uniform one converges where it does not; MUMPS' scaling is
    slower and converges on a few more).

    Raises
    ------
    RuntimeError
        No grid's problem was solved; the message has IPOPT's status of each.
    """
    phases, n = len(cells), NODES
    count = phases * n
    failures = []
    for density, scaling in ATTEMPTS:
        fractions = _fractions(density)
        starts = np.concatenate([[0.0], np.cumsum(fractions)[:-1]])
        nlp, objective, _ = _problem(route, limits, paths, cells, density=density)
        previous, spans, times = 0.0, [], []
        for cell in cells:
            span = max(cell.end_time - previous, 1e-2)
            spans.append(span)
            times.append(previous + span * starts)
            previous = cell.end_time
        times = np.concatenate([*times, [guess.duration]])
        values = guess.travel(np.clip(times, 0.0, guess.duration))
        state = np.vstack([values[0, :3], values[1, :3]])
        initial = np.concatenate([spans, state.ravel(order="F"), np.zeros(2 * count)])
        try:
            solution = _run(nlp, objective, initial, method, method.max_iterations, scaling=scaling)
        except RuntimeError as error:
            failures.append(f"grid {density:g}{', scaled' if scaling else ''}: {error}")
            continue
        steps = np.concatenate([duration * fractions for duration in solution[:phases]])
        return steps, solution[phases + 6 * (count + 1) :].reshape((2, count), order="F")
    raise RuntimeError("; ".join(failures))


def _end_state(start: np.ndarray, durations: np.ndarray, jerks: np.ndarray) -> np.ndarray:
    """Position, velocity and acceleration after constant-jerk intervals from the state ``start``."""
    p, v, a = start
    for h, j in zip(durations, jerks, strict=True):
        p, v, a = p + h * (v + h * (a / 2.0 + h * j / 6.0)), v + h * (a + h * j / 2.0), a + h * j
    return np.array([p, v, a])


def _ending_exactly(
    start: np.ndarray, target: float, durations: np.ndarray, jerks: np.ndarray, *, at_rest: bool
) -> np.ndarray:
    """``jerks`` corrected so the stretch ends exactly at ``target`` with velocity 0.

    The solver meets its equalities to its tolerance; integrated again, a stretch ends a few 1e-10
    off. Each interval's jerk moves the end state linearly (``h`` in acceleration, ``h^2/2 + h R``
    in velocity, ``h^3/6 + h^2 R/2 + h R^2/2`` in position, ``R`` the time after it), so the least
    correction of all its intervals' jerks (a few 1e-10 m/s^3) puts it back exactly: position and
    velocity where the path turns back, and acceleration too at the goal (``at_rest``).
    """
    # every interval of the stretch long enough to be well conditioned: the least correction of all
    last = np.nonzero(durations >= 1e-3 * max(float(durations.max(initial=0.0)), 1e-300))[0]
    if last.size == 0:
        return jerks
    after = np.concatenate([np.cumsum(durations[::-1])[::-1][1:], [0.0]])
    h, r = durations[last], after[last]
    effect = np.array([h**3 / 6.0 + h**2 * r / 2.0 + h * r**2 / 2.0, h**2 / 2.0 + h * r, h])
    error = np.array([target, 0.0, 0.0]) - _end_state(start, durations, jerks)
    rows = 3 if at_rest else 2
    corrected = jerks.copy()
    change = np.linalg.lstsq(effect[:rows], error[:rows], rcond=None)[0]
    if not np.all(np.abs(change) <= 0.5 * (1.0 - _JERK_HEADROOM) * float(np.max(np.abs(jerks), initial=1.0))):
        raise ArithmeticError(
            f"the solver's motion misses its own end by {np.max(np.abs(error)):.3g}: a correction of "
            f"{np.max(np.abs(change)):.3g} m/s^3 would be needed"
        )
    corrected[last] += change
    return corrected


def _through_cusps(phases: list[tuple[float, float]], targets: dict[int, float]) -> PiecewiseCubic:
    """The travel of constant-jerk ``phases`` (duration, jerk) from rest, exact at each cusp and the goal.

    ``targets`` maps a node (the index of the phase it ends) to the travel there, metres: each cusp,
    where the velocity is 0 and the travel's acceleration changes sign, and the goal (the largest
    node), where the vehicle is at rest (:func:`_ending_exactly`). Each stretch is integrated on its
    own from the state the one before ends in.
    """
    initial, jerks = [], []
    first, state = 0, np.zeros(3)
    goal = max(targets)
    for node in sorted(targets):
        durations = np.array([d for d, _ in phases[first:node]])
        corrected = _ending_exactly(
            state,
            targets[node],
            durations,
            np.array([j for _, j in phases[first:node]]),
            at_rest=node == goal,
        )
        entries = [(d, math.nan, j) for d, j in zip(durations, corrected, strict=True) if d > 0.0]
        if entries:  # it leaves the cusp with the acceleration it arrived with, along its axis
            entries[0] = (entries[0][0], float(state[2]), entries[0][2])
        stretch = PiecewiseCubic.from_phases(float(state[0]), entries, end=targets[node])
        reached = stretch.end_state()
        if abs(reached[0] - targets[node]) > 1e-9 or abs(reached[1]) > 1e-9:
            raise ArithmeticError(
                f"the solver's motion ends a stretch at {reached[0]:.9g} m, {reached[1]:.3g} m/s: expected "
                f"{targets[node]:.9g} m at rest"
            )
        if stretch.duration > 0.0:
            initial.extend(stretch.initial)
            jerks.extend(stretch.jerk)
            end = _end_state(stretch.initial[-1], np.diff(stretch.times[-2:]), stretch.jerk[-1:])
            state = np.array([targets[node], 0.0, -end[2] if node != goal else 0.0])
        first = node
    if not jerks:
        return PiecewiseCubic.from_phases(0.0, [])
    # the knots from all the phases at once, the same floats for both vehicles (no sliver pieces
    # between their knots where one vehicle's numbers would be read with the other's segment)
    kept = np.array([d for d, _ in phases if d > 0.0])
    return PiecewiseCubic(np.concatenate([[0.0], np.cumsum(kept)]), np.array(initial), np.array(jerks))


def optimal_graph_schedule(route: GraphRoute, limits: Limits, method) -> GraphSchedule:
    """The jerk-limited time-optimal schedule of ``route``'s class (see the module), unverified.

    Raises
    ------
    InputError
        A bad route or limits.
    RuntimeError
        The solver did not converge (the caller falls back).
    """
    check_graph_request(route, limits)
    exact = moves_one_at_a_time(route, limits, method, jerk=True)
    if not any(move.length > 0.0 for move in route.moves):
        return exact
    guess = overlapped_moves(route, limits, method, grid_points=120)
    cells = _cells(guess)
    durations, jerks = _solve(route, limits, exact.paths, cells, guess, method)
    durations = np.where(durations > _INSTANT, durations, 0.0)
    count = len(cells) * NODES
    cusps = _cusp_nodes(exact.paths, cells)
    profiles = []
    for v in range(2):
        phases = [
            (float(durations[c * NODES + k]), float(jerks[v, c * NODES + k]))
            for c in range(len(cells))
            for k in range(NODES)
        ]
        targets = {count: exact.paths[v].length}
        for node in cusps[v]:
            targets[node] = float(exact.paths[v].starts[cells[node // NODES - 1].segments[v] + 1])
        profiles.append(_through_cusps(phases, targets))
    kinematics = CubicKinematics((profiles[0], profiles[1]))
    notes = (f"optimal: {len(cells)} cells of the travel plane, {NODES} intervals each (IPOPT)",)
    return GraphSchedule(
        route, limits, method, exact.paths, (GraphSection(0.0, kinematics),), True, notes=notes
    )
