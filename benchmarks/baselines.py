"""Two strategies fleet software uses, as honest baselines for ``optimal`` (issue 10).

Both are independent of the package's timing methods: each vehicle's motion
is computed with Ruckig (jerk-limited, time-optimal for its own move), and the
result is checked by sampling the separation at every step.

* **Zone locking** (:func:`zone_locking`): the junction plus ``min_separation``
  on each leg is a mutex. Each vehicle drives its own path of the planner's
  route with Ruckig's online generator, one move (between reversals) at a time;
  before it enters the zone without the lock it brakes to a stop at the zone
  boundary and waits. The lock is granted in the order in which the route
  passes the junction, and released once the holder has left the zone.
* **Prioritized planning** (:func:`prioritized`): one vehicle drives its
  shortest path at full speed from time 0; the other drives to a holding point,
  waits, and leaves for its goal as early as the first vehicle's motion
  allows. Every holding point (each leg just clear of the junction and at its
  end, the start and the goal) and both orders are tried; the fastest wins.

Run: this module is imported by ``bench_optimal.py``; ``python
benchmarks/baselines.py`` prints both baselines for the issue's swaps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from ruckig import InputParameter, OutputParameter, Result, Ruckig, Trajectory

from limits import Limits, VehicleLimits
from topology import JUNCTION_INDEX, Route
from topology.cycle import as_indexed
from topology.indexed import track_distance

#: Sample period of the separation check and of the online generator, seconds (for short tracks).
PERIOD = 0.01
#: Most samples per motion: longer motions get a longer period.
_MAX_SAMPLES = 60_000


@dataclass(frozen=True, slots=True)
class Move:
    """A straight move of one vehicle (no reversal): from (leg, s) to (leg, s), maybe through the junction."""

    leg_from: int
    s_from: float
    leg_to: int
    s_to: float

    @property
    def length(self) -> float:
        """Metres driven."""
        return float(track_distance(self.leg_from, self.s_from, self.leg_to, self.s_to))

    def positions(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Leg index and s after driving ``u`` metres along the move (arrays)."""
        u = np.clip(u, 0.0, self.length)
        same = self.leg_from == self.leg_to and self.leg_from != JUNCTION_INDEX
        if same:
            sign = 1.0 if self.s_to >= self.s_from else -1.0
            return np.full(u.shape, self.leg_from), self.s_from + sign * u
        inbound = u < self.s_from
        leg = np.where(inbound, self.leg_from, self.leg_to)
        s = np.where(inbound, self.s_from - u, u - self.s_from)
        return np.where(s <= 0.0, JUNCTION_INDEX, leg), np.abs(s)

    def zone(self, radius: float) -> tuple[float, float] | None:
        """Odometer interval of the move inside the zone ``s < radius`` (None if it stays outside)."""
        u = np.linspace(0.0, self.length, 2001)
        _, s = self.positions(u)
        inside = np.nonzero(s < radius - 1e-12)[0]
        if inside.size == 0:
            return None
        # entry and exit in closed form: s is piecewise linear in u with slope +-1
        if self.leg_from == self.leg_to and self.leg_from != JUNCTION_INDEX:
            low, high = sorted((self.s_from, self.s_to))
            entry = abs(self.s_from - min(max(radius, low), high))
            return (0.0 if self.s_from < radius else entry, self.length if self.s_to < radius else entry)
        entry = max(0.0, self.s_from - radius)
        exit_ = min(self.length, self.s_from + radius)
        return entry, exit_


def _split_moves(waypoints: list[tuple[int, float]]) -> list[Move]:
    """One vehicle's path through its waypoints, merged into straight moves (split at reversals)."""
    moves: list[Move] = []
    points = [waypoints[0]]
    for point in waypoints[1:]:
        if track_distance(points[-1][0], points[-1][1], point[0], point[1]) > 0.0:
            points.append(point)
    if len(points) == 1:
        return []
    start = points[0]
    for previous, here, following in zip(points, points[1:], points[2:], strict=False):
        straight = track_distance(previous[0], previous[1], following[0], following[1]) >= (
            track_distance(previous[0], previous[1], here[0], here[1])
            + track_distance(here[0], here[1], following[0], following[1])
            - 1e-9
        )
        if not straight:  # a reversal at `here`
            moves.append(Move(start[0], start[1], here[0], here[1]))
            start = here
    moves.append(Move(start[0], start[1], points[-1][0], points[-1][1]))
    return moves


