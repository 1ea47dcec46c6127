"""The ``trajgen`` command line.

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from topology import Route, plan
from topology.errors import InputError
from trajgen.scenario import Scenario, default_scenario, load_scenario

__all__ = ["main"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2

logger = logging.getLogger(__name__)


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2) through our path."""

    def error(self, message: str):
        raise InputError(f"{self.prog}: {message}")


def route_summary(route: Route) -> dict:
    """A JSON-ready summary of a route."""
    return {
        "instruction": route.instruction.value,
        "waypoints": [[{"leg": p.leg, "s_m": p.s} for p in (w.first, w.second)] for w in route.waypoints],
        "regions": [str(r) for r in route.regions],
        "travel_m": list(route.travel),
        "min_separation_m": route.min_separation,
    }


def format_route(route: Route) -> str:
    """Human-readable multi-line description of a route."""
    lines = [
        f"instruction: {route.instruction.value}",
        f"homotopy class (regions): {' '.join(str(r) for r in route.regions) or '(one ray)'}",
        f"travel: vehicle 1 {route.travel[0]:g} m, vehicle 2 {route.travel[1]:g} m",
        "waypoints (vehicle 1, vehicle 2):",
    ]
    lines += [f"  {k:2d}  {w}" for k, w in enumerate(route.waypoints)]
    return "\n".join(lines)


def _load(path: str | None) -> Scenario:
    return default_scenario() if path is None else load_scenario(path)


def _plan_scenario(scenario: Scenario) -> Route:
    return plan(scenario.track, scenario.start, scenario.goal, min_separation=scenario.limits.min_separation)


def _command_plan(args: argparse.Namespace) -> int:
    route = _plan_scenario(_load(args.scenario))
    print(json.dumps(route_summary(route), indent=2) if args.json else format_route(route))
    return EXIT_OK


def _csv_options(args: argparse.Namespace):
    from trajgen.export import CsvOptions, Units

    delimiter = "\t" if args.delimiter in ("tab", "\\t") else args.delimiter
    return CsvOptions(
        sample_period=args.sample_period,
        delimiter=delimiter,
        decimal=args.decimal,
        units=Units.lookup(args.units),
    )


def run_schedule(
    scenario: Scenario, *, method: str, csv_dir: str | None, plot_dir: str | None, csv_options=None
) -> dict:
    """Plan, schedule, verify, then export: the whole job. Returns the JSON summary.

    Nothing is written unless the schedule passes the verifier.
    """
    from trajgen.export import write_profiles
    from trajgen.schedule import Method, make_schedule
    from trajgen.verify import verified

    method = Method.lookup(method)
    route = _plan_scenario(scenario)
    schedule = make_schedule(route, scenario.limits, method=method)
    report = verified(schedule)
    written: list[str] = []
    if csv_dir is not None:
        _, paths = write_profiles(schedule, scenario.names, csv_dir, options=csv_options)
        written += [str(p) for p in paths]
    if plot_dir is not None:
        from trajgen.plotting import plot_coordination, write_plots

        written += [str(p) for p in write_plots(schedule, plot_dir, names=scenario.names)]
        # the coordination diagram compares all three methods on this route
        others = {
            m.value: schedule if m is method else make_schedule(route, scenario.limits, method=m)
            for m in Method
        }
        written.append(str(plot_coordination(others, Path(plot_dir) / "coordination.png")))
    info = schedule.info
    return {
        "scenario": scenario.source,
        "method": method.value,
        "duration_s": schedule.duration,
        "jerk_limited": schedule.jerk_limited,
        "verified": report.passed,
        "worst_margins": report.summary(),
        "notes": list(schedule.notes),
        "fallback_reason": schedule.fallback_reason,
        "solver": None
        if info is None
        else {
            "solve_time_s": info.solve_time,
            "built": info.built,
            "iterations": info.iterations,
            "status": info.status,
            "source": info.source,
        },
        "route": route_summary(route),
        "files": written,
    }


