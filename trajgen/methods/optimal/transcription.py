"""Transcription of the multi-phase optimal-control problem into a parametric NLP (CasADi).

Stage ``k`` has state ``x_k = (s1, v1, a1, s2, v2, a2, T, c)`` (``T`` the
current segment's duration, ``c`` where the phase's reversing vehicle turns,
:mod:`~.braking`) and control ``u_k = (w1, w2)`` (jerk / max jerk), plus the
next segment's duration on the last interval of a segment and the next
phase's ``c`` on the last interval of a phase before one with a reversal. Variables are
ordered ``x_0, u_0, x_1, ...`` and each stage's constraints are its
gap-closing dynamics ``x_{k+1} - F(x_k, u_k)`` followed by its path
constraints: the layout fatrop's structure detection needs.

Constraints hold between nodes, not only at them: the dynamics are integrated
exactly, and the velocity (quadratic) and position (cubic) on each interval
are bounded through their Bernstein coefficients, whose convex hull contains
the polynomial. No inequality is tied to an equality: bounds on a position
that an equality pins (start, goal, junction crossing) are dropped, and so are
the between-node bounds of the first and last interval, which the rest
conditions make redundant; otherwise the interior-point solvers would have no
strict interior and crawl.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from trajgen.methods.optimal.braking_constraints import BRAKING_SAMPLES, VehicleSymbols, braking_terms
from trajgen.methods.optimal.phases import DEPTH, DURATION, STATE_SIZE, NlpShape, PhaseKind, Stage, stages

__all__ = ["ParameterLayout", "Transcription", "transcribe"]

#: Weight of the jerk regularization relative to the makespan (keeps the solver away from chattering).
_JERK_WEIGHT = 1e-4
#: Smallest duration of a segment, seconds.
MIN_SEGMENT = 1e-4


@dataclass(frozen=True, slots=True)
class ParameterLayout:
    """The order of the NLP's parameters: the one place both the symbols and the values follow.

    Parameters, in order: per phase the two vehicles' leg lengths (metres,
    0 for a vehicle parked at the junction), then ``max_velocity``,
    ``max_acceleration``, ``max_jerk``, ``emergency`` (the emergency
    decelerations, m/s²) (2 each), ``separation`` (1), ``braking`` (2: the braking rule's
    clearance, metres, and its margin per squared second of an interval, m/s²),
    ``start`` and ``goal`` (each vehicle's ``s``, 2 each), and the grid:
    per phase and interval its share of its segment's duration
    (``phase_count * intervals``; each segment's shares sum to 1). The grid
    is a parameter so that mesh refinement re-solves the same compiled NLP.

    Every quantity is in the problem's units (:class:`~.units.ProblemUnits`):
    :attr:`dimensions` gives each block's powers of length and time.
    """

    phase_count: int
    intervals: int

    @property
    def fields(self) -> tuple[tuple[str, int], ...]:
        """``(name, size)`` of each parameter block, in order."""
        return (
            ("lengths", 2 * self.phase_count),
            ("max_velocity", 2),
            ("max_acceleration", 2),
            ("max_jerk", 2),
            ("emergency", 2),
            ("separation", 1),
            ("braking", 2),
            ("start", 2),
            ("goal", 2),
            ("fractions", self.phase_count * self.intervals),
        )

    @property
    def size(self) -> int:
        """Number of parameters."""
        return sum(size for _, size in self.fields)

    @property
    def dimensions(self) -> tuple[np.ndarray, np.ndarray]:
        """Powers of length and of time of each parameter, shape (size,) each."""
        powers = {
            "lengths": (1, 0),
            "max_velocity": (1, -1),
            "max_acceleration": (1, -2),
            "max_jerk": (1, -3),
            "emergency": (1, -2),
            "separation": (1, 0),
            "start": (1, 0),
            "goal": (1, 0),
            "fractions": (0, 0),
        }
        length: list[int] = []
        time: list[int] = []
        for name, size in self.fields:
            if name == "braking":  # the clearance (m) and the margin per squared second (m/s²)
                length += [1, 1]
                time += [0, -2]
            else:
                length += [powers[name][0]] * size
                time += [powers[name][1]] * size
        return np.array(length), np.array(time)

    def split(self, vector) -> dict:
        """The blocks of a parameter vector (symbolic or numeric) by name."""
        blocks, offset = {}, 0
        for name, size in self.fields:
            blocks[name] = vector[offset : offset + size]
            offset += size
        return blocks

    def pack(self, **values) -> np.ndarray:
        """The parameter vector from blocks given by name (each of its block's size)."""
        parts = []
        for name, size in self.fields:
            block = np.atleast_1d(np.asarray(values.pop(name), dtype=float))
            if block.shape != (size,):
                raise ValueError(f"parameter block {name!r} must have {size} values, got {block.shape}")
            parts.append(block)
        if values:
            raise ValueError(f"unknown parameter blocks {sorted(values)!r}")
        return np.concatenate(parts)


def _bernstein_cubic(s, v, a, h):
    """Inner Bernstein coefficients of s(t) on [0, h] (the outer ones are the node values)."""
    return s + h * v / 3.0, s + 2.0 * h * v / 3.0 + h * h * a / 6.0


def _gap(nearer: int, s1, s2):
    """Separation inside a region, linear in s1, s2 (``nearer``: 0 on different legs, else the nearer one)."""
    if nearer == 1:
        return s2 - s1
    if nearer == 2:
        return s1 - s2
    return s1 + s2


@dataclass(frozen=True, slots=True)
class _StageFunction:
    """One kind of control interval as a CasADi function, with the bounds of its path constraints."""

    function: object  # casadi.Function (x, w, fraction, limits) -> (next 6 states, path, between, cost)
    path_bounds: tuple[np.ndarray, np.ndarray]
    between_bounds: tuple[np.ndarray, np.ndarray]


def _stacked(terms):
    import casadi as ca

    expression = ca.vertcat(*[t[0] for t in terms]) if terms else ca.SX(0, 1)
    return expression, (np.array([t[1] for t in terms]), np.array([t[2] for t in terms]))


def _interior_state(s, v, a, jerk, tau):
    """``(s, v, a)`` a time ``tau`` into an interval of constant ``jerk`` from ``(s, v, a)``."""
    return (
        s + tau * (v + tau * (a / 2.0 + tau * jerk / 6.0)),
        v + tau * (a + tau * jerk / 2.0),
        a + tau * jerk,
    )


@functools.lru_cache(maxsize=256)
def _stage_function(
    kind: PhaseKind,
    *,
    phase_end: bool,
    path: bool,
    between: bool,
    braking: bool = False,
    part: int = 0,
    part_end: bool = False,
) -> _StageFunction:
    """The interval function of one kind of stage, built once and inlined into every NLP.

    Inputs: ``x`` (8,) the node state, ``w`` (2,) jerk / max jerk, ``fraction``
    the interval's share of the segment duration, ``limits`` (13,) the two leg
    lengths, max velocities, accelerations, jerks, emergency decelerations, the
    separation and the braking rule's clearance and curvature margin (all in the
    problem's units, :mod:`~.units`). Outputs: the exactly integrated next state (6,) (at a
    ``phase_end``, ``v`` and ``a`` of the vehicle that switches negated: it
    enters its new leg), the node constraints, the between-node (Bernstein)
    constraints and the jerk regularization.

    With ``braking``, the braking rule
    (:mod:`~.braking`) joins the node constraints (``path``) and, at
    :data:`~.braking.BRAKING_SAMPLES` inside the interval, the between-node
    ones (``between``), each with the clearance plus the curvature margin times the
    squared interval. At a ``part_end`` the reversing vehicle ends the
    interval at rest at its turning point, the state ``c``.
    """
    import casadi as ca

    x, w, fraction, limits = ca.SX.sym("x", STATE_SIZE), ca.SX.sym("w", 2), ca.SX.sym("f"), ca.SX.sym("q", 13)
    lengths, v_max, a_max, j_max = limits[0:2], limits[2:4], limits[4:6], limits[6:8]
    emergency, separation = limits[8:10], limits[10]
    clearance, curvature = limits[11], limits[12]
    h = x[DURATION] * fraction
    following, cost = [], 0
    path_terms, between_terms = [], []  # (expression, low, high)
    inner: list[list] = [[], []]
    reversing = kind.reversing if braking else -1
    for vehicle in range(2):
        s, v, a = x[3 * vehicle], x[3 * vehicle + 1], x[3 * vehicle + 2]
        jerk = j_max[vehicle] * w[vehicle]
        # exact integration of constant jerk over h
        s_next, v_next, a_next = _interior_state(s, v, a, jerk, h)
        if part_end and vehicle == reversing:  # it turns back here, at rest, at c or beyond
            path_terms += [(v_next / v_max[vehicle], 0.0, 0.0), (s_next - x[DEPTH], 0.0, np.inf)]
        if phase_end and kind.switching == vehicle:
            v_next, a_next = -v_next, -a_next
        following += [s_next, v_next, a_next]
        if kind.parked[vehicle]:
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
        path_terms.append((_gap(kind.nearer, x[0], x[3]) - separation, 0.0, np.inf))
    if inner[0] and inner[1]:
        for c_first, c_second in zip(inner[0], inner[1], strict=True):
            between_terms.append((_gap(kind.nearer, c_first, c_second) - separation, 0.0, np.inf))
    elif inner[0] or inner[1]:  # the other vehicle is parked at the junction (s = 0)
        between_terms += [(c - separation, 0.0, np.inf) for c in inner[0] or inner[1]]
    if braking:
        margin = clearance + curvature * h * h

        def rule(tau):
            symbols = []
            for vehicle in range(2):
                jerk = j_max[vehicle] * w[vehicle]
                state = _interior_state(x[3 * vehicle], x[3 * vehicle + 1], x[3 * vehicle + 2], jerk, tau)
                limits_of = (v_max[vehicle], a_max[vehicle], j_max[vehicle], emergency[vehicle])
                symbols.append(VehicleSymbols(*state, *limits_of))
            terms = braking_terms(kind, part, (symbols[0], symbols[1]), x[DEPTH], separation, margin)
            return [(term, 0.0, np.inf) for term in terms]

        if path:
            path_terms += rule(0.0)
        if between:
            for share in BRAKING_SAMPLES:
                between_terms += rule(share * h)
    path_expression, path_bounds = _stacked(path_terms)
    between_expression, between_bounds = _stacked(between_terms)
    function = ca.Function(
        "trajgen_stage",
        [x, w, fraction, limits],
        [ca.vertcat(*following), path_expression, between_expression, cost],
    )
    return _StageFunction(function, path_bounds, between_bounds)


@dataclass(frozen=True, slots=True)
class Transcription:
    """The parametric NLP of one shape, ready for ``casadi.nlpsol``.

    Attributes
    ----------
    nlp : dict
        ``x``, ``p``, ``f``, ``g`` (CasADi SX).
    bounds : dict of str to ndarray
        ``lbx``, ``ubx``, ``lbg``, ``ubg``.
    equality : tuple of bool
        Which constraints are equalities (fatrop's structure detection needs it).
    size : int
        Number of variables.
    """

    nlp: dict
    bounds: dict
    equality: tuple[bool, ...]
    size: int


class _Builder:
    """Accumulates variables, bounds, constraints and the objective, stage by stage."""

    def __init__(self, shape: NlpShape) -> None:
        import casadi as ca

        self.ca = ca
        self.shape = shape
        self.variables: list = []
        self.lower: list[float] = []
        self.upper: list[float] = []
        self.constraints: list = []
        self.g_lower: list[float] = []
        self.g_upper: list[float] = []
        self.equality: list[bool] = []
        self.objective = 0

    def constrain(self, expression, low, high) -> None:
        size = int(expression.numel())
        low, high = np.broadcast_to(low, size), np.broadcast_to(high, size)
        self.constraints.append(expression)
        self.g_lower.extend(low)
        self.g_upper.extend(high)
        self.equality.extend(low == high)

    def state(self, name: str, phase: int, pinned: tuple[int, ...] = ()):
        """A node state of ``phase``; ``pinned`` vehicles' ``s`` is fixed by an equality: no bound on it."""
        x = self.ca.SX.sym(name, STATE_SIZE)
        low, high = [-np.inf] * STATE_SIZE, [np.inf] * STATE_SIZE
        kind = self.shape.kinds[phase]
        for vehicle in range(2):
            if kind.parked[vehicle]:  # at the junction for the whole phase
                low[3 * vehicle : 3 * vehicle + 3] = [0.0, 0.0, 0.0]
                high[3 * vehicle : 3 * vehicle + 3] = [0.0, 0.0, 0.0]
            elif vehicle not in pinned:
                low[3 * vehicle] = 0.0
        low[DURATION] = MIN_SEGMENT
        self.variables.append(x)
        self.lower.extend(low)
        self.upper.extend(high)
        return x

    def at_rest(self, x, phase: int, positions) -> None:
        for vehicle in range(2):
            if not self.shape.kinds[phase].parked[vehicle]:
                self.constrain(x[3 * vehicle] - positions[vehicle], 0.0, 0.0)
                self.constrain(x[3 * vehicle + 1 : 3 * vehicle + 3], 0.0, 0.0)

    def stage(self, stage: Stage, x, parameters: dict):
        """Add one control interval from node ``x``; returns the next node."""
        ca, kinds = self.ca, self.shape.kinds
        kind = kinds[stage.phase]
        u = ca.SX.sym(f"u{stage.phase}_{stage.interval}", stage.control_size)
        self.variables.append(u)
        extra_low = ([MIN_SEGMENT] if stage.new_segment else []) + ([-np.inf] if stage.new_depth else [])
        self.lower.extend([-1.0, -1.0, *extra_low])
        self.upper.extend([1.0, 1.0] + [np.inf] * len(extra_low))
        # The first and last intervals need no between-node bounds: from or to rest under constant
        # jerk, s, v and the gap there are monotone (all of the form c + d t^3), so the node values
        # bound them. Stating them anyway would tie inequalities to the rest equalities.
        function = _stage_function(
            kind,
            phase_end=stage.phase_end,
            path=not stage.first,
            between=not (stage.first or stage.last),
            braking=self.shape.braking,
            part=stage.part,
            part_end=stage.part_end,
        )
        lengths = parameters["lengths"][2 * stage.phase : 2 * stage.phase + 2]
        fraction = parameters["fractions"][stage.phase * self.shape.intervals + stage.interval]
        limits = ca.vertcat(
            lengths,
            parameters["max_velocity"],
            parameters["max_acceleration"],
            parameters["max_jerk"],
            parameters["emergency"],
            parameters["separation"],
            parameters["braking"],
        )
        following, node_path, between, cost = function.function(x, u[:2], fraction, limits)
        next_phase = stage.phase + 1 if stage.phase_end else stage.phase
        pinned = (kind.switching,) if stage.phase_end else (0, 1) if stage.last else ()
        x_next = self.state(f"x{stage.phase}_{stage.interval + 1}", next_phase, pinned)
        duration = u[2] if stage.new_segment else x[DURATION]
        depth = u[stage.control_size - 1] if stage.new_depth else x[DEPTH]
        self.constrain(x_next - ca.vertcat(following, duration, depth), 0.0, 0.0)
        if stage.interval == 0 and stage.phase > 0:  # the vehicle that changed leg is at the junction
            self.constrain(x[3 * kinds[stage.phase - 1].switching], 0.0, 0.0)
        if stage.first:  # rest at the start, which the planner has checked: no node constraints
            self.at_rest(x, stage.phase, parameters["start"])
            if not self.shape.reset_depth(0):  # no reversal in the first phase: c starts at 0
                self.constrain(x[DEPTH], 0.0, 0.0)
        if node_path.numel():
            self.constrain(node_path, *function.path_bounds)
        if between.numel():
            self.constrain(between, *function.between_bounds)
        self.objective += cost + (u[2] if stage.new_segment else 0)
        return x_next


def transcribe(shape: NlpShape) -> Transcription:
    """Build the parametric NLP of a region-sequence shape, stage by stage."""
    builder = _Builder(shape)
    ca = builder.ca
    layout = ParameterLayout(shape.phase_count, shape.intervals)
    symbols = ca.SX.sym("p", layout.size)
    parameters = layout.split(symbols)
    x = builder.state("x0", 0, (0, 1))
    builder.objective += x[DURATION]
    for stage in stages(shape):
        x = builder.stage(stage, x, parameters)
    builder.at_rest(x, shape.phase_count - 1, parameters["goal"])  # checked by the planner
    nlp = {
        "x": ca.vertcat(*builder.variables),
        "p": symbols,
        "f": builder.objective,
        "g": ca.vertcat(*builder.constraints),
    }
    bounds = {
        "lbx": np.array(builder.lower, dtype=float),
        "ubx": np.array(builder.upper, dtype=float),
        "lbg": np.array(builder.g_lower, dtype=float),
        "ubg": np.array(builder.g_upper, dtype=float),
    }
    return Transcription(nlp, bounds, tuple(bool(e) for e in builder.equality), int(nlp["x"].numel()))
