"""The sampled verifier: the second, independent opinion the tests hold the closed-form verifier against.

It samples a schedule every ``period`` seconds (and at every section boundary)
and checks the samples alone: separation, track ends, limits, start and goal,
that positions move no faster than the velocity limits allow, and the class.
It cannot see between its samples; the library's verifier can.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from topology import Region, reduce_regions
from topology.indexed import JUNCTION_INDEX, region_keys, track_distance
from trajgen.model.schedule import Schedule, ScheduleState
from trajgen.verification import POSITION_TOLERANCE, RELATIVE_TOLERANCE, REST_TOLERANCE, TRACK_END_TOLERANCE


@dataclass(frozen=True)
class SampledReport:
    passed: bool
    failures: tuple[str, ...]
    samples: int
    min_separation: float
    ratios: dict


def sampled_verify(schedule: Schedule, period: float = 1e-3) -> SampledReport:
    """Check ``schedule`` at samples ``period`` seconds apart."""
    route = schedule.route
    required = max(schedule.limits.min_separation, route.min_separation)
    with np.errstate(invalid="ignore", over="ignore"):
        state = schedule.state(_sample_times(schedule, period))
    failures: list[str] = []
    _check_finite(state, failures)
    closest = _check_separation(state, required, failures)
    _check_on_track(state, route.graph, failures)
    ratios = _check_limits(state, schedule, failures)
    _check_ends(state, schedule, failures)
    _check_consistency(state, schedule, failures)
    _check_class(state, route, failures)
    return SampledReport(not failures, tuple(failures), int(state.t.size), closest, ratios)


def _sample_times(schedule: Schedule, period: float) -> np.ndarray:
    duration = schedule.duration
    count = max(int(np.ceil(duration / period)), 1)
    grid = np.linspace(0.0, duration, count + 1)
    boundaries = np.array([section.start_time for section in schedule.sections] + [duration])
    return np.unique(np.concatenate([grid, boundaries]))


def _check_separation(state: ScheduleState, required: float, failures: list[str]) -> float:
    """Smallest track distance between the vehicles, metres; records a violation of ``required``."""
    separation = track_distance(state.leg[0], state.s[0], state.leg[1], state.s[1])
    worst = int(np.argmin(separation))
    if separation[worst] < required - POSITION_TOLERANCE:
        failures.append(
            f"separation {separation[worst]:.9g} m at t={state.t[worst]:.4f} s "
            f"is below the minimum {required:g} m"
        )
    if separation[worst] <= 0.0:
        failures.append(f"vehicles collide at t={state.t[worst]:.4f} s")
    return float(separation[worst])


def _check_on_track(state: ScheduleState, graph, failures: list[str]) -> None:
    """Every sampled position within its leg (to :data:`TRACK_END_TOLERANCE`)."""
    lengths = np.array(graph.lengths)
    on_leg = state.leg != JUNCTION_INDEX
    overrun = np.where(on_leg, state.s - lengths[np.where(on_leg, state.leg, 0)], 0.0)
    worst_overrun = float(overrun.max())
    if worst_overrun > TRACK_END_TOLERANCE:
        vehicle, k = np.unravel_index(int(np.argmax(overrun)), overrun.shape)
        failures.append(
            f"vehicle {vehicle + 1} is {worst_overrun:.3g} m past the end of leg "
            f"{graph.names[state.leg[vehicle, k]]!r} at t={state.t[k]:.4f} s "
            f"(tolerance {TRACK_END_TOLERANCE:g} m)"
        )


def _check_limits(
    state: ScheduleState, schedule: Schedule, failures: list[str]
) -> dict[str, tuple[float, float]]:
    """Largest ``|value| / limit`` per vehicle of velocity, acceleration and (if limited) jerk."""
    checks = [
        ("velocity", state.velocity, "max_velocity", "m/s"),
        ("acceleration", state.acceleration, "max_acceleration", "m/s^2"),
    ]
    if schedule.jerk_limited:
        checks.append(("jerk", state.jerk, "max_jerk", "m/s^3"))
    ratios: dict[str, tuple[float, float] | None] = {"jerk": None}
    for name, values, limit_name, unit in checks:
        per_vehicle = []
        for vehicle in range(2):
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(np.abs(values[vehicle])))
            ratio = float(abs(values[vehicle, k]) / limit)
            per_vehicle.append(ratio)
            if ratio > 1.0 + RELATIVE_TOLERANCE:
                failures.append(
                    f"vehicle {vehicle + 1} {name} {values[vehicle, k]:.9g} {unit} at t={state.t[k]:.4f} s "
                    f"exceeds its {limit_name} {limit:g} {unit}"
                )
        ratios[name] = (per_vehicle[0], per_vehicle[1])
    return ratios


def _check_ends(state: ScheduleState, schedule: Schedule, failures: list[str]) -> tuple[float, float]:
    """Distance of the first and last sample from the route's start and goal, metres; both at rest."""
    route, graph = schedule.route, schedule.route.graph
    errors = []
    for label, index, expected in (("start", 0, route.start), ("goal", -1, route.goal)):
        error = 0.0
        for vehicle, position in enumerate(expected):
            leg = JUNCTION_INDEX if position.leg is None else graph.index(position.leg)
            error += float(
                track_distance(state.leg[vehicle, index], state.s[vehicle, index], leg, position.s)
            )
            # at rest: v = 0; a jerk-limited method also starts and ends with a = 0
            residue = abs(state.velocity[vehicle, index])
            if schedule.jerk_limited:
                residue += abs(state.acceleration[vehicle, index])
            if residue > REST_TOLERANCE:
                failures.append(
                    f"vehicle {vehicle + 1} is not at rest at the {label} (|v| + |a| = {residue:.3g})"
                )
        if error > POSITION_TOLERANCE:
            failures.append(f"{label} is off the route's {label} by {error:.3g} m (expected <= 1e-9 m)")
        errors.append(error)
    return errors[0], errors[1]


