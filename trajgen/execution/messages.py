"""What the executor exchanges with the vehicles and its callers: states, setpoints, commands, events.

Plain frozen values; :class:`~trajgen.execution.executor.Executor` takes
:class:`VehicleState` s each cycle and returns a :class:`Command`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from topology import JUNCTION_INDEX, StarGraph
from topology.options import Option
from trajgen.errors import InputError
from trajgen.model.schedule import check_period

__all__ = [
    "PERIOD_RANGE",
    "Command",
    "Event",
    "GoalDecision",
    "Mode",
    "Setpoint",
    "VehicleState",
    "check_measured_numbers",
    "checked_names",
    "checked_number",
    "checked_period",
    "checked_state",
]


class Mode(Option):
    """What the executor is doing."""

    FOLLOWING = "following"  #: both vehicles on the plan's clock
    RETIMING = "retiming"  #: a vehicle re-timed by Ruckig, in the plan's order
    STOPPING = "stopping"  #: both braking to rest for a new goal
    DONE = "done"  #: both vehicles at rest at their goals


@dataclass(frozen=True, slots=True)
class VehicleState:
    """A vehicle's measured state.

    Attributes
    ----------
    leg : int
        Leg index in the track's order, ``JUNCTION_INDEX`` (-1) at the junction.
    s : float
        Distance from the junction, metres.
    velocity, acceleration : float
        Along the vehicle's axis, m/s and m/s².
    """

    leg: int
    s: float
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True, slots=True)
class Setpoint:
    """A vehicle's setpoint for the end of a cycle.

    Attributes
    ----------
    axis, velocity, acceleration, jerk : float
        On the vehicle's signed axis: m, m/s, m/s², m/s³.
    leg : int
        Leg index (``JUNCTION_INDEX`` at the junction).
    s : float
        Distance from the junction, metres.
    branch : int
        The leg the vehicle takes when it next passes the junction (its own leg if it turns back there).
    """

    axis: float
    velocity: float
    acceleration: float
    jerk: float
    leg: int
    s: float
    branch: int


@dataclass(frozen=True, slots=True)
class Command:
    """What one :meth:`Executor.step` returns.

    Attributes
    ----------
    time : float
        The time the setpoints are for, seconds since the executor started.
    setpoints : tuple of Setpoint
        One per vehicle.
    mode : Mode
    braking : tuple of bool
        Whether each vehicle holds (service braking) because the braking invariant says so (empty:
        not said).
    certified : bool
        Whether the braking check passed for these setpoints.
    emergency : bool
        Every vehicle brakes as hard as it can: nothing else could be certified.
    frontiers : tuple of float
        Each vehicle's frontier this cycle, metres of its travel (``inf``: none binds it; empty: not
        said).
    """

    time: float
    setpoints: tuple[Setpoint, ...]
    mode: Mode
    braking: tuple[bool, ...] = ()
    certified: bool = True
    emergency: bool = False
    frontiers: tuple[float, ...] = ()


@dataclass(frozen=True, slots=True)
class Event:
    """Something the executor did.

    Attributes
    ----------
    time : float
        Seconds since the executor started.
    kind : str
        ``retime`` (a vehicle leaves the plan's clock), ``hold`` (the braking invariant holds a
        vehicle), ``emergency`` (both brake hard), ``goal-accepted``, ``goal-refused``, ``replan``
        (a new goal's plan), ``speed-limit``, ``done``.
    detail : str
    """

    time: float
    kind: str
    detail: str


@dataclass(frozen=True, slots=True)
class GoalDecision:
    """The executor's answer to a goal request.

    Attributes
    ----------
    accepted : bool
    reason : str
        Why it was refused (empty when accepted).
    """

    accepted: bool
    reason: str = ""


#: Shortest and longest control period, seconds.
PERIOD_RANGE = (0.002, 0.1)


def checked_period(period: object) -> float:
    """A control period within :data:`PERIOD_RANGE`, seconds.

    Raises
    ------
    InputError
        Not a finite number, or outside the range (naming both).
    """
    period = check_period(period)
    if not PERIOD_RANGE[0] <= period <= PERIOD_RANGE[1]:
        raise InputError(
            f"control period must be {PERIOD_RANGE[0]:g} to {PERIOD_RANGE[1]:g} s, got {period!r}"
        )
    return period


def checked_number(value: object, name: str, *, zero: bool = False) -> float:
    """``value`` as a float if it is a finite number > 0 (``zero``: >= 0), else InputError naming ``name``."""
    finite = isinstance(value, (int, float)) and math.isfinite(value)
    if not (finite and (value > 0.0 or (zero and value == 0))):
        raise InputError(f"{name} must be a finite number {'>=' if zero else '>'} 0, got {value!r}")
    return float(value)


def checked_names(names: object, count: int) -> tuple[str, ...]:
    """The vehicles' names as events call them: one non-empty string per vehicle (``None``: ``vehicle k``).

    Raises
    ------
    InputError
        Naming the value given and the number of vehicles.
    """
    if names is None:
        return tuple(f"vehicle {k}" for k in range(1, count + 1))
    named = isinstance(names, tuple) and all(isinstance(name, str) and name for name in names)
    if not (named and len(names) == count):
        raise InputError(f"names must be {count} non-empty strings, one per vehicle, got {names!r}")
    return names


def check_measured_numbers(state: object, number: int) -> None:
    """Refuse ``state`` unless it is a VehicleState whose numbers are finite.

    Raises
    ------
    InputError
        Not a VehicleState, or ``s``, ``velocity`` or ``acceleration`` not a finite number.
    """
    if not isinstance(state, VehicleState):
        raise InputError(f"vehicle {number} state must be a VehicleState, got {type(state).__name__}")
    for name in ("s", "velocity", "acceleration"):
        value = getattr(state, name)
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"vehicle {number} measured {name} must be a finite number, got {value!r}")


def checked_state(state: object, number: int, graph: StarGraph) -> VehicleState:
    """``state`` if it is a measured state on ``graph``, clamped to its leg's end by round-off (1 µm).

    Raises
    ------
    InputError
        Not a VehicleState, a number that is not finite, an unknown leg, or a position off its leg.
    """
    check_measured_numbers(state, number)
    count = graph.leg_count
    if state.leg != JUNCTION_INDEX and not 0 <= state.leg < count:
        raise InputError(
            f"vehicle {number} measured leg must be a leg index 0 to {count - 1} of the {count} legs "
            f"or {JUNCTION_INDEX} (the junction), got {state.leg!r}"
        )
    top = graph.lengths[state.leg] if state.leg != JUNCTION_INDEX else 0.0
    if state.s < 0.0 or state.s > top + 1e-6:
        raise InputError(
            f"vehicle {number} measured s {state.s!r} m is off leg {state.leg!r}: expected 0 to {top!r} m"
        )
    if state.s > top:
        return VehicleState(state.leg, top, state.velocity, state.acceleration)
    return state
