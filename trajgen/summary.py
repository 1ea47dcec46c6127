"""Machine-readable (JSON-ready) and human-readable summaries of routes and runs."""

from __future__ import annotations

from topology import Homotopy, Route

__all__ = ["class_label", "format_route", "format_run", "route_summary"]


def class_label(route: Route) -> str:
    """The route's homotopy class for people: its way round and whether it is the paper's."""
    return _class_text(route.way_round.value, route.homotopy is Homotopy.PAPER)


def _class_makespan(comparison: dict) -> str:
    if comparison["makespan_s"] is not None:
        return f"{comparison['makespan_s']:.3f} s"
    if comparison["failure"]:
        return f"failed ({comparison['failure']})"
    return "not solved (its lower bound cannot beat exact)"


def _class_text(way_round: str, paper: bool) -> str:
    whose = "the paper's instruction" if paper else "not the paper's: faster"
    return f"{way_round} ({whose})"


def route_summary(route: Route) -> dict:
    """A JSON-ready summary of a route."""
    return {
        "instruction": route.instruction.value,
        "waypoints": [[{"leg": p.leg, "s_m": p.s} for p in (w.first, w.second)] for w in route.waypoints],
        "regions": [str(r) for r in route.regions],
        "homotopy": route.homotopy.value,
        "paper_class": route.homotopy is Homotopy.PAPER,
        "way_round": route.way_round.value,
        "arc_length_m": route.arc_length,
        "travel_m": list(route.travel),
        "min_separation_m": route.min_separation,
    }


def format_route(route: Route) -> str:
    """Human-readable multi-line description of a route."""
    lines = [
        f"instruction: {route.instruction.value}",
        f"homotopy class: {class_label(route)}, regions "
        f"{' '.join(str(r) for r in route.regions) or '(one ray)'}",
        f"travel: vehicle 1 {route.travel[0]:g} m, vehicle 2 {route.travel[1]:g} m",
        "waypoints (vehicle 1, vehicle 2):",
    ]
    lines += [f"  {k:2d}  {w}" for k, w in enumerate(route.waypoints)]
    return "\n".join(lines)


def format_run(summary: dict) -> str:
    """Human-readable lines of a run's JSON summary (:meth:`trajgen.pipeline.RunResult.summary`)."""
    margins = summary["worst_margins"]
    jerk = (
        f", |j|/limit {max(margins['jerk_ratio']):.6f}" if summary["jerk_limited"] else ", jerk not limited"
    )
    lines = [
        f"scenario: {summary['scenario']}",
        f"method: {summary['method']}  duration: {summary['duration_s']:.3f} s  "
        f"verified: {summary['verified']}",
        f"worst margins: separation {margins['min_separation_m']:.4f} m "
        f"(margin {margins['separation_margin_m']:.4f} m), |v|/limit {max(margins['velocity_ratio']):.6f}, "
        f"|a|/limit {max(margins['acceleration_ratio']):.6f}{jerk}",
        f"homotopy class: {_class_text(summary['route']['way_round'], summary['route']['paper_class'])}",
    ]
    if summary["solver"] is not None:
        lines += [
            f"class {c['way_round']} ({c['homotopy']}): "
            + _class_makespan(c)
            + f", lower bound {c['lower_bound_s']:.3f} s"
            + (" <- chosen" if c["chosen"] else "")
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