def _check_consistency(state: ScheduleState, schedule: Schedule, failures: list[str]) -> None:
    """Positions move no faster than the vehicles' velocity limits allow (track and kinematics agree)."""
    dt = np.diff(state.t)
    for vehicle in range(2):
        moved = track_distance(
            state.leg[vehicle, :-1], state.s[vehicle, :-1], state.leg[vehicle, 1:], state.s[vehicle, 1:]
        )
        limit = schedule.limits.vehicles[vehicle].max_velocity
        jumps = np.nonzero(moved > limit * dt * (1.0 + RELATIVE_TOLERANCE) + POSITION_TOLERANCE)[0]
        if jumps.size:
            k = int(jumps[0])
            failures.append(
                f"vehicle {vehicle + 1} jumps {moved[k]:.6g} m in {dt[k]:.3g} s at t={state.t[k]:.4f} s "
                f"(faster than its max_velocity)"
            )


def _check_class(state: ScheduleState, route, failures: list[str]) -> bool:
    """Whether the sampled region sequence (homotopy class) is the route's."""
    expected = route.region_keys
    sampled = reduce_regions(region_keys(state.leg[0], state.s[0], state.leg[1], state.s[1]))
    if sampled == expected:
        return True

    def show(keys):
        return " ".join(str(Region.from_key(route.graph, key)) for key in keys)

    failures.append(f"homotopy class differs: schedule visits [{show(sampled)}], route [{show(expected)}]")
    return False


def _check_finite(state: ScheduleState, failures: list[str]) -> None:
    """Every sampled time, position and derivative is a finite number."""
    for name in ("t", "axis", "velocity", "acceleration", "jerk", "s"):
        values = getattr(state, name)
        bad = ~np.isfinite(values)
        if bad.any():
            where = np.argwhere(bad)[0]
            k = int(where[-1])
            failures.append(
                f"{name} is not finite ({values[tuple(where)]!r}) at t={state.t[k]!r} s "
                f"({int(bad.sum())} samples in all): expected finite numbers"
            )
