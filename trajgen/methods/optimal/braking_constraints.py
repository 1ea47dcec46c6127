"""The braking rule as constraints of the optimal-control NLP, phase by phase in leg coordinates.

A plan meant for execution obeys the braking rule (:mod:`trajgen.verification.braking_rule`):
at every instant each vehicle that follows at a conflict can still come to
rest, under its service braking, short of every position at which it would
meet a position where its leader could still come to rest (from the leader's
earliest rest point, under its emergency deceleration, onwards). This module
states that rule inside one phase of the NLP, where each vehicle stays on one
leg with state ``(s, v, a)`` (``s`` metres from the junction, ``v`` and ``a``
positive outward). Every expression is CasADi ``SX``.

Points of one vehicle (leg coordinates, metres)
-----------------------------------------------
* **Earliest rest** ``R = s + v |v| / (2 E)`` (``E`` its emergency
  deceleration): :func:`~trajgen.model.coordination.earliest_rest`.
* **Service stop**: ``lo = s - D(-v, b_in)`` moving inward and
  ``hi = s + D(v, b_out)`` moving outward, ``D`` the bound of
  :func:`~trajgen.model.coordination.stopping_distance` (with the speed and ``b``,
  a smooth upper bound of the acceleration in the direction of travel, when
  positive; ``D`` grows with both). ``lo`` of a vehicle moving outward is
  ``s``: its stop lies outward.
* **Stop past a reversal**: a vehicle moving outward that turns back at
  ``c`` and whose service stop would carry it past ``c`` ends it, in travel,
  as far back from ``c`` as it overshoots: at ``2 c - hi``.

Roles from the route
--------------------
Who follows whom depends on which way the vehicles move. Each phase fixes it
(:class:`~.phases.Motion`, :func:`~.phases.phase_motions`): the vehicle ``w``
that passes the junction at the phase end moves inward; the other, ``o``,
outward, inward, or outward in the phase's first part and inward in its
second (it makes room for ``w`` and comes back; its turning point ``c`` is a
state of the NLP, tied to its position at the end of the first part). These
directions choose the roles only: the NLP does not bound the velocity's sign
(such bounds made fatrop 1.1.8 loop forever), so each point below is taken for
either direction of travel, and the verifier judges the result:

* ``o`` moving outward leads (it passed the junction first, or makes room):
  ``w``'s service stop comes no nearer to any point where ``o`` can still
  rest than ``d``: ``λ1(lo_w) + R_o >= d`` (``λ1``: a smooth lower bound of
  ``max(0, x)``, exact for ``x >= 0``: a stop carried past the junction
  comes no nearer than the junction). If ``o`` turns back in this phase, the
  part of its service stop past its turning point follows ``w``:
  ``λ0(-R_w) + 2 c - hi_o >= d``.
* ``o`` moving inward follows ``w`` through the junction: while ``w``'s
  earliest rest is short of the junction, ``w`` may still rest *at* the
  junction, so ``o`` stops ``d`` short of it; once it lies ``x = -R_w`` past
  it, on a leg other than ``o``'s, ``d - x`` is enough:
  ``λ0(-R_w) + lo_o >= d`` (``λ0``: a smooth lower bound of ``max(0, x)``,
  exactly 0 for ``x <= 0``).

On a **shared leg** (gap ``s_far - s_near``) the far vehicle leads outward
and the near one inward: ``R_far - hi_near >= d`` and
``lo_far - R_near >= d``, both always (the one that does not apply is implied
by the other unless one vehicle is much the faster). In the **last phase**
nobody passes the junction: ``λ1(lo_j) + R_i >= d`` for both orders. With a
vehicle **parked** at the junction, the mover's inward stop keeps
``lo_m >= d``. Where a phase leaves a direction free (shared legs, the last
phase), ``lo`` and ``hi`` are taken with smooth upper bounds of ``max(∓v, 0)``.

Between mesh points
-------------------
The verifier checks the rule at every instant, the NLP at a few: each node and
:data:`BRAKING_SAMPLES` inside each interval, each with a margin that grows
with the square of the interval (the constraints' curvature in time):
``μ = BRAKING_MARGIN + BRAKING_CURVATURE h²``.
"""

