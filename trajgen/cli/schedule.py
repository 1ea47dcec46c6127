"""``trajgen plan``, ``trajgen schedule`` and ``trajgen demo``: the planner's route and the pipeline."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from topology import GraphRoute
from trajgen.cli.options import (
    add_csv_options,
    add_method,
    csv_options,
    method_from,
    scenario_from,
    scenario_method,
)
from trajgen.cli.parser import EXIT_OK
from trajgen.errors import OutputError, VerificationError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.model.summary import (
    closest_text,
    format_graph_route,
    format_route,
    format_run,
    graph_route_summary,
    route_summary,
)
from trajgen.pipeline import Outputs, run
from trajgen.scenario import BuiltinScenario, builtin_scenario
from trajgen.verification.graph_route import verify_graph_route

__all__ = ["register"]


def _command_plan(args: argparse.Namespace) -> int:
    picture = None
    if args.plot is not None:
        picture = Path(args.plot)
        if picture.suffix.lower() != ".png" or args.plot.endswith(("/", os.sep)):
            raise OutputError(
                f"--plot {args.plot!r} does not name a .png file: expected a file name ending in .png"
            )
        check_output_paths([picture])  # before planning: a bad path is refused at once
    scenario = scenario_from(args.scenario)
    route = scenario.route()
    if isinstance(route, GraphRoute):
        report = verify_graph_route(route)
        if not report.passed:  # neither printed nor drawn: the planner's route failed the verifier
            raise VerificationError(f"the planner's route fails the verifier: {'; '.join(report.failures)}")
        summary = graph_route_summary(route, scenario.names)
        summary |= {"verified": True, "closest_approach_m": report.closest}
        text = format_graph_route(route, scenario.names) + (
            f"\nverified: every move keeps {route.min_separation:g} m; "
            f"closest approach {closest_text(report.closest)}"
        )
    else:
        summary, text = route_summary(route), format_route(route)
    if picture is not None:
        commit_files({picture: _route_picture(route, scenario.names)})
    print(json.dumps(summary, indent=2) if args.json else text)
    return EXIT_OK


def _route_picture(route, names) -> bytes:
    """The PNG of a route: the track graph from above with the moves, or a junction's configurations."""
    from trajgen.plots import png_bytes  # matplotlib only when a picture is asked for

    if isinstance(route, GraphRoute):
        from trajgen.plots.graph_route import plot_graph_route

        return png_bytes(plot_graph_route(route, names=names))
    from trajgen.plots import plot_configuration

    return png_bytes(plot_configuration(route, names=names))


def _command_schedule(args: argparse.Namespace) -> int:
    scenario = scenario_from(args.scenario)
    outputs = Outputs(
        csv_dir=args.csv,
        plot_dir=args.plot,
        csv=csv_options(args),
        dialect=args.dialect,
        max_points=args.max_points,
    )
    summary = run(scenario, method=scenario_method(args, scenario), outputs=outputs).summary()
    print(json.dumps(summary, indent=2) if args.json else format_run(summary))
    return EXIT_OK


def _command_demo(args: argparse.Namespace) -> int:
    chosen = BuiltinScenario.lookup(args.scenario)
    scenario = builtin_scenario(chosen)
    if args.live:
        from trajgen.cli.live import live_demo  # the broker, the vehicles and the master

        return live_demo(
            scenario,
            method=method_from(args),
            time_scale=args.time_scale,
            state_rate=args.state_rate,
            output=args.output,
            json_summary=args.json,
        )
    result = run(
        scenario, method=method_from(args), outputs=Outputs(csv_dir=args.output, plot_dir=args.output)
    )
    if args.json:
        print(json.dumps(result.summary(), indent=2))
        return EXIT_OK
    print(f"Demo: the built-in scenario {scenario.source} ({chosen.description}).")
    route = result.route
    print(format_graph_route(route, scenario.names) if isinstance(route, GraphRoute) else format_route(route))
    print(format_run(result.summary()))
    print(f"CSV profiles and plots are in {args.output}/")
    return EXIT_OK


def register(commands) -> None:
    """Add ``demo``, ``plan`` and ``schedule`` to the sub-commands."""
    demo = commands.add_parser(
        "demo",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    demo.add_argument(
        "--scenario",
        default=BuiltinScenario.SWAP.value,
        metavar="|".join(b.value for b in BuiltinScenario),
        help="the built-in scenario, one of:\n"
        + "\n".join(f"{b.value}: {b.description}" for b in BuiltinScenario)
        + f"\n(default {BuiltinScenario.SWAP.value})",
    )
    demo.add_argument("--output", default="trajgen-demo", help="folder for CSV and plots (trajgen-demo)")
    demo.add_argument(
        "--live",
        action="store_true",
        help="drive it live instead: an MQTT broker, two simulated VDA 5050 vehicles and the\n"
        "master in this process; writes live-run.jsonl and live-run.png",
    )
    demo.add_argument(
        "--time-scale", type=float, default=4.0, metavar="K", help="with --live: K times real time (4)"
    )
    demo.add_argument(
        "--state-rate",
        type=float,
        default=1.0,
        metavar="HZ",
        help="with --live: each vehicle's states per second of the run, besides those on events (1)",
    )
    demo.add_argument(
        "--json", action="store_true", help="print a machine-readable summary (of the live run with --live)"
    )
    add_method(demo)
    demo.set_defaults(run=_command_demo)

    plan_parser = commands.add_parser("plan")
    plan_parser.add_argument("scenario", help="scenario TOML file")
    plan_parser.add_argument("--json", action="store_true", help="print a machine-readable summary")
    plan_parser.add_argument(
        "--plot",
        metavar="FILE.png",
        help="draw the route into FILE.png: a track graph from above with the numbered moves, or "
        "a junction's configuration space with the route",
    )
    plan_parser.set_defaults(run=_command_plan)

    schedule = commands.add_parser(
        "schedule",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    schedule.add_argument("scenario", help="scenario TOML file")
    add_method(schedule)
    schedule.add_argument(
        "--csv", metavar="DIR", help="write DIR/<vehicle name>.csv per vehicle (.txt for codesys-xy)"
    )
    schedule.add_argument(
        "--plot",
        metavar="DIR",
        help="write DIR/speed.png, DIR/separation.png, DIR/coordination.png, DIR/layout.png\n"
        "(the track from above with each vehicle's moves, numbered); on a junction also\n"
        "DIR/configuration.png (the configuration space drawn flat: route and retraction;\n"
        "4 to 8 legs: the retract graph G_k with the route)",
    )
    schedule.add_argument("--json", action="store_true", help="print a machine-readable summary")
    add_csv_options(schedule)
    schedule.set_defaults(run=_command_schedule)
