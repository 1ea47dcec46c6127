"""The verifier's checks of each polynomial piece, in closed form: limits, track, separation, continuity.

On each piece both vehicles' signed axes are single polynomials and each
vehicle is on one leg, so every check takes the extrema at the ends and at the
roots of a derivative: nothing hides between samples. Each check appends what
fails to ``failures`` as a :class:`~trajgen.verification.report.Finding`: in plain words (the
vehicle, the quantity, when and where on the track), with the arrays that define the piece
(:func:`piece_arrays`) as its details.
"""

from __future__ import annotations

import numpy as np

from topology import RegionKey
from topology.indexed import JUNCTION_INDEX, track_distance
from trajgen.model import polynomials
from trajgen.model.pieces import Pieces, motion_arrays
from trajgen.model.schedule import Schedule
from trajgen.verification.report import (
    CONTINUITY_TOLERANCE,
    POSITION_TOLERANCE,
    RELATIVE_TOLERANCE,
    TRACK_END_TOLERANCE,
    Finding,
)

__all__ = [
    "allowance",
    "check_maps",
    "check_parked",
    "check_piece_continuity",
    "check_piece_limits",
    "check_piece_separation",
    "check_piece_track",
    "continuity_allowance",
    "piece_arrays",
    "place",
    "places",
    "time_resolution",
]


def piece_arrays(schedule: Schedule, pieces: Pieces, k: int, vehicles: tuple[int, ...] = (0, 1)) -> str:
    """The arrays that define piece ``k`` of the given vehicles, by their paths (for failure messages)."""
    if not pieces.count:
        return "sections[0]"
    section = int(pieces.section[k])
    return "; ".join(
        motion_arrays(schedule, section, vehicle, int(pieces.interval[vehicle, k])) for vehicle in vehicles
    )


def place(schedule: Schedule, pieces: Pieces, vehicle: int, k: int, time: float) -> str:
    """Where a vehicle is at ``time`` (seconds, in piece ``k``), in words: its leg and metres out.

    For example ``on leg 'A', 3.205 m from the junction`` or ``in the junction``.
    """
    leg = int(pieces.leg[vehicle, k])
    if leg == JUNCTION_INDEX:
        return "in the junction"
    tau = np.array([time - float(pieces.start[k])])
    axis = float(polynomials.evaluate(pieces.axis[vehicle, k : k + 1], tau)[0])
    s = float(pieces.s_offset[vehicle, k] + pieces.s_sign[vehicle, k] * axis)
    return f"on leg {schedule.route.graph.names[leg]!r}, {s:.3f} m from the junction"


def places(schedule: Schedule, pieces: Pieces, k: int, time: float) -> str:
    """Where both vehicles are at ``time`` (seconds, in piece ``k``), in words."""
    return " and ".join(f"vehicle {v + 1} {place(schedule, pieces, v, k, time)}" for v in range(2))


def time_resolution(schedule: Schedule) -> float:
    """The time round-off of the schedule, seconds: breakpoints are floats of its duration's size."""
    return 8.0 * float(np.spacing(max(schedule.duration, 1.0)))


def allowance(schedule: Schedule, vehicle: int, name: str) -> float:
    """What a quantity may exceed its limit or jump by, in its units.

    1e-6 of the limit, plus what the next derivative's limit allows within the
    time round-off (a jerk of 1e6 m/s^3 moves the acceleration 1e-8 m/s^2 in 1e-14 s).
    """
    limits = schedule.limits.vehicles[vehicle]
    eps = time_resolution(schedule)
    if name == "position":
        return TRACK_END_TOLERANCE + limits.max_velocity * eps
    if name == "velocity":
        return RELATIVE_TOLERANCE * limits.max_velocity + limits.max_acceleration * eps
    if name == "acceleration":
        return RELATIVE_TOLERANCE * limits.max_acceleration + limits.max_jerk * eps
    return RELATIVE_TOLERANCE * limits.max_jerk


def continuity_allowance(schedule: Schedule, vehicle: int, name: str, length_scale: float) -> float:
    """What a quantity may jump by from piece to piece, in its units: round-off of its scale.

    ``length_scale``: metres, the largest position of the schedule (at least 1 m). A table
    read back (``end_tolerance`` set) is held to its interpolation's allowances instead.
    """
    if schedule.end_tolerance is not None:
        return allowance(schedule, vehicle, name)
    limits = schedule.limits.vehicles[vehicle]
    eps = time_resolution(schedule)
    if name == "position":
        return CONTINUITY_TOLERANCE * length_scale + limits.max_velocity * eps
    if name == "velocity":
        return CONTINUITY_TOLERANCE * limits.max_velocity + limits.max_acceleration * eps
    return CONTINUITY_TOLERANCE * limits.max_acceleration + limits.max_jerk * eps