def _print_schedule_summary(summary: dict) -> None:
    margins = summary["worst_margins"]
    print(f"scenario: {summary['scenario']}")
    print(
        f"method: {summary['method']}  duration: {summary['duration_s']:.3f} s  "
        f"verified: {summary['verified']}"
    )
    print(
        f"worst margins: separation {margins['min_separation_m']:.4f} m "
        f"(margin {margins['separation_margin_m']:.4f} m), |v|/limit {max(margins['velocity_ratio']):.6f}, "
        f"|a|/limit {max(margins['acceleration_ratio']):.6f}"
        + (
            f", |j|/limit {max(margins['jerk_ratio']):.6f}"
            if summary["jerk_limited"]
            else ", jerk not limited"
        )
    )
    for note in summary["notes"]:
        print(f"note: {note}")
    if summary["fallback_reason"]:
        print(f"warning: fell back to the exact schedule: {summary['fallback_reason']}")
    for path in summary["files"]:
        print(f"wrote {path}")


def _command_schedule(args: argparse.Namespace) -> int:
    scenario = _load(args.scenario)
    options = _csv_options(args)
    summary = run_schedule(
        scenario, method=args.method, csv_dir=args.csv, plot_dir=args.plot, csv_options=options
    )
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_schedule_summary(summary)
    return EXIT_OK


def _command_demo(args: argparse.Namespace) -> int:
    scenario = default_scenario()
    output = args.output
    print(f"Demo: the built-in scenario {scenario.source} (two AGVs swap ends of legs A and B).")
    print(format_route(_plan_scenario(scenario)))
    summary = run_schedule(scenario, method=args.method, csv_dir=output, plot_dir=output)
    _print_schedule_summary(summary)
    print(f"CSV profiles and plots are in {output}/")
    return EXIT_OK


def _add_csv_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--sample-period", type=float, default=0.01, help="seconds between CSV rows (0.01)")
    parser.add_argument("--delimiter", default=";", help="CSV field separator (';'); 'tab' for a tab")
    parser.add_argument("--decimal", default=".", choices=[".", ","], help="decimal mark ('.')")
    parser.add_argument("--units", default="m", choices=["m", "mm"], help="length unit of the CSV (m)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``trajgen`` command."""
    parser = _ArgumentParser(
        prog="trajgen", description="Collision-free schedules for two AGVs on a Y-track."
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_ArgumentParser)

    demo = commands.add_parser("demo", help="run the built-in swap scenario end to end")
    demo.add_argument("--output", default="trajgen-demo", help="folder for CSV and plots (trajgen-demo)")
    demo.add_argument("--method", default="optimal", help="exact, toppra or optimal (%(default)s)")
    demo.set_defaults(run=_command_demo)

    plan_parser = commands.add_parser("plan", help="print the planner's route for a scenario file")
    plan_parser.add_argument("scenario", help="scenario TOML file")
    plan_parser.add_argument("--json", action="store_true", help="print a machine-readable summary")
    plan_parser.set_defaults(run=_command_plan)

    schedule = commands.add_parser("schedule", help="schedule, verify and export a scenario")
    schedule.add_argument("scenario", help="scenario TOML file")
    schedule.add_argument("--method", default="optimal", help="exact, toppra or optimal (%(default)s)")
    schedule.add_argument("--csv", metavar="DIR", help="write DIR/<vehicle name>.csv per vehicle")
    schedule.add_argument(
        "--plot", metavar="DIR", help="write DIR/speed.png, DIR/separation.png, DIR/coordination.png"
    )
    schedule.add_argument("--json", action="store_true", help="print a machine-readable summary")
    _add_csv_options(schedule)
    schedule.set_defaults(run=_command_schedule)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    try:
        args = build_parser().parse_args(argv)
        logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(message)s")
        return args.run(args)
    except InputError as error:
        print(f"trajgen: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as error:
        logger.debug("internal failure", exc_info=True)
        print(f"trajgen: internal failure: {type(error).__name__}: {error}", file=sys.stderr)
        return EXIT_FAILURE
