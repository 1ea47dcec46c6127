"""Each vehicle's path along a route as a function of the distance it has travelled.

The executor works in *travel* coordinates: ``p`` is the distance a vehicle
has driven along its own path of the route (``0 <= p <= length``), so both
vehicles' progress is monotone and a plan is a monotone curve in the
``(p1, p2)`` plane (:mod:`trajgen.model.coordination`). Plain floats and tuples: these
functions run every control cycle.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from topology import JUNCTION_INDEX, Route

__all__ = [
    "Interval",
    "TravelAxis",
    "VehiclePath",
    "interval_distance",
    "set_distance",
    "travel_within_segment",
]

#: A velocity below this along the axis is at rest for :meth:`TravelAxis.travel_at_axis`, m/s.
_STILL = 1e-9
#: Moves of a vehicle shorter than this between two waypoints are ignored, metres.
MOVE_RESOLUTION = 1e-9
#: One stretch of track: (leg index, smallest s, largest s), metres.
Interval = tuple[int, float, float]


def interval_distance(first: Interval, second: Interval) -> float:
    """Track distance between two stretches of track, metres (0 if they overlap)."""
    leg_a, low_a, high_a = first
    leg_b, low_b, high_b = second
    if leg_a == leg_b:
        return max(0.0, low_b - high_a, low_a - high_b)
    return low_a + low_b


def set_distance(first: tuple[Interval, ...], second: tuple[Interval, ...]) -> float:
    """Track distance between two unions of stretches, metres."""
    best = math.inf
    for leg_a, low_a, high_a in first:
        for leg_b, low_b, high_b in second:
            if leg_a == leg_b:
                gap = low_b - high_a if low_b > high_a else (low_a - high_b if low_a > high_b else 0.0)
            else:
                gap = low_a + low_b
            if gap < best:
                best = gap
    return best


def travel_within_segment(
    travel: tuple[float, float], span: tuple[float, float], s: float, near: float
) -> float | None:
    """The travel at ``s`` on a segment, if it lies there nearer ``near`` than both its ends; else None.

    ``travel``: the segment's travel at its start and end; ``span``: its ``s`` there (metres, on
    one leg or edge). Every other segment of a path lies beyond an end of this one in travel, so
    such a place is the nearest the path passes ``s`` at.
    """
    s_from, s_to = span
    if not min(s_from, s_to) <= s <= max(s_from, s_to):
        return None
    start, end = travel
    p = start + (s - s_from if s_to > s_from else s_from - s)
    distance = abs(p - near)
    return p if distance < near - start and distance < end - near else None


class TravelAxis:
    """What a path in travel coordinates answers from its segments' travel, headings and axis alone.

    Shared by :class:`VehiclePath` (a junction's legs) and
    :class:`~trajgen.model.graph_vehicle_path.GraphVehiclePath` (a track graph's edges), which
    hold ``starts``, ``headings``, ``axis_starts``, ``stops`` and ``length`` as described there.
    Plain floats: these run every control cycle.
    """

    __slots__ = ()

    s_from: tuple[float, ...]
    s_to: tuple[float, ...]
    starts: tuple[float, ...]
    headings: tuple[int, ...]
    axis_starts: tuple[float, ...]
    stops: tuple[float, ...]
    length: float

    def run_on_overrun(self, p_low: float, p_high: float, tops: tuple[float, float]) -> float:
        """How far travel over ``[p_low, p_high]`` may take the vehicle beyond what its sweep holds, metres.

        Before 0 or past :attr:`length` the sweep runs on along the end segment's leg or edge and
        is clipped at its ends (``0`` and ``tops``: the first and last segment's leg or edge
        length). Beyond a clipped end the vehicle is on some other leg or edge of that node: within
        the clipped metres of it, so a track distance to the sweep, less this overrun, is a sound
        distance to the vehicle (the track distance is 1-Lipschitz). A path that does not move
        sweeps its home point only: any travel away from 0 is overrun.
        """
        if not self.headings:
            return max(abs(p_low), abs(p_high))
        overrun = 0.0
        if p_low < 0.0:
            s = self.s_from[0] + (p_low if self.s_to[0] > self.s_from[0] else -p_low)
            overrun = max(-s, s - tops[0], 0.0)
        if p_high > self.length:
            beyond = p_high - self.length
            s = self.s_to[-1] + (beyond if self.s_to[-1] > self.s_from[-1] else -beyond)
            overrun = max(overrun, -s, s - tops[1])
        return overrun

    def segment(self, p: float) -> int:
        """Index of the segment holding travel ``p`` (clipped to the path)."""
        k = bisect.bisect_right(self.starts, p) - 1
        return 0 if k < 0 else k

    def heading(self, p: float) -> int:
        """``d axis / dp`` at travel ``p``."""
        return self.headings[self.segment(p)] if self.headings else 1

    def axis(self, p: float) -> float:
        """The vehicle's signed axis at travel ``p`` (beyond the ends: extended along the end segments)."""
        if not self.headings:
            return self.axis_starts[0] if self.axis_starts else 0.0
        k = self.segment(p)
        return self.axis_starts[k] + self.headings[k] * (p - self.starts[k])

    def travel_at_axis(self, axis: float, near: float, velocity: float) -> float:
        """The travel at which the vehicle's signed axis is ``axis``, moving at ``velocity`` along it.

        The axis runs back and forth through reversals, so one value can be met more than once:
        the first segment from ``near``'s that holds ``axis`` and is driven in the direction of
        ``velocity`` (m/s, along the axis; at rest, either way) is taken. The end segments run on
        beyond the path's ends.
        """
        if not self.headings:
            return 0.0
        k = self.segment(near)
        last = len(self.headings) - 1
        while True:
            p = self.starts[k] + self.headings[k] * (axis - self.axis_starts[k])
            end = self.starts[k + 1] if k < last else math.inf
            # at rest (to round-off) either way will do: a sign of 1e-17 m/s must not skip a segment
            forward = self.headings[k] * velocity >= -_STILL
            if k == last or (p <= end + 1e-9 and forward):
                return max(p, self.starts[k]) if k else p
            k += 1

    def next_stop(self, p: float, tolerance: float) -> float:
        """The first reversal ahead of travel ``p`` (more than ``tolerance`` ahead), or the path's end."""
        k = bisect.bisect_right(self.stops, p + tolerance)
        return self.stops[k] if k < len(self.stops) else self.length


@dataclass(frozen=True, slots=True)
class VehiclePath(TravelAxis):
    """One vehicle's path along a route, parameterised by travelled distance ``p`` (metres).

    The path is a sequence of segments, each on one leg and monotone in ``s``;
    consecutive segments on different legs pass through the junction. The
    vehicle's signed axis (its odometer) changes by ``heading * dp``; the
    heading flips where the path reverses on a leg (the vehicle must be at rest
    there: :attr:`stops`).

    Attributes
    ----------
    legs : tuple of int, shape (m,)
        Leg index of each segment.
    s_from, s_to : tuple of float, shape (m,)
        Distance from the junction at each segment's ends, metres.
    starts : tuple of float, shape (m,)
        Travel at each segment's start, metres (``starts[0] == 0``).
    headings : tuple of int, shape (m,)
        ``d axis / dp`` on each segment: +1 or -1.
    axis_starts : tuple of float, shape (m,)
        Axis value at each segment's start, metres.
    length : float
        Total travel, metres.
    stops : tuple of float
        Travel at each reversal, ascending, metres.
    home : tuple of (int, float)
        ``(leg, s)`` of a path that does not move (``m == 0``).
    home_orientation : int
        ``ds / d axis`` of a path that does not move: the ``orientation`` it was built with (+1 if
        none). A vehicle that stays put keeps the way its axis runs, so its next plan continues it.
    """

    legs: tuple[int, ...]
    s_from: tuple[float, ...]
    s_to: tuple[float, ...]
    starts: tuple[float, ...]
    headings: tuple[int, ...]
    axis_starts: tuple[float, ...]
    length: float
    stops: tuple[float, ...]
    home: tuple[int, float]
    home_orientation: int = 1

    @classmethod
    def from_route(
        cls, route: Route, vehicle: int, *, axis_start: float = 0.0, orientation: int | None = None
    ) -> VehiclePath:
        """The path of ``vehicle`` (0 or 1) along ``route`` (see :meth:`from_waypoints`)."""
        return cls.from_waypoints(
            route.indexed_waypoints, vehicle, axis_start=axis_start, orientation=orientation
        )

    @classmethod
    def from_waypoints(
        cls, waypoints, vehicle: int, *, axis_start: float = 0.0, orientation: int | None = None
    ) -> VehiclePath:
        """The path of ``vehicle`` (0 or 1) through indexed configurations ``(leg1, s1, leg2, s2)``.

        Between consecutive configurations each vehicle moves within one leg, or through the
        junction from one leg to another; moves shorter than :data:`MOVE_RESOLUTION` are ignored.

        Parameters
        ----------
        waypoints : sequence of tuple, shape (n, 4)
        vehicle : int
        axis_start : float, optional
            Axis value at the start, metres.
        orientation : int, optional
            ``ds / d axis`` of the vehicle at the start (+1 if its axis grows
            away from the junction). ``None``: the axis grows in the direction of
            the first move (the convention of :class:`~trajgen.model.schedule.Schedule`).
        """
        pieces: list[list] = []  # [leg, s_from, s_to]
        waypoints = list(waypoints)
        last = waypoints[0]
        for b in waypoints[1:]:
            a = last
            leg_a, s_a, leg_b, s_b = a[2 * vehicle], a[2 * vehicle + 1], b[2 * vehicle], b[2 * vehicle + 1]
            # round-off next to the junction (3e-15 for a timed vertex at it) is the junction: else the
            # path would pass it through slivers of a segment that never quite reach it
            s_a, s_b = (0.0 if s <= MOVE_RESOLUTION else s for s in (s_a, s_b))
            if abs(s_a - s_b) <= MOVE_RESOLUTION and (leg_a == leg_b or max(s_a, s_b) <= MOVE_RESOLUTION):
                continue
            last = b
            if leg_a == leg_b or s_b == 0.0 or s_a == 0.0:
                leg = leg_b if s_a == 0.0 else leg_a  # from the junction: the leg it enters
                if pieces and pieces[-1][0] == leg and (pieces[-1][2] - pieces[-1][1]) * (s_b - s_a) > 0.0:
                    pieces[-1][2] = s_b  # the same move, split by the other vehicle's waypoint
                else:
                    pieces.append([leg, s_a, s_b])
            else:  # through the junction within one segment (not produced by plan(), but harmless)
                pieces.append([leg_a, s_a, 0.0])
                pieces.append([leg_b, 0.0, s_b])
        first = waypoints[0]
        home = (first[2 * vehicle], first[2 * vehicle + 1])
        legs, s_from, s_to, starts, headings, axis_starts, stops = [], [], [], [], [], [], []
        travel, axis = 0.0, float(axis_start)
        heading = 1
        if pieces and orientation is not None:
            heading = (1 if pieces[0][2] > pieces[0][1] else -1) * (1 if orientation >= 0 else -1)
        for k, (leg, s_a, s_b) in enumerate(pieces):
            if k and leg == legs[-1] and (s_b - s_a) * (s_to[-1] - s_from[-1]) < 0.0:
                heading = -heading  # a reversal on one leg
                stops.append(travel)
            legs.append(leg)
            s_from.append(float(s_a))
            s_to.append(float(s_b))
            starts.append(travel)
            headings.append(heading)
            axis_starts.append(axis)
            travel += abs(s_b - s_a)
            axis += heading * abs(s_b - s_a)
        if not legs:  # a vehicle that does not move keeps its axis value
            axis_starts.append(axis)
        return cls(
            tuple(legs),
            tuple(s_from),
            tuple(s_to),
            tuple(starts),
            tuple(headings),
            tuple(axis_starts),
            travel,
            tuple(stops),
            home,
            -1 if orientation is not None and orientation < 0 else 1,
        )

    def place(self, p: float) -> tuple[int, float, int, float, int]:
        """Everything about travel ``p`` at once: ``(leg, s, heading, axis, branch)``.

        As :meth:`locate`, :meth:`heading` and :meth:`axis` give them, with ``branch`` the leg the
        vehicle takes when it next passes the junction (its own leg if it turns back there). One
        segment lookup: this runs every control cycle.
        """
        if not self.legs:
            leg, s = self.home
            return leg, s, 1, self.axis(p), leg
        k = self.segment(p)
        length = abs(self.s_to[k] - self.s_from[k])
        local = min(max(p - self.starts[k], 0.0), length)
        s = self.s_from[k] + (local if self.s_to[k] > self.s_from[k] else -local)
        heading = self.headings[k]
        axis = self.axis_starts[k] + heading * (p - self.starts[k])
        leg = self.legs[k] if s > 0.0 else JUNCTION_INDEX
        branch = self.legs[k + 1] if self.s_to[k] == 0.0 and k + 1 < len(self.legs) else self.legs[k]
        return leg, s, heading, axis, branch

    def locate(self, p: float) -> tuple[int, float]:
        """``(leg, s)`` at travel ``p`` (clipped to [0, length]); leg is ``JUNCTION_INDEX`` at s = 0."""
        if not self.legs:
            return self.home
        k = self.segment(p)
        local = min(max(p - self.starts[k], 0.0), abs(self.s_to[k] - self.s_from[k]))
        s = self.s_from[k] + (local if self.s_to[k] > self.s_from[k] else -local)
        return (self.legs[k] if s > 0.0 else JUNCTION_INDEX), s

    def outward(self, p: float) -> int:
        """``ds / dp`` at travel ``p``: +1 away from the junction, -1 towards it (+1 if it never moves)."""
        if not self.legs:
            return 1
        k = self.segment(p)
        return 1 if self.s_to[k] > self.s_from[k] else -1

    def project(self, leg: int, s: float, near: float, slack: float = 1e-9) -> float | None:
        """The travel at which the path passes ``(leg, s)``, nearest ``near``; ``None`` if it never does.

        A position up to ``slack`` metres beyond the end of a stretch of the path counts as that end;
        within ``slack`` of ``near`` a stretch that holds the position is preferred to one it
        overshoots, beyond that the nearer place wins. A position on the first or last segment's
        leg before the start or past the end of the path gives a travel below 0 or above
        :attr:`length`.
        """
        best = None
        best_key = (math.inf, math.inf)  # (how far off its stretch, how far from near)
        if not self.legs:
            home_leg, home_s = self.home
            same = abs(s - home_s) <= slack and (leg == home_leg or max(s, home_s) <= slack)
            return 0.0 if same else None
        nearest = self._project_on_segment_of(leg, s, near, slack)
        if nearest is not None:
            return nearest
        last = len(self.legs) - 1
        for k, seg_leg in enumerate(self.legs):
            low, high = min(self.s_from[k], self.s_to[k]), max(self.s_from[k], self.s_to[k])
            outward = self.s_to[k] > self.s_from[k]
            if seg_leg != leg and s != 0.0:
                # on another leg, ``s`` from the junction: as far from this segment's junction end
                if low > 0.0 or s > slack:
                    continue
                p = self.starts[k] + (low - self.s_from[k]) * (1.0 if outward else -1.0)
                key = (s + max(abs(p - near) - slack, 0.0), abs(p - near))
                if key < best_key:
                    best, best_key = p, key
                continue
            # the first and last segments run on along their leg: a vehicle before the start or past
            # the end of its path is at a travel below 0 or above the length
            if k == 0:
                low, high = (-math.inf, high) if outward else (low, math.inf)
            if k == last:
                low, high = (low, math.inf) if outward else (-math.inf, high)
            if not low - slack <= s <= high + slack:
                continue
            clamped = min(max(s, low), high)
            p = self.starts[k] + (clamped - self.s_from[k]) * (1.0 if outward else -1.0)
            # how far off its stretch plus how far outside the window of ``slack`` about ``near``: a
            # stretch that holds the point exactly but lies far away (the run-on past the path's end)
            # loses to a nearby one the point overshoots by round-off
            off = 0.0 if abs(clamped - s) <= 1e-9 else abs(clamped - s)
            key = (off + max(abs(p - near) - slack, 0.0), abs(p - near))
            if key < best_key:
                best, best_key = p, key
        return best

    def _project_on_segment_of(self, leg: int, s: float, near: float, slack: float) -> float | None:
        """:meth:`project`'s answer if it lies on ``near``'s own segment, nearer than its ends; else None.

        Every other segment lies beyond an end of this one in travel, so a place here closer to
        ``near`` than both ends wins outright. This is the usual case, and it runs every cycle.
        """
        if s <= slack:
            return None
        k = self.segment(near)
        if self.legs[k] != leg:
            return None
        end = self.starts[k + 1] if k + 1 < len(self.starts) else self.length
        return travel_within_segment((self.starts[k], end), (self.s_from[k], self.s_to[k]), s, near)

    def overrun(self, p_low: float, p_high: float, leg_lengths: tuple[float, ...]) -> float:
        """Metres travel over ``[p_low, p_high]`` may run beyond :meth:`sweep` (:meth:`run_on_overrun`)."""
        if not self.legs:
            return self.run_on_overrun(p_low, p_high, (0.0, 0.0))
        return self.run_on_overrun(p_low, p_high, (leg_lengths[self.legs[0]], leg_lengths[self.legs[-1]]))

    def sweep(self, p_low: float, p_high: float, leg_lengths: tuple[float, ...]) -> tuple[Interval, ...]:
        """The track covered while travel runs over ``[p_low, p_high]``, as stretches per leg.

        Travel before 0 or past ``length`` extends the first or last segment
        along its leg (clipped to the leg), so a vehicle off the ends of its
        path is still accounted for.
        """
        if not self.legs:
            leg, s = self.home
            return ((leg, s, s),)
        out = []
        starts = self.starts
        last = len(self.legs) - 1
        # only the segments that end at or after p_low and start at or before p_high can hold some
        first = max(bisect.bisect_left(starts, p_low) - 1, 0)
        final = self.segment(p_high)
        for k in range(first, final + 1):
            start = starts[k]
            a = p_low if k == 0 or p_low > start else start
            if k < last:
                end = starts[k + 1]
                b = p_high if p_high < end else end
            else:  # the last segment runs on past the path's end
                b = p_high
            if a > b:
                continue
            s_from = self.s_from[k]
            if self.s_to[k] > s_from:
                lo, hi = s_from + (a - start), s_from + (b - start)
            else:
                lo, hi = s_from - (b - start), s_from - (a - start)
            leg = self.legs[k]
            top = leg_lengths[leg]
            out.append(
                (
                    leg,
                    0.0 if lo < 0.0 else (top if lo > top else lo),
                    0.0 if hi < 0.0 else (top if hi > top else hi),
                )
            )
        if not out:  # an empty or reversed range: the point itself
            leg, s = self.locate(p_low)
            return ((leg if leg != JUNCTION_INDEX else self.legs[self.segment(p_low)], s, s),)
        return tuple(out)
