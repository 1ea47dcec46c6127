"""Schedules: the two vehicles' motion over time along a planned route (the data model).

A :class:`Schedule` is a sequence of :class:`Section` s in time. Within a
section each vehicle's *signed axis* (its odometer along its own path,
positive in the direction of its first move, decreasing when it reverses)
maps monotonically onto the track (:class:`AxisMap`), so the track position
at any time follows from the axis value. The methods that compute schedules
implement :class:`TimingMethod`; they live in :mod:`trajgen.methods`.
"""

from __future__ import annotations

import abc
import enum
import warnings
from dataclasses import InitVar, dataclass, field
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import JUNCTION_INDEX, Configuration, Position, Route, TrackGraph
from topology.indexed import track_distance
from topology.validation import finite_real
from trajgen.errors import InputError
from trajgen.lazy import RenamedAttribute
from trajgen.model.profiles import PiecewiseCubic
from trajgen.model.state import TrackState
from trajgen.model.values import ArrayValue, readonly

__all__ = [
    "AxisMap",
    "CubicKinematics",
    "FallbackReason",
    "Kinematics",
    "MethodInfo",
    "Schedule",
    "ScheduleState",
    "Section",
    "TimedSection",
    "TimingMethod",
    "check_period",
    "check_request",
    "sample_block",
    "sample_rows",
]


def check_period(period: float) -> float:
    """Return a sample period in seconds if it is finite and > 0, else raise InputError.

    Examples
    --------
    >>> check_period(0.01)
    0.01
    """
    value = finite_real(period, "sample period (seconds)", InputError)
    if value <= 0.0:
        raise InputError(f"sample period must be > 0 s, got {value!r}")
    return value


def sample_rows(duration: float, period: float) -> int:
    """Number of samples every ``period`` seconds from 0 to ``duration``, the last exactly at the end."""
    count = int(np.floor(duration / period + 1e-9))
    return count + 2 if duration - count * period > 1e-9 * max(1.0, duration) else count + 1


def sample_block(duration: float, period: float, start: int, stop: int) -> np.ndarray:
    """Sample times ``start`` to ``stop - 1`` of the grid of :func:`sample_rows`, seconds."""
    rows = sample_rows(duration, period)
    times = np.arange(start, min(stop, rows)) * period
    if times.size and min(stop, rows) == rows:
        times[-1] = duration  # the last sample is the goal
    return times


def check_request(route: object, limits: object) -> tuple[Route, Limits]:
    """Return ``(route, limits)`` if a timing method can serve them, else raise InputError.

    The route must be a :class:`~topology.Route` planned for at least the
    separation the limits ask for.
    """
    if not isinstance(route, Route):
        raise InputError(f"route must be a topology.Route, got {type(route).__name__}")
    if not isinstance(limits, Limits):
        raise InputError(f"limits must be a limits.Limits, got {type(limits).__name__}")
    if route.min_separation < limits.min_separation:
        raise InputError(
            f"the route was planned for a min_separation of {route.min_separation!r} m but the limits ask "
            f"{limits.min_separation!r} m: plan it with plan(..., min_separation={limits.min_separation!r})"
        )
    return route, limits


class FallbackReason(enum.Enum):
    """Why a method returned the ``exact`` schedule in place of its own."""

    SOLVER_FAILED = "solver-failed"  #: no solver converged
    VERIFICATION_FAILED = "verification-failed"  #: the solution failed the verifier
    SETUP_FAILED = "setup-failed"  #: the problem could not be set up (initial guess, parameters)
    TIME_LIMIT = "time-limit"  #: a solver did not come back within the method's time limit (a safety stop)
    TIME_BUDGET = "time-limit"  #: deprecated name of :attr:`TIME_LIMIT` (0.7)


class MethodInfo(abc.ABC):
    """Diagnostics a timing method attaches to its schedules."""

    __slots__ = ()

    @abc.abstractmethod
    def summary(self) -> dict:
        """JSON-ready diagnostics."""


