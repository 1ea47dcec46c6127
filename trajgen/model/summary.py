"""Machine-readable (JSON-ready) and human-readable summaries of routes and runs.

Every summary names a route's class in the same words (:func:`class_label`): ``planned`` (the
class of the planner's route) or ``other``, and which it is in brackets: on a Y (three legs) its
way round the boundary circle of the configuration space (``planned (counterclockwise)``); on a
junction of four to eight legs which route on the retract graph ``G_k`` it is (docs/star.md:
``other (second-shortest route on G_4)``); on a track graph its moves, in order
(``planned (agv1 A -> c:1.5; agv2 D -> A; agv1 c:1.5 -> D)``). :func:`class_name` is the part in
brackets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from topology import GraphRoute, Homotopy, Instruction, Route, WayRound

__all__ = [
    "DISTANCE_PLACES",
    "ROUND_OFF_M",
    "both_or_all",
    "class_label",
    "class_name",
    "class_words",
    "closest_text",
    "format_graph_route",
    "format_provenance",
    "format_route",
    "format_run",
    "graph_route_summary",
    "provenance",
    "route_summary",
    "summary_class_label",
]

#: Decimal places of a closest approach and its margin, in the summaries and on the plots (metres).
DISTANCE_PLACES = 4
#: Round-off forgiven before a distance is rounded down, metres: the verifier's POSITION_TOLERANCE
#: (a separation it accepts as kept is not shown below the minimum).
ROUND_OFF_M = 1e-9

#: Four or more legs: the class of the planner's route by its instruction (``{graph}``: ``G_k``).
_PLANNER_CLASS = {
    Instruction.SHORTEST: "shortest route on {graph}",
    Instruction.TWO_TIED: "shortest route on {graph} (two tied)",
    Instruction.MANY_TIED: "shortest route on {graph} (three or more tied)",
}


def class_name(route: Route) -> str:
    """Which class the route is in, in words: the part in brackets of :func:`class_label`.

    Three legs: its way round the boundary circle (``counterclockwise``,
    ``clockwise`` or ``none``). Four to eight legs: which route on ``G_k`` it
    is, e.g. ``shortest route on G_4`` (the planner's, by its instruction) or
    ``second-shortest route on G_4`` (``plan(..., homotopy="other")``).

    Examples
    --------
    >>> from topology import Configuration, Position, StarGraph, plan
    >>> crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    >>> start = Configuration(Position("N", 10.0), Position("S", 10.0))
    >>> class_name(plan(crossing, start, start.swapped(), homotopy="other"))
    'second-shortest route on G_4'
    """
    if route.graph.cycle is not None:
        return route.way_round.value
    graph = f"G_{route.graph.leg_count}"
    if route.way_round is WayRound.NONE:
        return f"none (start and goal retract to one point of {graph})"
    if route.homotopy is Homotopy.OTHER:
        return f"second-shortest route on {graph}"
    return _PLANNER_CLASS[route.instruction].format(graph=graph)


def both_or_all(count: int) -> str:
    """How the messages say "every vehicle" of ``count``: ``both`` of two, ``all`` of more.

    Examples
    --------
    >>> both_or_all(2), both_or_all(4)
    ('both', 'all')
    """
    return "both" if count == 2 else "all"


def closest_text(metres: float) -> str:
    """A closest approach (or a separation margin) for people: ``1.5000 m``, rounded down.

    Rounded down to :data:`DISTANCE_PLACES` places, so the figure shown is never above the value
    (1.49996 m is ``1.4999 m``, not ``1.5000 m``, which would hide that it is below a 1.5 m
    minimum), after forgiving :data:`ROUND_OFF_M` of round-off (1.4999999999 m, a separation
    kept exactly, is ``1.5000 m``). A value that is not finite is written as Python writes it.

    Examples
    --------
    >>> closest_text(1.5000009912), closest_text(1.49996), closest_text(-0.00004)
    ('1.5000 m', '1.4999 m', '-0.0001 m')
    """
    if not math.isfinite(metres):
        return f"{metres} m"
    scale = 10**DISTANCE_PLACES
    shown = math.floor((metres + ROUND_OFF_M) * scale) / scale + 0.0  # + 0.0: no "-0.0000"
    return f"{shown:.{DISTANCE_PLACES}f} m"


def class_words(homotopy: str, name: str) -> str:
    """A class as every summary names it: ``planned (counterclockwise)``, ``other (...)``.

    Parameters
    ----------
    homotopy : str
        ``"planned"`` (the class of the planner's route) or ``"other"``
        (:class:`topology.Homotopy` values).
    name : str
        Which class it is (:func:`class_name`, or a track graph's moves).

    Examples
    --------
    >>> class_words("other", "clockwise")
    'other (clockwise)'
    """
    return f"{Homotopy(homotopy).value} ({name})"


def graph_class_label(route: GraphRoute) -> str:
    """A route's class on a track graph in words: its moves in order, by the vehicles' names.

    The parts of a joint move are joined by ``&`` (they happen at once).
    """
    track, names = route.track, route.names
    return (
        "; ".join(
            " & ".join(
                f"{names[m.vehicle]} {track.name(m.points[0])} -> {track.name(m.points[-1])}" for m in step
            )
            for step in route.steps
        )
        or "no move"
    )


def class_label(route: Route | GraphRoute, *, planned: bool | None = None) -> str:
    """The route's class as every summary names it: ``planned`` or ``other``, and which (:func:`class_words`).

    Parameters
    ----------
    route : Route or GraphRoute
    planned : bool, optional
        A track graph's route only: whether it is in the class of the planner's route (a
        :class:`~topology.GraphRoute` does not know; ``optimal`` may take another). Not given: its
        moves alone (:func:`graph_class_label`).

    Examples
    --------
    >>> from topology import Configuration, Position, YGraph, plan
    >>> track = YGraph({"A": 10.0, "B": 10.0, "C": 10.0})
    >>> start = Configuration(Position("A", 10.0), Position("B", 10.0))
    >>> class_label(plan(track, start, start.swapped(), min_separation=1.5))
    'planned (counterclockwise)'
    >>> class_label(plan(track, start, start.swapped(), min_separation=1.5, homotopy="other"))
    'other (clockwise)'
    """
    if isinstance(route, GraphRoute):
        if route.label is not None and planned is None:  # a junction's route keeps the paper's class
            return route.label
        moves = graph_class_label(route)
        return moves if planned is None else class_words("planned" if planned else "other", moves)
    return class_words(route.homotopy.value, class_name(route))


def _class_makespan(comparison: dict) -> str:
    if comparison["makespan_s"] is not None:
        return f"{comparison['makespan_s']:.3f} s"
    if comparison["failure"]:
        return f"failed ({comparison['failure']})"
    return "not solved (its lower bound cannot beat exact)"


def route_summary(route: Route) -> dict:
    """A JSON-ready summary of a route.

    Four or more legs add ``legs`` (k) and ``class`` (:func:`class_name`); ``way_round`` is
    ``graph`` there and ``arc_length_m`` the route's length on ``G_k``.
    """
    summary = {
        "instruction": route.instruction.value,
        "waypoints": [[{"leg": p.leg, "s_m": p.s} for p in (w.first, w.second)] for w in route.waypoints],
        "regions": [str(r) for r in route.regions],
        "homotopy": route.homotopy.value,
        "planned_class": route.homotopy is Homotopy.PLANNED,
        "way_round": route.way_round.value,
        "arc_length_m": route.arc_length,
        "travel_m": list(route.travel),
        "min_separation_m": route.min_separation,
    }
    if route.graph.cycle is None:
        summary["legs"] = route.graph.leg_count
        summary["class"] = class_name(route)
    return summary


def graph_route_summary(route: GraphRoute, names: Sequence[str] | None = None) -> dict:
    """A JSON-ready summary of a route on a track graph: each vehicle's travel and the moves.

    Each move names the vehicle, where it starts and ends (``EDGE:s`` or a node), the nodes it
    passes, the edges it runs along, its length and where each other vehicle stands meanwhile
    (``standing``: name to place); a part of a joint move names the vehicles that move with it
    (``with``). ``names``: the vehicles' (default the route's).
    """
    track = route.track
    names = route.names if names is None else tuple(names)
    return {
        "track": {"nodes": len(track.nodes), "edges": track.edge_count, "length_m": track.total_length},
        "min_separation_m": route.min_separation,
        "start": [track.name(p) for p in route.start],
        "goal": [track.name(p) for p in route.goal],
        "travel_m": list(route.travel),
        "length_m": route.length,
        "moves": [
            {
                "vehicle": names[move.vehicle],
                "from": track.name(move.points[0]),
                "to": track.name(move.points[-1]),
                "via": [track.name(p) for p in move.points[1:-1]],
                "edges": [track.edges[e].name for e in move.edges],
                "length_m": move.length,
                "standing": {names[v]: track.name(point) for v, point in move.standing()},
                **({"with": [names[v] for v in move.movers if v != move.vehicle]} if move.joint else {}),
            }
            for move in route.moves
        ],
        "critical_points": route.critical_points,
        "searched": route.searched,
        **({"label": route.label} if route.label is not None else {}),
    }


def _meanwhile(move: dict) -> list[str]:
    """What the other vehicles do during a move of the summary: where each stands, who moves with it."""
    said = [", ".join(f"{name} at {place}" for name, place in move["standing"].items())]
    if "with" in move:
        said.append("with " + ", ".join(move["with"]))
    return [text for text in said if text]


def format_graph_route(route: GraphRoute, names: Sequence[str] | None = None) -> str:
    """Human-readable multi-line description of a route on a track graph (``names``: as the summary's)."""
    names = route.names if names is None else tuple(names)
    summary = graph_route_summary(route, names)
    travel = ", ".join(f"{name} {metres:g} m" for name, metres in zip(names, route.travel, strict=True))
    lines = [
        f"track: {summary['track']['nodes']} nodes, {summary['track']['edges']} edges, "
        f"{summary['track']['length_m']:g} m; minimum separation {route.min_separation:g} m",
        f"travel: {travel} ({route.length:g} m in all, "
        + (f"class {route.label})" if route.label else "the least of any one-at-a-time route)"),
        f"moves ({len(route.moves)}):",
    ]
    for number, move in enumerate(summary["moves"], start=1):
        lines.append(
            f"  {number:2d}  {move['vehicle']}: {move['from']} -> {move['to']} along "
            f"{', '.join(move['edges'])}, {move['length_m']:g} m "
            f"({'; '.join(_meanwhile(move))})"
        )
    return "\n".join(lines)


def format_route(route: Route) -> str:
    """Human-readable multi-line description of a route.

    Four or more legs also name the planner's three instructions and the route's length on ``G_k``.
    """
    graph = route.graph
    instructions = Instruction.of_track(graph)
    lines = [
        f"instruction: {route.instruction.value}",
        f"class: {class_label(route)}, regions {' '.join(str(r) for r in route.regions) or '(one ray)'}",
        f"travel: vehicle 1 {route.travel[0]:g} m, vehicle 2 {route.travel[1]:g} m",
        "waypoints (vehicle 1, vehicle 2):",
    ]
    if graph.cycle is None:  # four or more legs: the planner's three instructions and the route on G_k
        lines[0] += f" (of {', '.join(i.value for i in instructions)} on {graph.leg_count} legs)"
        lines.insert(
            2,
            f"length on G_{graph.leg_count}: {route.arc_length:g} m (of {graph.boundary_length:g} m in all)",
        )
    lines += [f"  {k:2d}  {w}" for k, w in enumerate(route.waypoints)]
    return "\n".join(lines)


def summary_class_label(route: dict) -> str:
    """The class of a run's route summary (``summary["route"]``), in :func:`class_label`'s words.

    A junction's (:func:`route_summary`): ``planned (counterclockwise)``; a track graph's
    (:func:`graph_route_summary` with ``homotopy``): ``planned (agv1 A -> B; ...)``.
    """
    if "moves" in route:  # a track graph: its moves in order (who goes where, who waits)
        moves = "; ".join(f"{m['vehicle']} {m['from']} -> {m['to']}" for m in route["moves"]) or "no move"
        return moves if "homotopy" not in route else class_words(route["homotopy"], moves)
    return class_words(route["homotopy"], route.get("class", route["way_round"]))


def _chosen_mark(comparison: dict, *, fallback: bool) -> str:
    """`` <- chosen`` for the class whose solution was returned; nothing for a class that failed."""
    if not comparison["chosen"]:
        return ""
    if comparison["failure"] is not None or fallback:
        return " (the exact fallback keeps this class)"
    return " <- chosen"


def provenance(schedule, asked: str) -> dict:
    """Which method was asked for and which computed ``schedule``, JSON-ready.

    ``method`` (asked for), ``computed_by`` (``exact`` after a fallback), ``fallback_reason``
    (``None`` or a :class:`~trajgen.model.schedule.FallbackReason` value) and
    ``time_limit_reached`` (the method's safety stop ended its work early: the only way the same
    request can give another schedule on another machine or under load).
    """
    info = None if schedule.info is None else schedule.info.summary()
    return {
        "method": asked,
        "computed_by": schedule.method.name,
        "fallback_reason": None if schedule.fallback_reason is None else schedule.fallback_reason.value,
        "time_limit_reached": bool(info is not None and info.get("time_limit_reached", False)),
    }


def format_provenance(summary: dict) -> str:
    """``method`` for people: ``optimal``, or ``exact (fallback from optimal: time-limit)``."""
    text = summary["computed_by"]
    if summary["fallback_reason"] is not None:
        text += f" (fallback from {summary['method']}: {summary['fallback_reason']})"
    elif summary["computed_by"] != summary["method"]:
        text += f" (asked for {summary['method']})"
    if summary.get("time_limit_reached"):
        text += ", refinement ended by the time limit"
    return text


def format_run(summary: dict) -> str:
    """Human-readable lines of a run's JSON summary (:meth:`trajgen.pipeline.RunResult.summary`)."""
    margins = summary["worst_margins"]
    jerk = (
        f", |j|/limit {max(margins['jerk_ratio']):.6f}" if summary["jerk_limited"] else ", jerk not limited"
    )
    lines = [
        f"scenario: {summary['scenario']}",
        f"method: {format_provenance(summary)}  duration: {summary['duration_s']:.3f} s  "
        f"verified: {summary['verified']}",
        f"worst margins: separation {closest_text(margins['min_separation_m'])} "
        f"(margin {closest_text(margins['separation_margin_m'])}), "
        f"|v|/limit {max(margins['velocity_ratio']):.6f}, "
        f"|a|/limit {max(margins['acceleration_ratio']):.6f}{jerk}",
        f"class: {summary_class_label(summary['route'])}",
    ]
    if summary["solver"] is not None:
        lines += [
            f"class {class_words(c['homotopy'], c.get('class', c['way_round']))}: "
            + _class_makespan(c)
            + f", lower bound {c['lower_bound_s']:.3f} s"
            + _chosen_mark(c, fallback=summary["fallback_reason"] is not None)
            for c in summary["solver"].get("classes", ())
        ]
    lines += [f"note: {note}" for note in summary["notes"]]
    export = summary.get("export")
    if export is not None:
        slower = (
            f", {100.0 * (export['time_scale'] - 1.0):.4f} % slower to fit the limits as interpolated"
            if export["time_scale"] > 1.0
            else ""
        )
        lines.append(
            f"{export['dialect']} tables: {export['points'][0]} and {export['points'][1]} points "
            f"(limit {export['point_limit']:,}, {export['interpolation']}), worst error "
            f"{1e3 * max(export['position_error_m']):.3g} mm and "
            f"{1e3 * max(export['velocity_error_mps']):.3g} mm/s{slower}; verified as interpolated: "
            f"separation {closest_text(export['min_separation_m'])}"
        )
    if summary["fallback_reason"]:
        lines.append(f"warning: fell back to the exact schedule ({summary['fallback_reason']})")
    lines += [f"wrote {path}" for path in summary["files"]]
    return "\n".join(lines)
