"""Machine-readable (JSON-ready) and human-readable summaries of routes and runs.

A route's homotopy class is named for people by :func:`class_name`: on a Y
(three legs) the way round the boundary circle of the configuration space;
on a junction of four to eight legs, which route on the retract graph
``G_k`` it is (docs/star.md): the planner's shortest route (its
instruction), or the second-shortest, in another class.
"""

from __future__ import annotations

from topology import GraphRoute, Homotopy, Instruction, Route, WayRound

__all__ = [
    "class_label",
    "class_name",
    "format_graph_route",
    "format_provenance",
    "format_route",
    "format_run",
    "graph_route_summary",
    "provenance",
    "route_summary",
]

#: Four or more legs: the class of the planner's route by its instruction (``{graph}``: ``G_k``).
_PLANNER_CLASS = {
    Instruction.SHORTEST: "shortest route on {graph}",
    Instruction.TWO_TIED: "shortest route on {graph} (two tied)",
    Instruction.MANY_TIED: "shortest route on {graph} (three or more tied)",
}


def class_name(route: Route) -> str:
    """The route's homotopy class for people, without whose it is.

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


def graph_class_label(route: GraphRoute) -> str:
    """A route's class on a track graph in words: its moves in order, by the vehicles' names."""
    track, names = route.track, route.names
    return (
        "; ".join(
            f"{names[m.vehicle]} {track.name(m.points[0])} -> {track.name(m.points[-1])}" for m in route.moves
        )
        or "no move"
    )


def class_label(route: Route | GraphRoute) -> str:
    """The route's homotopy class for people: :func:`class_name` and whether it is the planner's.

    On a track graph: its moves in order (:func:`graph_class_label`).
    """
    if isinstance(route, GraphRoute):
        return graph_class_label(route)
    return _class_text(class_name(route), route.homotopy is Homotopy.PLANNED, route.graph.cycle is not None)


def _class_makespan(comparison: dict) -> str:
    if comparison["makespan_s"] is not None:
        return f"{comparison['makespan_s']:.3f} s"
    if comparison["failure"]:
        return f"failed ({comparison['failure']})"
    return "not solved (its lower bound cannot beat exact)"


def _class_text(name: str, paper: bool, circle: bool = True) -> str:
    """``name (whose)``: the paper's instruction on a Y (``circle``), the planner's on more legs."""
    whose = "the paper's" if circle else "the planner's"
    return f"{name} ({whose} instruction)" if paper else f"{name} (not {whose}: faster)"


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


def graph_route_summary(route: GraphRoute, names: tuple[str, str] = ("vehicle 1", "vehicle 2")) -> dict:
    """A JSON-ready summary of a route on a track graph: each vehicle's travel and the moves.

    Each move names the vehicle, where it starts and ends (``EDGE:s`` or a node), the nodes it
    passes, the edges it runs along, its length and where the other vehicle stands meanwhile.
    """
    track = route.track
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
                "other_at": track.name(move.standing),
            }
            for move in route.moves
        ],
        "critical_points": route.critical_points,
        "searched": route.searched,
    }


def format_graph_route(route: GraphRoute, names: tuple[str, str] = ("vehicle 1", "vehicle 2")) -> str:
    """Human-readable multi-line description of a route on a track graph."""
    summary = graph_route_summary(route, names)
    lines = [
        f"track: {summary['track']['nodes']} nodes, {summary['track']['edges']} edges, "
        f"{summary['track']['length_m']:g} m; minimum separation {route.min_separation:g} m",
        f"travel: {names[0]} {route.travel[0]:g} m, {names[1]} {route.travel[1]:g} m "
        f"({route.length:g} m in all, the least of any one-at-a-time route)",
        f"moves ({len(route.moves)}):",
    ]
    for number, move in enumerate(summary["moves"], start=1):
        lines.append(
            f"  {number:2d}  {move['vehicle']}: {move['from']} -> {move['to']} along "
            f"{', '.join(move['edges'])}, {move['length_m']:g} m (the other at {move['other_at']})"
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
        f"homotopy class: {class_label(route)}, regions "
        f"{' '.join(str(r) for r in route.regions) or '(one ray)'}",
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


def _route_class_text(route: dict) -> str:
    """The class line of a run's route summary (:func:`route_summary`)."""
    circle = "class" not in route
    return _class_text(route["way_round"] if circle else route["class"], route["planned_class"], circle)


def _graph_class_text(route: dict) -> str:
    """The class line of a route on a track graph: its moves in order (who goes where, who waits)."""
    moves = "; ".join(f"{m['vehicle']} {m['from']} -> {m['to']}" for m in route["moves"]) or "no move"
    return f"the planned route's, every conflict passed in its order ({moves})"


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
        f"worst margins: separation {margins['min_separation_m']:.4f} m "
        f"(margin {round(margins['separation_margin_m'], 4) + 0.0:.4f} m), "
        f"|v|/limit {max(margins['velocity_ratio']):.6f}, "
        f"|a|/limit {max(margins['acceleration_ratio']):.6f}{jerk}",
        f"homotopy class: {_route_class_text(summary['route'])}"
        if "moves" not in summary["route"]
        else f"class: {_graph_class_text(summary['route'])}",
    ]
    if summary["solver"] is not None:
        lines += [
            f"class {c.get('class', c['way_round'])} ({c['homotopy']}): "
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
            f"separation {export['min_separation_m']:.4f} m"
        )
    if summary["fallback_reason"]:
        lines.append(f"warning: fell back to the exact schedule ({summary['fallback_reason']})")
    lines += [f"wrote {path}" for path in summary["files"]]
    return "\n".join(lines)