class TimingMethod(abc.ABC):
    """Interface of the timing methods: turn ``(route, limits)`` into a :class:`Schedule`.

    Implementations are frozen dataclasses that carry their own options; the
    registry :data:`trajgen.methods.METHODS` lists them.
    """

    __slots__ = ()

    #: Name of the method (``--method NAME`` on the command line).
    name: ClassVar[str]
    #: One line for the help texts.
    description: ClassVar[str]
    #: Deprecated name of ``description`` (0.7).
    summary = RenamedAttribute("description", "0.7")

    @property
    @abc.abstractmethod
    def jerk_limited(self) -> bool:
        """Whether the method's schedules limit jerk."""

    @abc.abstractmethod
    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """Time-parameterize ``route`` under ``limits`` (unverified: see :func:`trajgen.certify`)."""

    def schedule_graph(self, route, limits: Limits):
        """Time-parameterize a route on a track graph (:class:`topology.GraphRoute`) under ``limits``.

        Returns a :class:`~trajgen.model.graph_schedule.GraphSchedule` (unverified: see
        :func:`trajgen.certify`).

        Raises
        ------
        InputError
            The method does not time track graphs yet.
        """
        raise InputError(
            f"method {self.name!r} does not time a track graph yet: expected --method exact (docs/graphs.md)"
        )

    @property
    def plans_for_execution(self) -> bool:
        """Whether its schedules obey the braking rule (:mod:`~trajgen.verification.braking_rule`).

        ``exact`` and ``toppra`` plans always do; ``optimal`` ones with ``braking_rule=True``.
        """
        return True

    def for_execution(self) -> TimingMethod:
        """The method as it plans for the online executor (its plans obey the braking rule)."""
        return self

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True, eq=False)
class AxisMap(ArrayValue):
    """Where one vehicle is on the track as a function of its signed axis, within one section.

    Sub-ranges of the axis, each on one leg, in the order the vehicle drives
    them; ``s = s_start + outward * (axis - axis_start)``.

    Attributes
    ----------
    axis_start, axis_end : ndarray, shape (r,)
        Axis at the start and end of each sub-range, metres.
    legs : ndarray of int, shape (r,)
        Leg index (``JUNCTION_INDEX`` at the junction).
    s_start : ndarray, shape (r,)
        Distance from the junction at ``axis_start``, metres.
    outward : ndarray of int, shape (r,)
        ``ds/daxis``: +1, -1, or 0 when the vehicle does not move.
    """

    axis_start: np.ndarray
    axis_end: np.ndarray
    legs: np.ndarray
    s_start: np.ndarray
    outward: np.ndarray

    def __post_init__(self) -> None:
        for name, dtype in (
            ("axis_start", float),
            ("axis_end", float),
            ("legs", int),
            ("s_start", float),
            ("outward", int),
        ):
            object.__setattr__(self, name, readonly(np.atleast_1d(getattr(self, name)), dtype))
            if dtype is float and not np.all(np.isfinite(getattr(self, name))):
                raise InputError(f"axis map: {name} holds a non-finite value: expected finite numbers")

    @classmethod
    def parked(cls, axis: float, leg: int, s: float) -> AxisMap:
        """A vehicle that does not move in the section, at axis value ``axis``."""
        return cls(np.array([axis]), np.array([axis]), np.array([leg]), np.array([s]), np.array([0]))

    def locate(self, axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Leg index and distance from the junction for axis values, shape (n,) each.

        A value outside every sub-range (round-off at the ends) takes the
        nearest sub-range; ``s`` is clipped at 0 (the junction). With a single
        sub-range the vehicle stays on one leg, where the affine map holds for
        every axis value (it may drive back and forth).
        """
        axis = np.asarray(axis, dtype=float)
        if len(self.legs) == 1:
            s = np.maximum(self.s_start[0] + self.outward[0] * (axis - self.axis_start[0]), 0.0)
            return np.where(s > 0.0, self.legs[0], JUNCTION_INDEX), s
        low = np.minimum(self.axis_start, self.axis_end)
        high = np.maximum(self.axis_start, self.axis_end)
        gap = np.maximum(low[:, None] - axis[None, :], 0.0) + np.maximum(axis[None, :] - high[:, None], 0.0)
        r = np.argmin(gap, axis=0)
        s = self.s_start[r] + self.outward[r] * (np.clip(axis, low[r], high[r]) - self.axis_start[r])
        s = np.maximum(s, 0.0)
        legs = np.where(s > 0.0, self.legs[r], JUNCTION_INDEX)
        return legs, s

    def flipped(self) -> AxisMap:
        """The same map for the axis of opposite sign."""
        return AxisMap(-self.axis_start, -self.axis_end, self.legs, self.s_start, -self.outward)


class Kinematics(abc.ABC):
    """Interface of a section's motion: both vehicles' signed-axis kinematics over local time."""

    __slots__ = ()

    @property
    @abc.abstractmethod
    def duration(self) -> float:
        """Length of the section, seconds."""

    @abc.abstractmethod
    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """Axis, velocity, acceleration, jerk of both vehicles; shape (2, 4, n). ``t`` in [0, duration]."""


@dataclass(frozen=True, slots=True)
class CubicKinematics(Kinematics):
    """Every vehicle as a piecewise cubic (constant jerk between breakpoints).

    Attributes
    ----------
    vehicles : tuple of PiecewiseCubic
        Each vehicle's signed axis (its travel, on a track graph) over the section's local time.
    """

    vehicles: tuple[PiecewiseCubic, ...]

    @property
    def duration(self) -> float:
        """Length of the section, seconds: the latest of the vehicles' ends."""
        return max(profile.duration for profile in self.vehicles)

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """Axis, velocity, acceleration, jerk of every vehicle; shape (m, 4, n)."""
        return np.stack([profile.evaluate(t) for profile in self.vehicles])


@dataclass(frozen=True, slots=True)
class TimedSection:
    """A stretch of a schedule in time: both vehicles' motion over the section's local time.

    Attributes
    ----------
    start_time : float
        Seconds from the start of the schedule.
    kinematics : Kinematics
        Motion of both vehicles (their signed axes on a junction, their travel on a track graph).
    """

    start_time: float
    kinematics: Kinematics

    def __post_init__(self) -> None:
        finite_real(self.start_time, "section start_time (seconds)", InputError)

    @property
    def duration(self) -> float:
        """Seconds."""
        return self.kinematics.duration


@dataclass(frozen=True, slots=True)
class Section(TimedSection):
    """A stretch of a schedule in which each vehicle's axis maps monotonically onto the track.

    Attributes
    ----------
    start_time : float
        Seconds from the start of the schedule.
    kinematics : Kinematics
        Motion of both signed axes over the section's local time.
    maps : tuple of 2 AxisMap
        Axis -> track position, per vehicle.
    """

    maps: tuple[AxisMap, AxisMap]


#: The states a junction's schedule gives: the one :class:`~trajgen.model.state.TrackState` of every
#: track (its legs the edges of its track graph; before issue 49 a type of its own, with ``leg``).
ScheduleState = TrackState


@dataclass(frozen=True, slots=True)
class Schedule:
    """A timed motion of both vehicles along a route.

    Attributes
    ----------
    route : Route
        The planner's route (its homotopy class is the schedule's).
    limits : Limits
        The vehicle limits and separation it was computed for.
    method : TimingMethod
        The method, with its options, that computed the motion.
    sections : tuple of Section
        Consecutive in time, the first at t = 0.
    jerk_limited : bool
        Whether the motion limits jerk (``toppra`` does not).
    notes : tuple of str
        What the method did that a user should know (e.g. corners rounded).
    fallback_reason : FallbackReason or None
        Set when the requested method could not deliver and this is the
        ``exact`` schedule in its place; ``notes`` say more.
    info : MethodInfo or None
        Method diagnostics (e.g. :class:`trajgen.methods.optimal.OptimalInfo`).
    smoothness : int or None
        How many derivatives of position are continuous and zero at the start
        and goal (0: position only, as a linearly interpolated table; 1: also
        velocity; 2: also acceleration). ``None``: 2 if ``jerk_limited``, else 1;
        the attribute is always the number.
    end_tolerance : float or None
        How far from the route's start and goal the motion may begin and end,
        and past a leg's end it may reach, metres (``None``: the verifier's
        1e-9 m and 1e-6 m; PLC tables: 1e-6 m; a generic CSV read back: 1e-5 m).
        When set (a table as a controller interpolates it), continuity from
        piece to piece is held to 1e-6 of each limit (1e-6 m for positions);
        ``None`` (a method's schedule) holds it to round-off.
    checked_limits : int or None
        How many derivatives (1: velocity, 2: acceleration, 3: jerk) the
        verifier checks against the limits in closed form. ``None``: velocity
        and acceleration, and jerk if ``jerk_limited``; a table read back
        defines fewer (:mod:`trajgen.export.plc.tables` checks the rest from its points).
    """

    route: Route
    limits: Limits
    method: TimingMethod
    sections: tuple[Section, ...]
    jerk_limited: bool
    notes: tuple[str, ...] = ()
    fallback_reason: FallbackReason | None = None
    info: MethodInfo | None = field(default=None, compare=False)
    smoothness: int | None = None
    end_tolerance: float | None = None
    checked_limits: int | None = None
    continuity: InitVar[int | None] = None

    def __post_init__(self, continuity: int | None) -> None:
        object.__setattr__(self, "sections", tuple(self.sections))
        object.__setattr__(self, "notes", tuple(self.notes))
        if continuity is not None:
            warnings.warn(
                "Schedule(continuity=...) is deprecated since trajgen 0.7: use smoothness=",
                DeprecationWarning,
                stacklevel=3,
            )
            object.__setattr__(self, "smoothness", continuity)
        if self.smoothness is None:
            object.__setattr__(self, "smoothness", 2 if self.jerk_limited else 1)

    def __repr__(self) -> str:
        """One line: method, makespan, sections, jerk, class (the arrays stay out of it)."""
        jerk = "jerk-limited" if self.jerk_limited else "jerk not limited"
        fallback = "" if self.fallback_reason is None else f", fell back ({self.fallback_reason.value})"
        return (
            f"<Schedule: {self.method.name}, {self.duration:.3f} s in {len(self.sections)} section(s), "
            f"{jerk}, {self.route.way_round.value}{fallback}>"
        )

    @property
    def track(self) -> TrackGraph:
        """The track the schedule is on, as a track graph (its route's junction at the door).

        The junction is its node ``O``, each leg an edge from it (:meth:`~topology.StarGraph.track_graph`);
        :meth:`state` places the vehicles on it. ``route.graph`` is the junction itself.
        """
        return self.route.graph.track_graph()

    @property
    def duration(self) -> float:
        """Makespan: time until both vehicles are at rest at the goal, seconds."""
        last = self.sections[-1]
        return last.start_time + last.duration

    def state(self, t) -> TrackState:
        """States of both vehicles at times ``t`` (seconds, clipped to [0, duration]).

        Parameters
        ----------
        t : float or array_like, shape (n,)
        """
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        # section starts are read from the sections each time: no cached copy can disagree with them
        starts = np.array([section.start_time for section in self.sections])
        index = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.sections) - 1)
        kin = np.zeros((2, 4, t.size))
        leg = np.zeros((2, t.size), dtype=int)
        s = np.zeros((2, t.size))
        for k, section in enumerate(self.sections):
            mask = index == k
            if not mask.any():
                continue
            local = np.clip(t[mask] - section.start_time, 0.0, section.duration)
            if k == len(self.sections) - 1:  # the goal is the end of the last section, not a round-off before
                local[t[mask] >= self.duration] = section.duration
            values = section.kinematics.evaluate(local)
            kin[:, :, mask] = values
            for vehicle in range(2):
                leg[vehicle, mask], s[vehicle, mask] = section.maps[vehicle].locate(values[vehicle, 0])
        for array in (t, kin, leg, s):  # freeze the buffers, so the state's views are safe as they are
            array.flags.writeable = False
        edge = np.where(leg == JUNCTION_INDEX, 0, leg)  # the junction: s = 0 on the first leg
        return TrackState(t, kin[:, 0], kin[:, 1], kin[:, 2], kin[:, 3], edge, s)

    def sample(self, period: float) -> TrackState:
        """States every ``period`` seconds from t = 0, plus a last sample exactly at the goal."""
        period = check_period(period)
        return self.state(sample_block(self.duration, period, 0, sample_rows(self.duration, period)))

    def distances(self, state: TrackState) -> np.ndarray:
        """Track distance between the vehicles in ``state`` (this schedule's, at some times), metres, (n,)."""
        return track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])

    def configuration_at(self, t: float) -> Configuration:
        """The two vehicles' positions at time ``t`` (seconds) as a Configuration."""
        state = self.state(t)
        graph = self.route.graph
        positions = []
        for v in range(2):
            leg, s = int(state.leg[v, 0]), float(state.s[v, 0])
            if leg != JUNCTION_INDEX and 0.0 < s - graph.lengths[leg] <= 1e-6:
                s = graph.lengths[leg]  # round-off at a leg's end; larger overruns still raise
            positions.append(Position(graph.names[leg] if leg != JUNCTION_INDEX else None, s))
        return Configuration(*positions)
