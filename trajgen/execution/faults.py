"""Faults a simulated plant applies to the vehicles, and their text form (``--fault SPEC``).

``stop:NAME@T+D``
    NAME brakes at its emergency deceleration at T seconds and cannot move for D seconds.
``slow:NAME@T=V``, ``slow:NAME@T+D=V``
    From T on (for D seconds), NAME's drive cannot exceed V m/s.
``lag:NAME@T=MS``
    From T on, NAME follows its setpoints MS milliseconds late (the delay builds up at half the
    rate of time, so the vehicle never runs backwards).
``jump:NAME@T=DS``
    At T, NAME's measured position is corrected by DS metres along its axis (the true position was
    off): the vehicle is DS metres further along from then on.
``goal:NAME@T=LEG:S``
    At T, a new goal for NAME is requested from the executor.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from topology import EdgePoint, Option, Position, StarGraph, TrackGraph
from topology.validation import short_repr
from trajgen.errors import InputError

__all__ = ["FAULT_RANGES", "Fault", "FaultError", "FaultKind", "parse_fault"]

#: Accepted ranges: fault time (s), stop duration (s), lag (ms).
FAULT_RANGES = {"time": (0.0, 1e5), "stop": (0.0, 3600.0), "lag": (0.0, 200.0)}

_SPEC = re.compile(r"^(?P<kind>[a-z]+):(?P<name>[^@]+)@(?P<time>[^+=]+)(?P<sep>[+=])(?P<value>.+)$")


class FaultError(InputError):
    """A fault spec that is malformed, names an unknown vehicle, or is out of range."""


class FaultKind(Option):
    """The kinds of fault the plant can apply."""

    STOP = "stop"
    SLOW = "slow"
    LAG = "lag"
    JUMP = "jump"
    GOAL = "goal"


@dataclass(frozen=True, slots=True)
class Fault:
    """One fault.

    Attributes
    ----------
    kind : FaultKind
    vehicle : int
        0 or 1.
    time : float
        When it starts, seconds.
    value : float
        ``stop``: duration, s; ``slow``: top speed, m/s; ``lag``: delay, s; ``jump``: metres; ``goal``: 0.
    goal : Position, EdgePoint (on a track graph) or None
        The requested goal (``goal`` only).
    spec : str
        The text it was parsed from.
    duration : float
        How long a ``slow`` lasts, seconds (``inf``: to the end).
    """

    kind: FaultKind
    vehicle: int
    time: float
    value: float
    goal: Position | EdgePoint | None = None
    spec: str = ""
    duration: float = math.inf

    @property
    def end(self) -> float:
        """When the fault stops acting, seconds (``inf`` if it never does; a jump or goal acts at once)."""
        if self.kind is FaultKind.STOP:
            return self.time + self.value
        if self.kind is FaultKind.SLOW:
            return self.time + self.duration
        if self.kind is FaultKind.LAG:
            return math.inf
        return self.time


def _number(text: str, what: str, spec: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise FaultError(f"fault {short_repr(spec)}: {what} {short_repr(text)} is not a number") from None
    if not math.isfinite(value):
        raise FaultError(f"fault {short_repr(spec)}: {what} must be finite, got {short_repr(text)}")
    return value


def parse_fault(
    spec: object,
    *,
    names: tuple[str, str],
    graph: StarGraph | TrackGraph,
    max_velocity: tuple[float, float],
    max_jump: float,
) -> Fault:
    """Parse one ``--fault`` spec.

    Parameters
    ----------
    spec : str
        For example ``stop:agv1@5+3``.
    names : tuple of 2 str
        The vehicles' names.
    graph : StarGraph or TrackGraph
        The track (for ``goal``: ``LEG:s`` on a junction, ``EDGE:s`` or a node on a track graph).
    max_velocity : tuple of 2 float
        The vehicles' top speeds, m/s (a ``slow`` speed must be below it).
    max_jump : float
        Largest ``|DS|`` of a ``jump``, metres: the executor's position margin.

    Raises
    ------
    FaultError
        Malformed, an unknown vehicle, or a value out of range; the message names the spec.
    """
    if not isinstance(spec, str):
        raise FaultError(f"fault spec must be a string, got {type(spec).__name__}")
    match = _SPEC.match(spec.strip())
    if match is None:
        raise FaultError(
            f"fault {short_repr(spec)} is malformed: expected KIND:NAME@T+D (stop), KIND:NAME@T=VALUE "
            "(slow, lag, jump, goal) or slow:NAME@T+D=VALUE"
        )
    try:
        kind = FaultKind.lookup(match["kind"])
    except InputError:
        raise FaultError(
            f"fault {short_repr(spec)}: unknown kind {short_repr(match['kind'])}: expected one of "
            f"{', '.join(k.value for k in FaultKind)}"
        ) from None
    name = match["name"]
    if name not in names:
        raise FaultError(
            f"fault {short_repr(spec)}: unknown vehicle {short_repr(name)}: expected one of {list(names)!r}"
        )
    vehicle = names.index(name)
    time = _number(match["time"], "time", spec)
    low, high = FAULT_RANGES["time"]
    if not low <= time <= high:
        raise FaultError(
            f"fault {short_repr(spec)}: time {time!r} s out of range: expected {low:g} to {high:g} s"
        )
    text = match["value"]
    duration = math.inf
    if kind is FaultKind.SLOW and match["sep"] == "+":
        span, equals, text = text.partition("=")
        if not equals:
            raise FaultError(f"fault {short_repr(spec)}: slow takes NAME@T=VALUE or NAME@T+D=VALUE")
        duration = _number(span, "duration", spec)
        if not duration > 0.0:
            raise FaultError(f"fault {short_repr(spec)}: slow duration {duration!r} s: expected > 0 s")
    elif (match["sep"] == "+") != (kind is FaultKind.STOP):
        expected = "NAME@T+D" if kind is FaultKind.STOP else "NAME@T=VALUE"
        raise FaultError(f"fault {short_repr(spec)}: {kind.value} takes {expected}")
    if kind is FaultKind.GOAL:
        try:
            goal = graph.point(text)
        except InputError as error:
            raise FaultError(f"fault {short_repr(spec)}: goal: {error}") from None
        return Fault(kind, vehicle, time, 0.0, goal, spec)
    value = _number(text, kind.value, spec)
    if kind is FaultKind.STOP:
        low, high = FAULT_RANGES["stop"]
        if not low < value <= high:
            raise FaultError(
                f"fault {short_repr(spec)}: stop duration {value!r} s out of range: "
                f"expected > {low:g} to {high:g} s"
            )
    elif kind is FaultKind.SLOW:
        top = max_velocity[vehicle]
        if not 0.0 < value < top:
            raise FaultError(
                f"fault {short_repr(spec)}: speed {value!r} m/s out of range: expected > 0 and below "
                f"{name}'s max_velocity {top!r} m/s"
            )
    elif kind is FaultKind.LAG:
        low, high = FAULT_RANGES["lag"]
        if not low < value <= high:
            raise FaultError(
                f"fault {short_repr(spec)}: lag {value!r} ms out of range: expected > {low:g} to {high:g} ms"
            )
        value = value / 1000.0
    elif kind is FaultKind.JUMP and not 0.0 < abs(value) <= max_jump:
        raise FaultError(
            f"fault {short_repr(spec)}: jump {value!r} m out of range: expected 0 < |DS| <= {max_jump!r} m "
            "(the executor's position margin; a larger error could break the separation unseen)"
        )
    return Fault(kind, vehicle, time, value, None, spec, duration)