def check_piece_limits(pieces: Pieces, schedule: Schedule, failures: list[str]) -> dict:
    """Largest ``|v|``, ``|a|`` (and ``|j|``) / limit per vehicle over every piece, in closed form."""
    names = [("velocity", "max_velocity", "m/s"), ("acceleration", "max_acceleration", "m/s^2")]
    if schedule.jerk_limited:
        names.append(("jerk", "max_jerk", "m/s^3"))
    if schedule.checked_limits is not None:  # a table read back: the rest is checked from its points
        names = names[: schedule.checked_limits]
    ratios: dict[str, tuple[float, float] | None] = {
        "velocity": (0.0, 0.0),
        "acceleration": (0.0, 0.0),
        "jerk": None,
    }
    for vehicle in range(2):
        c = pieces.axis[vehicle]
        for order, (name, limit_name, unit) in enumerate(names, start=1):
            for _ in range(order):
                c = polynomials.derivative(c)
            low, t_low, high, t_high = polynomials.extrema(c, pieces.length)
            peak = np.maximum(np.abs(low), np.abs(high))
            limit = getattr(schedule.limits.vehicles[vehicle], limit_name)
            k = int(np.argmax(peak)) if peak.size else 0
            ratio = float(peak[k] / limit) if peak.size else 0.0
            previous = ratios.get(name) or (0.0, 0.0)
            ratios[name] = (ratio, previous[1]) if vehicle == 0 else (previous[0], ratio)
            if peak.size and not peak[k] <= limit + allowance(schedule, vehicle, name):
                when = pieces.start[k] + (t_high[k] if abs(high[k]) >= abs(low[k]) else t_low[k])
                failures.append(
                    Finding(
                        f"vehicle {vehicle + 1} {name} reaches {peak[k]:.9g} {unit} at t={when:.6f} s "
                        f"({place(schedule, pieces, vehicle, k, when)}) exceeds its {limit_name} "
                        f"{limit:g} {unit}",
                        piece_arrays(schedule, pieces, k, (vehicle,)),
                    )
                )
            c = pieces.axis[vehicle]
    return ratios


def check_piece_track(
    pieces: Pieces,
    track: np.ndarray,
    schedule: Schedule,
    failures: list[str],
    past_end: float = TRACK_END_TOLERANCE,
) -> None:
    """Each vehicle stays on its leg and in its map's range; ``track``: s polynomials, shape (2, n, 5)."""
    graph = schedule.route.graph
    lengths = np.array(graph.lengths)
    for vehicle in range(2):
        low, t_low, high, t_high = polynomials.extrema(track[vehicle], pieces.length)
        on_leg = pieces.leg[vehicle] != JUNCTION_INDEX
        length = np.where(on_leg, lengths[np.where(on_leg, pieces.leg[vehicle], 0)], 0.0)
        over = np.nonzero(on_leg & (high > length + past_end))[0]
        if over.size:
            k = int(over[0])
            failures.append(
                Finding(
                    f"vehicle {vehicle + 1} is {high[k] - length[k]:.3g} m past the end of leg "
                    f"{graph.names[pieces.leg[vehicle, k]]!r} ({length[k]:g} m long) at "
                    f"t={pieces.start[k] + t_high[k]:.6f} s: expected at most {past_end:g} m",
                    piece_arrays(schedule, pieces, k, (vehicle,)),
                )
            )
        under = np.nonzero(low < -TRACK_END_TOLERANCE)[0]
        if under.size:
            k = int(under[0])
            where = (
                "the junction"
                if pieces.leg[vehicle, k] == JUNCTION_INDEX
                else f"leg {graph.names[pieces.leg[vehicle, k]]!r}"
            )
            failures.append(
                Finding(
                    f"vehicle {vehicle + 1} runs {-low[k]:.3g} m through the junction while the schedule "
                    f"keeps it on {where}, at t={pieces.start[k] + t_low[k]:.6f} s: expected it to "
                    "change leg at the junction",
                    piece_arrays(schedule, pieces, k, (vehicle,)),
                )
            )
        axis_low, _, axis_high, _ = polynomials.extrema(pieces.axis[vehicle], pieces.length)
        outside = np.nonzero(
            (axis_low < pieces.axis_low[vehicle] - TRACK_END_TOLERANCE)
            | (axis_high > pieces.axis_high[vehicle] + TRACK_END_TOLERANCE)
        )[0]
        if outside.size:
            k = int(outside[0])
            failures.append(
                Finding(
                    f"vehicle {vehicle + 1} travels beyond the stretch of track its schedule places it on "
                    f"at t={pieces.start[k]:.6f} s: its axis runs {axis_low[k]:.6g} to "
                    f"{axis_high[k]:.6g} m, expected within {pieces.axis_low[vehicle, k]:.6g} to "
                    f"{pieces.axis_high[vehicle, k]:.6g} m",
                    piece_arrays(schedule, pieces, k, (vehicle,)),
                )
            )