def _leg_of(point: tuple[int, float]) -> tuple[int, float]:
    return (JUNCTION_INDEX, 0.0) if point[1] <= 0.0 else point


def _ruckig_move(distance: float, vehicle: VehicleLimits, period: float) -> np.ndarray:
    """Odometer samples of Ruckig's time-optimal rest-to-rest move over ``distance``, every ``period``."""
    if distance <= 0.0:
        return np.zeros(1)
    otg = Ruckig(1)
    request = InputParameter(1)
    request.current_position, request.target_position = [0.0], [distance]
    request.max_velocity = [vehicle.max_velocity]
    request.max_acceleration = [vehicle.max_acceleration]
    request.max_jerk = [vehicle.max_jerk]
    trajectory = Trajectory(1)
    if otg.calculate(request, trajectory) not in (Result.Working, Result.Finished):
        raise RuntimeError(f"ruckig failed for a move of {distance} m")
    count = math.ceil(trajectory.duration / period) + 1
    samples = np.array([trajectory.at_time(min(k * period, trajectory.duration))[0][0] for k in range(count)])
    samples[-1] = distance
    return samples


@dataclass(frozen=True, slots=True)
class BaselineResult:
    """A baseline's motion: its makespan and the smallest sampled separation."""

    makespan: float
    min_separation: float
    safe: bool
    detail: str


def _period(route: Route, limits: Limits) -> float:
    longest = max(route.graph.lengths) * 8 / min(v.max_velocity for v in limits.vehicles)
    return max(PERIOD, longest / _MAX_SAMPLES)


def _vehicle_paths(route: Route) -> list[list[Move]]:
    paths = []
    for vehicle in range(2):
        points = [_leg_of((w[2 * vehicle], w[2 * vehicle + 1])) for w in route.indexed_waypoints]
        paths.append(_split_moves(points))
    return paths


def zone_locking(route: Route, limits: Limits) -> BaselineResult:
    """Both vehicles along the route's paths with Ruckig; the junction zone is a mutex (see module)."""
    period = _period(route, limits)
    radius = max(limits.min_separation, route.min_separation)
    paths = _vehicle_paths(route)
    # lock order: each zone use, ordered by the route segment where it begins
    uses = []
    for vehicle, path in enumerate(paths):
        travelled = 0.0
        for index, move in enumerate(path):
            if move.zone(radius) is not None:
                uses.append((_first_segment(route, vehicle, travelled), vehicle, index))
            travelled += move.length
    order = [(vehicle, index) for _, vehicle, index in sorted(uses)]
    otgs = [Ruckig(1, period) for _ in range(2)]
    requests, outputs = [InputParameter(1) for _ in range(2)], [OutputParameter(1) for _ in range(2)]
    for vehicle, request in enumerate(requests):
        vehicle_limits = limits.vehicles[vehicle]
        request.max_velocity = [vehicle_limits.max_velocity]
        request.max_acceleration = [vehicle_limits.max_acceleration]
        request.max_jerk = [vehicle_limits.max_jerk]
    state = [[0.0, 0.0, 0.0] for _ in range(2)]  # odometer in the current move, v, a
    current = [0, 0]
    holder: int | None = None
    turn = 0
    trace: list[list[tuple[int, float]]] = [[], []]
    rest = [_leg_of(route.indexed_waypoints[-1][2 * v : 2 * v + 2]) for v in range(2)]
    t = 0.0
    slowest = min(v.max_velocity for v in limits.vehicles)
    for _ in range(int(50 * (route.length + 10.0) / slowest / period)):
        for vehicle in range(2):
            if current[vehicle] >= len(paths[vehicle]):
                trace[vehicle].append(rest[vehicle])
                continue
            move = paths[vehicle][current[vehicle]]
            zone = move.zone(radius)
            target = move.length
            if zone is not None and holder != vehicle and state[vehicle][0] < zone[1]:
                if holder is None and turn < len(order) and order[turn] == (vehicle, current[vehicle]):
                    holder = vehicle
                else:  # wait at the zone boundary
                    target = max(zone[0], state[vehicle][0])
            request, output = requests[vehicle], outputs[vehicle]
            request.current_position = [state[vehicle][0]]
            request.current_velocity = [state[vehicle][1]]
            request.current_acceleration = [state[vehicle][2]]
            request.target_position = [target]
            result = otgs[vehicle].update(request, output)
            if result not in (Result.Working, Result.Finished):
                return BaselineResult(math.inf, 0.0, False, f"ruckig: {result}")
            state[vehicle] = [output.new_position[0], output.new_velocity[0], output.new_acceleration[0]]
            leg, s = move.positions(np.array([state[vehicle][0]]))
            trace[vehicle].append((int(leg[0]), float(s[0])))
            use = (vehicle, current[vehicle])
            leaving = zone is not None and zone[1] < move.length and state[vehicle][0] >= zone[1]
            if holder == vehicle and leaving:  # out of the zone again: release
                holder, turn = None, order.index(use) + 1
            if result == Result.Finished and target >= move.length:
                # a move that ends in the zone keeps the lock into the next one, which leaves it
                if holder == vehicle:
                    turn = order.index(use) + 1
                    if current[vehicle] == len(paths[vehicle]) - 1:
                        holder = None if rest[vehicle][1] >= radius else holder
                current[vehicle] += 1
                state[vehicle] = [0.0, 0.0, 0.0]
        t += period
        if all(current[v] >= len(paths[v]) for v in range(2)):
            break
    else:
        detail = f"deadlock or step limit: moves {current}, lock {holder}, turn {turn}, state {state}"
        return BaselineResult(math.inf, 0.0, False, detail)
    legs = np.array([[p[0] for p in trace[v]] for v in range(2)])
    s = np.array([[p[1] for p in trace[v]] for v in range(2)])
    distance = track_distance(legs[0], s[0], legs[1], s[1])
    smallest = float(distance.min())
    return BaselineResult(
        t, smallest, smallest >= radius - 1e-6, f"period {period:g} s, {len(order)} zone uses"
    )