from __future__ import annotations

from trajgen.methods.optimal.phases import NO_SWITCH, Motion, PhaseKind

__all__ = [
    "BRAKING_CURVATURE",
    "BRAKING_MARGIN",
    "BRAKING_SAMPLES",
    "VehicleSymbols",
    "braking_terms",
    "direction",
    "service_distance",
]

#: Interior points of each interval at which the rule is stated, as fractions of the interval.
BRAKING_SAMPLES = (1.0 / 3.0, 2.0 / 3.0)
#: Clearance above the separation every braking constraint keeps, metres.
BRAKING_MARGIN = 1e-6
#: Margin per squared second of the interval (m/s²): covers the constraints' sag between the samples.
BRAKING_CURVATURE = 0.05
#: Width of the smooth ``max(x, 0)`` bounds: speed (share of the max velocity) and acceleration (of max).
_SPEED_WIDTH = 1e-2
_ACCELERATION_WIDTH = 1e-2
#: Width of ``λ0``, ``λ1`` (share of the separation).
_KINK_WIDTH = 0.05


class VehicleSymbols:
    """One vehicle's symbols at one instant: leg state and limits (CasADi SX).

    Parameters
    ----------
    s, v, a : SX
        Distance from the junction (m), velocity and acceleration (positive outward; m/s, m/s²).
    a_max, j_max, emergency : SX
        Its max acceleration (m/s²), max jerk (m/s³) and emergency deceleration (m/s²).
    v_max : SX
        Its max velocity, m/s (scales the smooth bounds).
    """

    __slots__ = ("a", "a_max", "emergency", "j_max", "s", "v", "v_max")

    def __init__(self, s, v, a, v_max, a_max, j_max, emergency) -> None:
        self.s, self.v, self.a = s, v, a
        self.v_max, self.a_max, self.j_max, self.emergency = v_max, a_max, j_max, emergency


def direction(kind: PhaseKind, vehicle: int, part: int) -> int:
    """Which way ``vehicle`` moves in ``part`` of a phase of ``kind``: +1 outward, -1 inward, 0 free."""
    motion = kind.motion[vehicle]
    if motion is Motion.OUTWARD or (motion is Motion.REVERSING and part == 0):
        return 1
    if motion is Motion.INWARD or (motion is Motion.REVERSING and part == 1):
        return -1
    return 0


def _positive_part(ca, x, width):
    """A smooth upper bound of ``max(x, 0)``, within ``width / 2`` of it."""
    return 0.5 * (x + ca.sqrt(x * x + width * width))


def _lambda0(ca, x, width):
    """Lower bound of ``max(0, x)``, exactly 0 for ``x <= 0`` (C1; ``x - width/2`` beyond ``width``)."""
    inside = ca.fmin(ca.fmax(x, 0.0), width)
    return inside * inside / (2.0 * width) + ca.fmax(x - width, 0.0)


def _lambda1(ca, x, width):
    """Lower bound of ``max(0, x)``, exactly ``x`` for ``x >= 0`` (C1; ``-width/2`` below ``-width``)."""
    inside = ca.fmin(ca.fmax(x, -width), 0.0)
    return ca.fmax(x, 0.0) + inside + inside * inside / (2.0 * width)


def service_distance(speed, push, a_max, j_max):
    """The stopping-distance bound of :func:`~trajgen.model.coordination.stopping_distance`, metres.

    ``speed`` (m/s) and ``push`` (the acceleration in the direction of travel, m/s²) are taken
    as given, both >= 0: upper bounds of the two give an upper bound of the distance.
    """
    ramp = speed * push / j_max + push**3 / (3.0 * j_max * j_max)
    peak = speed + push * push / (2.0 * j_max)
    return ramp + peak * peak / (2.0 * a_max) + peak * a_max / (2.0 * j_max)


def _earliest_rest(ca, vehicle: VehicleSymbols, way: int):
    """Where the vehicle can be at rest earliest, leg coordinates (m): ``s + v |v| / (2 E)``."""
    speed_squared = vehicle.v * (vehicle.v if way > 0 else -vehicle.v if way < 0 else ca.fabs(vehicle.v))
    return vehicle.s + speed_squared / (2.0 * vehicle.emergency)