def check_piece_separation(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, required: float, failures: list[str]
) -> tuple[float, list]:
    """Smallest track distance over every piece and each piece's region."""
    same = (pieces.leg[0] == pieces.leg[1]) & (pieces.leg[0] != JUNCTION_INDEX)
    gap = np.where(same[:, None], track[0] - track[1], track[0] + track[1])
    low, t_low, high, t_high = polynomials.extrema(gap, pieces.length)
    crossing = same & (low < 0.0) & (high > 0.0)
    closest = np.where(same, np.where(high <= 0.0, -high, low), low)
    closest = np.where(crossing, 0.0, closest)
    when = np.where(same & (high <= 0.0), t_high, t_low)
    regions: list = []
    middle = polynomials.evaluate(gap, 0.5 * pieces.length)
    for k in range(pieces.count):
        first, second = int(pieces.leg[0, k]), int(pieces.leg[1, k])
        if first == JUNCTION_INDEX or second == JUNCTION_INDEX:
            regions.append(None)
        else:
            regions.append(RegionKey(first, second, 0 if first != second else (1 if middle[k] < 0.0 else 2)))
    if not pieces.count:
        return float("inf"), regions
    k = int(np.argmin(closest))
    if crossing[k]:
        leg = schedule.route.graph.names[int(pieces.leg[0, k])]
        failures.append(
            Finding(
                f"the vehicles pass each other on leg {leg!r} between t={pieces.start[k]:.6f} s and "
                f"t={pieces.start[k] + pieces.length[k]:.6f} s: expected them never to",
                piece_arrays(schedule, pieces, k),
            )
        )
    elif closest[k] < required - POSITION_TOLERANCE:
        at = pieces.start[k] + when[k]
        failures.append(
            Finding(
                f"separation {closest[k]:.9g} m at t={at:.6f} s is below the minimum {required:g} m "
                f"({places(schedule, pieces, k, at)})",
                piece_arrays(schedule, pieces, k),
            )
        )
    return float(closest[k]), regions


def check_piece_continuity(
    pieces: Pieces, track: np.ndarray, schedule: Schedule, failures: list[str]
) -> None:
    """Position, velocity (and for jerk-limited schedules acceleration) continuous from piece to piece.

    Velocity and acceleration are compared along the track (``ds/dt``) where a
    vehicle stays on one leg, so a reversal hidden in a map change is a jump;
    through the junction (where ``s`` changes leg) along its own axis. The
    axis itself (each vehicle's odometer, exported beside ``s``) is continuous too.
    """
    if pieces.count < 2:
        return
    h = pieces.length[:-1]
    length_scale = max(1.0, float(np.max(np.abs(pieces.axis[:, :, 0]))), *schedule.route.graph.lengths)
    for vehicle in range(2):
        end_s = polynomials.evaluate(track[vehicle, :-1], h)
        start_s = track[vehicle, 1:, 0]
        jump = track_distance(pieces.leg[vehicle, :-1], end_s, pieces.leg[vehicle, 1:], start_s)
        same_leg = (pieces.leg[vehicle, :-1] == pieces.leg[vehicle, 1:]) & (
            pieces.leg[vehicle, 1:] != JUNCTION_INDEX
        )
        sign_before = np.where(same_leg, pieces.s_sign[vehicle, :-1], 1.0)
        sign_after = np.where(same_leg, pieces.s_sign[vehicle, 1:], 1.0)
        axis_end = polynomials.evaluate(pieces.axis[vehicle, :-1], h)
        checks = [("position", jump), ("axis", np.abs(axis_end - pieces.axis[vehicle, 1:, 0]))]
        derivative = pieces.axis[vehicle]
        names = ["velocity", "acceleration"][: schedule.smoothness]
        for name in names:
            derivative = polynomials.derivative(derivative)
            before = sign_before * polynomials.evaluate(derivative[:-1], h)
            after = sign_after * derivative[1:, 0]
            checks.append((name, np.abs(before - after)))
        for name, values in checks:
            quantity = "position" if name == "axis" else name
            tolerance = continuity_allowance(schedule, vehicle, quantity, length_scale)
            unit = {"position": "m", "axis": "m", "velocity": "m/s", "acceleration": "m/s^2"}[name]
            jumps = np.nonzero(~(values <= tolerance))[0]
            if jumps.size:
                k = int(jumps[0])
                at = float(pieces.start[k + 1])
                failures.append(
                    Finding(
                        f"vehicle {vehicle + 1} {name} jumps by {values[k]:.3g} {unit} at t={at:.6f} s "
                        f"({place(schedule, pieces, vehicle, k + 1, at)}, tolerance {tolerance:.3g} {unit})",
                        f"between {piece_arrays(schedule, pieces, k, (vehicle,))} and "
                        f"{piece_arrays(schedule, pieces, k + 1, (vehicle,))}",
                    )
                )