def _first_segment(route: Route, vehicle: int, odometer: float) -> int:
    """Route segment in which ``vehicle`` has driven ``odometer`` metres (plus a hair)."""
    travelled = 0.0
    for index, (first, second) in enumerate(route.segment_travel):
        travelled += (first, second)[vehicle]
        if travelled > odometer + 1e-9:
            return index
    return len(route.segment_travel)


def _shortest(a: tuple[int, float], b: tuple[int, float]) -> list[Move]:
    return [Move(a[0], a[1], b[0], b[1])] if track_distance(a[0], a[1], b[0], b[1]) > 0.0 else []


def _samples(moves: list[Move], vehicle: VehicleLimits, period: float, still: tuple[int, float]):
    legs, s = [np.array([still[0]])], [np.array([still[1]])]
    for move in moves:
        leg, position = move.positions(_ruckig_move(move.length, vehicle, period))
        legs.append(leg)
        s.append(position)
    return np.concatenate(legs), np.concatenate(s)


def prioritized(route: Route, limits: Limits) -> BaselineResult:
    """One vehicle at full speed on its shortest path, the other via the best holding point (see module)."""
    period = _period(route, limits)
    radius = max(limits.min_separation, route.min_separation)
    graph = route.graph
    start = [_leg_of(as_indexed(graph, route.start)[2 * v : 2 * v + 2]) for v in range(2)]
    goal = [_leg_of(as_indexed(graph, route.goal)[2 * v : 2 * v + 2]) for v in range(2)]
    best = BaselineResult(math.inf, 0.0, False, "no holding point works")
    for leader in range(2):
        follower = 1 - leader
        lead_leg, lead_s = _samples(
            _shortest(start[leader], goal[leader]), limits.vehicles[leader], period, start[leader]
        )
        holds = {start[follower], goal[follower]}
        for leg in range(len(graph.lengths)):
            holds |= {(leg, radius), (leg, graph.lengths[leg])}
        for hold in holds:
            first_leg, first_s = _samples(
                _shortest(start[follower], hold), limits.vehicles[follower], period, start[follower]
            )
            second_leg, second_s = _samples(
                _shortest(hold, goal[follower]), limits.vehicles[follower], period, hold
            )
            result = _earliest_departure(
                (lead_leg, lead_s), (first_leg, first_s), (second_leg, second_s), radius, period
            )
            if result is not None and result.makespan < best.makespan:
                best = BaselineResult(
                    result.makespan,
                    result.min_separation,
                    True,
                    f"vehicle {leader + 1} first, vehicle {follower + 1} holds at "
                    f"leg {hold[0]} s={hold[1]:g}",
                )
    return best


