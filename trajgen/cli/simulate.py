"""``trajgen simulate``: a scenario in closed loop under faults."""

from __future__ import annotations

import argparse
import json
import sys

from trajgen.cli.options import add_csv_options, add_method, csv_dialect, scenario_from
from trajgen.cli.parser import EXIT_FAILURE, EXIT_OK

__all__ = ["register"]


def _command_simulate(args: argparse.Namespace) -> int:
    from trajgen.export.csv import CsvOptions
    from trajgen.simulation_pipeline import format_simulation, run_simulation  # the executor and its Ruckig

    scenario = scenario_from(args.scenario)
    run = run_simulation(
        scenario,
        args.fault,
        period=args.period,
        method=args.method,
        position_margin=args.position_margin,
        trace_dir=args.trace,
        plot_dir=args.plot,
        csv_options=CsvOptions(**csv_dialect(args)),
    )
    result, summary = run.result, run.summary()
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(format_simulation(summary, min_separation=scenario.limits.min_separation))
    failures = []
    if not result.reached_goal:
        failures.append("did not reach the goal")
    if result.violations:
        failures.append(f"had {result.violations} violation{'s' if result.violations != 1 else ''}")
    if failures:
        print(f"trajgen: the simulated run {' and '.join(failures)}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def register(commands) -> None:
    """Add ``simulate`` to the sub-commands."""
    simulate = commands.add_parser(
        "simulate",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    simulate.add_argument("scenario", help="scenario TOML file")
    simulate.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="SPEC",
        help="a fault of the simulated plant, repeatable:\n"
        "  stop:NAME@T+D    NAME stops at T s for D s\n"
        "  slow:NAME@T=V    from T s NAME's drive cannot exceed V m/s (below its max_velocity)\n"
        "  lag:NAME@T=MS    from T s NAME follows its setpoints MS ms late (at most 200)\n"
        "  jump:NAME@T=DS   at T s NAME's measured position is corrected by DS m\n"
        "                   (|DS| at most --position-margin)\n"
        "  goal:NAME@T=LEG:S  at T s a new goal LEG:S (metres from the junction) is requested;\n"
        "                   on a track graph EDGE:S (metres from the edge's from node) or a node",
    )
    simulate.add_argument(
        "--period", type=float, default=0.01, help="control period, seconds (0.002 to 0.1; 0.01)"
    )
    add_method(simulate, what="timing method of the undisturbed plan", homotopy=False)
    simulate.add_argument(
        "--position-margin",
        type=float,
        default=0.05,
        help="the executor's position margin, metres (0.05); also the largest jump",
    )
    simulate.add_argument(
        "--trace",
        metavar="DIR",
        help="write DIR/<vehicle name>.csv per vehicle: the executed motion, one row per period",
    )
    simulate.add_argument(
        "--plot", metavar="DIR", help="write DIR/simulation.png (planned vs executed speed, separation)"
    )
    simulate.add_argument("--json", action="store_true", help="print a machine-readable summary")
    add_csv_options(simulate, sampling=False)
    simulate.set_defaults(run=_command_simulate)