def check_maps(schedule: Schedule, failures: list[str]) -> None:
    """Each section's position maps are well formed: known legs, unit slopes, contiguous sub-ranges."""
    legs = len(schedule.route.graph.lengths)
    for index, section in enumerate(schedule.sections):
        start = float(section.start_time)
        window = f"t={start:.3f} to {start + float(section.duration):.3f} s"
        for vehicle, axis_map in enumerate(section.maps):
            where = f"sections[{index}].maps[{vehicle}]"
            who = f"vehicle {vehicle + 1}'s track map (where its axis lies on the track) for {window}"
            if not np.all(np.isin(axis_map.outward, (-1, 0, 1))):
                failures.append(
                    Finding(
                        f"{who}: map slopes {axis_map.outward.tolist()} are not -1, 0 or +1",
                        f"{where}.outward",
                    )
                )
            if not np.all((axis_map.legs >= JUNCTION_INDEX) & (axis_map.legs < legs)):
                failures.append(
                    Finding(
                        f"{who}: map legs {axis_map.legs.tolist()} are not track legs: expected "
                        f"{JUNCTION_INDEX} (the junction) or a leg index 0 to {legs - 1} ({legs} legs)",
                        f"{where}.legs",
                    )
                )
                continue
            at_junction = axis_map.legs == JUNCTION_INDEX
            if np.any(at_junction & ((axis_map.outward != 0) | (axis_map.s_start != 0.0))):
                failures.append(
                    Finding(
                        f"{who}: a map sub-range at the junction moves or lies off it",
                        f"{where}.{{legs,outward,s_start}}",
                    )
                )
            if np.any(~at_junction & (axis_map.s_start < -TRACK_END_TOLERANCE)):
                failures.append(
                    Finding(f"{who}: a map sub-range starts before the junction (s < 0)", f"{where}.s_start")
                )
            if axis_map.legs.size > 1:
                s_end = axis_map.s_start + axis_map.outward * (axis_map.axis_end - axis_map.axis_start)
                scale = max(1.0, float(np.max(np.abs(axis_map.axis_end))))
                gaps = np.abs(axis_map.axis_end[:-1] - axis_map.axis_start[1:])
                same = axis_map.legs[:-1] == axis_map.legs[1:]
                broken = np.where(
                    same, np.abs(s_end[:-1] - axis_map.s_start[1:]), s_end[:-1] + axis_map.s_start[1:]
                )
                if np.any(gaps > 1e-12 * scale) or np.any(broken > TRACK_END_TOLERANCE):
                    failures.append(
                        Finding(
                            f"{who}: map sub-ranges do not join (axis or track gap)",
                            f"{where}.{{axis_start,axis_end,s_start}}",
                        )
                    )


def check_parked(pieces: Pieces, schedule: Schedule, failures: list[str]) -> None:
    """A vehicle whose map says it stands still (slope 0) does not move its axis."""
    for vehicle in range(2):
        parked = pieces.s_sign[vehicle] == 0.0
        if not parked.any():
            continue
        low, _, high, _ = polynomials.extrema(
            polynomials.derivative(pieces.axis[vehicle][parked]), pieces.length[parked]
        )
        moving = np.maximum(np.abs(low), np.abs(high)) > allowance(schedule, vehicle, "velocity")
        if moving.any():
            k = int(np.nonzero(parked)[0][np.argmax(moving)])
            failures.append(
                Finding(
                    f"vehicle {vehicle + 1} moves at t={pieces.start[k]:.6f} s "
                    f"({place(schedule, pieces, vehicle, k, float(pieces.start[k]))}) where its schedule "
                    "says it stands still",
                    piece_arrays(schedule, pieces, k, (vehicle,)),
                )
            )