def _hold(leg: np.ndarray, s: np.ndarray, start: int, length: int) -> tuple[np.ndarray, np.ndarray]:
    """Samples ``start .. start + length`` of a motion that stays at its last sample once it is over."""
    index = np.clip(np.arange(start, start + length), 0, len(s) - 1)
    return leg[index], s[index]


def _earliest_departure(lead, first, second, radius: float, period: float) -> BaselineResult | None:
    """The follower drives ``first`` from 0, waits, then ``second`` as early as the separation allows.

    The leader waits the fewest samples that keep the follower's way to its holding point clear
    (none, where it can; waiting longer would let the follower finish first, which is the other
    order), then drives at full speed; the follower leaves the hold at the first
    sample from which the rest of its motion stays clear. Each candidate is one vectorized check.
    """
    lead_leg, lead_s = lead
    first_count, second_count = len(first[1]), len(second[1])
    hold_leg, hold_s = first[0][-1], first[1][-1]
    goal_leg, goal_s = second[0][-1], second[1][-1]
    lead_count = len(lead_s)
    clear = radius - 1e-9
    for delay in range(lead_count + first_count):
        # the leader, delayed: index t of the follower's clock is the leader's t - delay
        leg, s = _hold(lead_leg, lead_s, -delay, first_count)
        if track_distance(leg, s, first[0], first[1]).min() < clear:
            continue
        horizon = delay + lead_count + second_count + first_count
        leg, s = _hold(lead_leg, lead_s, -delay, horizon)
        waiting = track_distance(leg, s, hold_leg, hold_s)
        at_goal = track_distance(leg, s, goal_leg, goal_s)
        # suffix minimum: the follower parked at its goal from sample k on stays clear iff after[k] holds
        after = np.minimum.accumulate(at_goal[::-1])[::-1]
        for departure in range(first_count - 1, horizon - second_count):
            if waiting[departure] < clear:
                break  # the leader reaches the hold while the follower still waits there
            end = departure + second_count
            gap = track_distance(leg[departure:end], s[departure:end], second[0], second[1])
            if gap.min() >= clear and after[end - 1] >= clear:
                makespan = max(delay + lead_count - 1, end - 1) * period
                return BaselineResult(
                    makespan, float(gap.min()), True, f"leader starts after {delay * period:g} s"
                )
        # Only the fewest delay is tried: a longer one lets the follower finish first, which is
        # the other order (tried too).
        return None
    return None


def main() -> None:
    from topology import Configuration, Position, YGraph, plan

    cases = [
        ("10/10/10, 2.0/1.0/2.0 and 0.5/0.25/0.5", (10, 10, 10), (2.0, 1.0, 2.0), (0.5, 0.25, 0.5)),
        ("12/8/15, 1.0/0.5/1.0 and 0.7/0.35/0.6", (12, 8, 15), (1.0, 0.5, 1.0), (0.7, 0.35, 0.6)),
        ("200/120/80, 1.0/0.5/1.0 both", (200, 120, 80), (1.0, 0.5, 1.0), (1.0, 0.5, 1.0)),
    ]
    for label, legs, first, second in cases:
        track = YGraph(dict(zip("ABC", legs, strict=True)))
        limits = Limits((VehicleLimits(*first), VehicleLimits(*second)), 1.5)
        start = Configuration(Position("A", legs[0]), Position("B", legs[1]))
        route = plan(track, start, start.swapped(), min_separation=1.5)
        zone, priority = zone_locking(route, limits), prioritized(route, limits)
        print(
            f"swap A<->B on {label}: zone locking {zone.makespan:.2f} s (safe {zone.safe}), "
            f"prioritized {priority.makespan:.2f} s ({priority.detail})"
        )


if __name__ == "__main__":
    main()