def _stop_inward(ca, vehicle: VehicleSymbols, way: int):
    """``lo``: at or inward of the inward end of the vehicle's service stop, metres."""
    if way > 0:
        return vehicle.s
    speed = -vehicle.v if way < 0 else _positive_part(ca, -vehicle.v, _SPEED_WIDTH * vehicle.v_max)
    push = _positive_part(ca, -vehicle.a, _ACCELERATION_WIDTH * vehicle.a_max)
    return vehicle.s - service_distance(speed, push, vehicle.a_max, vehicle.j_max)


def _stop_outward(ca, vehicle: VehicleSymbols, way: int):
    """``hi``: at or outward of the outward end of the vehicle's service stop, metres."""
    if way < 0:
        return vehicle.s
    speed = vehicle.v if way > 0 else _positive_part(ca, vehicle.v, _SPEED_WIDTH * vehicle.v_max)
    push = _positive_part(ca, vehicle.a, _ACCELERATION_WIDTH * vehicle.a_max)
    return vehicle.s + service_distance(speed, push, vehicle.a_max, vehicle.j_max)


def braking_terms(
    kind: PhaseKind,
    part: int,
    vehicles: tuple[VehicleSymbols, VehicleSymbols],
    depth,
    separation,
    margin,
) -> list:
    """The braking rule at one instant of a phase: expressions that must be ``>= 0``, metres.

    Parameters
    ----------
    kind : PhaseKind
        The phase: parked vehicles, shared leg, the vehicle that passes the junction at its end,
        which way each vehicle moves.
    part : int
        0 or 1: the part of the phase (a reversing vehicle moves outward in 0, inward in 1).
    vehicles : tuple of 2 VehicleSymbols
    depth : SX
        ``c``: where the phase's reversing vehicle turns, metres from the junction.
    separation : SX
        The separation the plan keeps, metres.
    margin : SX
        Clearance each constraint keeps above it, metres.
    """
    import casadi as ca

    width = _KINK_WIDTH * separation
    d = separation + margin
    ways = [direction(kind, v, part) for v in (0, 1)]
    # the points are taken for either direction of travel: the NLP does not bound the direction
    # (fatrop 1.1.8 can loop forever on such bounds), the roles below follow the planned one
    rest = [_earliest_rest(ca, vehicles[v], 0) for v in (0, 1)]
    inward = [_stop_inward(ca, vehicles[v], 0) for v in (0, 1)]
    if kind.parked[0] or kind.parked[1]:
        if kind.parked[0] and kind.parked[1]:
            return []
        mover = 1 if kind.parked[0] else 0
        return [] if ways[mover] > 0 else [inward[mover] - d]
    if kind.nearer:
        near, far = kind.nearer - 1, 2 - kind.nearer
        return [
            rest[far] - _stop_outward(ca, vehicles[near], 0) - d,  # the near one follows outward
            inward[far] - rest[near] - d,  # the far one follows inward
        ]
    if kind.switching == NO_SWITCH:
        return [_lambda1(ca, inward[j], width) + rest[1 - j] - d for j in (0, 1)]
    w, o = kind.switching, 1 - kind.switching
    terms = []
    if kind.joins:  # w enters o's leg: whatever of it passes the junction comes nearer to o
        overshoot = -_positive_part(ca, -rest[w], _SPEED_WIDTH * width)
        w_stop = inward[w]
    else:  # w enters another leg: what passes the junction comes no nearer to o than the junction
        overshoot = _lambda0(ca, -rest[w], width)
        w_stop = _lambda1(ca, inward[w], width)
    if ways[o] >= 0:  # o leads: w follows it
        terms.append(w_stop + rest[o] - d)
    if ways[o] <= 0:  # o follows w through the junction
        terms.append(overshoot + inward[o] - d)
    if kind.motion[o] is Motion.REVERSING and part == 0:  # o's stop carried past its turning point
        terms.append(overshoot + 2.0 * depth - _stop_outward(ca, vehicles[o], 0) - d)
    return terms
