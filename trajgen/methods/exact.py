"""The ``exact`` method: the planner's route followed exactly, one straight piece at a time.

Along each maximal straight piece of the route in the plane of the two signed
axes, both vehicles move rest to rest with the time-optimal jerk-limited
S-curve (closed form) under both vehicles' limits scaled to the piece; they
stop wherever the direction changes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from limits import Limits
from topology import Route
from trajgen.errors import InputError
from trajgen.methods.graph_timing import moves_one_at_a_time
from trajgen.model.axes import piece_maps, piece_profiles, route_axes, straight_pieces
from trajgen.model.schedule import CubicKinematics, Schedule, Section, TimingMethod, check_request

__all__ = ["Exact"]


@dataclass(frozen=True, slots=True)
class Exact(TimingMethod):
    """The route followed exactly, one straight piece at a time, rest to rest.

    Parameters
    ----------
    jerk : bool, optional
        Jerk-limited S-curves (default). ``False`` gives velocity/acceleration
        limited trapezoids, the reference that ``toppra`` is never slower than.

    Examples
    --------
    >>> from trajgen.scenario import default_scenario
    >>> scenario = default_scenario()
    >>> round(Exact().schedule(scenario.route(), scenario.limits).duration, 3)
    67.5
    """

    name: ClassVar[str] = "exact"
    description: ClassVar[str] = "the route exactly, one straight piece at a time, jerk-limited S-curves"

    jerk: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.jerk, bool):
            raise InputError(f"exact option jerk must be True or False, got {self.jerk!r}")

    @property
    def jerk_limited(self) -> bool:
        """Whether the schedules limit jerk (the ``jerk`` option)."""
        return self.jerk

    def schedule(self, route: Route, limits: Limits) -> Schedule:
        """The exact schedule of ``route`` under ``limits``."""
        check_request(route, limits)
        axes = route_axes(route)
        sections = []
        clock = 0.0
        for first, last in straight_pieces(axes.axes) or [(0, 0)]:
            profiles = piece_profiles(axes.axes[first], axes.axes[last], limits, jerk=self.jerk)
            maps = piece_maps(axes, first, last) if last > first else axes.parked
            section = Section(clock, CubicKinematics(profiles), maps)
            sections.append(section)
            clock += section.duration
        return Schedule(route, limits, self, tuple(sections), jerk_limited=self.jerk)

    def schedule_graph(self, route, limits: Limits):
        """The exact schedule of a route on a track graph: its moves one after the other, rest to rest."""
        return moves_one_at_a_time(route, limits, self, jerk=self.jerk)

    def waypoint_times(self, schedule: Schedule) -> np.ndarray:
        """Time at which an exact schedule of this method passes each route waypoint, seconds, shape (n,).

        Within a straight piece both axes move in fixed proportion, so the
        time a waypoint is passed is the time the axis of the vehicle that
        moves more reaches the waypoint's value (solved on its cubic).
        """
        axes = route_axes(schedule.route).axes
        times = np.zeros(len(axes))
        for section, (first, last) in zip(schedule.sections, straight_pieces(axes), strict=False):
            moving = int(np.argmax(np.abs(axes[last] - axes[first])))
            profile = section.kinematics.vehicles[moving]  # type: ignore[attr-defined]
            for k in range(first, last + 1):
                times[k] = section.start_time + profile.time_at(axes[k, moving])
        return times
