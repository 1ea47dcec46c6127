"""The ``trajgen`` command line: parses arguments, runs the pipeline, prints the result.

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure (nothing written). ``trajgen simulate``
also exits 1 when the simulated run missed its goal or had violations (its
trace and plot are written: they are the evidence).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import sys
from collections.abc import Sequence

from trajgen.errors import InputError, OptionError
from trajgen.export import DEFAULT_MAX_ROWS, CsvOptions, Units
from trajgen.methods import METHODS, HomotopyChoice, Optimal
from trajgen.online.run import format_simulation, run_simulation
from trajgen.pipeline import Outputs, run
from trajgen.scenario import Scenario, default_scenario, load_scenario
from trajgen.schedule import TimingMethod
from trajgen.summary import format_route, format_run, route_summary

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_OK", "build_parser", "main"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2

logger = logging.getLogger(__name__)


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2) through our path."""

    def error(self, message: str):
        raise InputError(f"{self.prog}: {message}")


def _load(path: str | None) -> Scenario:
    return default_scenario() if path is None else load_scenario(path)


def _command_plan(args: argparse.Namespace) -> int:
    route = _load(args.scenario).plan()
    print(json.dumps(route_summary(route), indent=2) if args.json else format_route(route))
    return EXIT_OK


def _csv_dialect(args: argparse.Namespace) -> dict:
    """``--delimiter``, ``--decimal``, ``--units`` as keyword arguments of CsvOptions."""
    delimiter = "\t" if args.delimiter in ("tab", "\\t") else args.delimiter
    return {"delimiter": delimiter, "decimal": args.decimal, "units": Units.lookup(args.units)}


def _csv_options(args: argparse.Namespace) -> CsvOptions:
    return CsvOptions(sample_period=args.sample_period, max_rows=args.max_rows, **_csv_dialect(args))


def _command_schedule(args: argparse.Namespace) -> int:
    scenario = _load(args.scenario)
    outputs = Outputs(csv_dir=args.csv, plot_dir=args.plot, csv=_csv_options(args))
    summary = run(scenario, method=_method(args), outputs=outputs).summary()
    print(json.dumps(summary, indent=2) if args.json else format_run(summary))
    return EXIT_OK


def _command_demo(args: argparse.Namespace) -> int:
    scenario = default_scenario()
    result = run(scenario, method=_method(args), outputs=Outputs(csv_dir=args.output, plot_dir=args.output))
    print(f"Demo: the built-in scenario {scenario.source} (two AGVs swap ends of legs A and B).")
    print(format_route(result.route))
    print(format_run(result.summary()))
    print(f"CSV profiles and plots are in {args.output}/")
    return EXIT_OK


def _command_simulate(args: argparse.Namespace) -> int:
    scenario = _load(args.scenario)
    result, files = run_simulation(
        scenario,
        args.fault,
        period=args.period,
        method=args.method,
        position_margin=args.position_margin,
        trace_dir=args.trace,
        plot_dir=args.plot,
        csv_options=CsvOptions(**_csv_dialect(args)),
    )
    summary = {**result.summary(), "files": [str(path) for path in files]}
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


def _add_method(
    parser: argparse.ArgumentParser, *, what: str = "timing method", homotopy: bool = True
) -> None:
    parser.add_argument(
        "--method",
        default=METHODS.default,
        metavar="|".join(METHODS.names),
        help=f"{what}, one of:\n{METHODS.help()}",
    )
    if not homotopy:
        return
    parser.add_argument(
        "--homotopy",
        metavar="|".join(c.value for c in HomotopyChoice),
        help="optimal only: 'fastest' (default) solves both ways round the configuration circle and\n"
        "keeps the faster; 'paper' keeps the class of the paper's instruction",
    )


def _method(args: argparse.Namespace) -> TimingMethod:
    """The method object of ``--method`` with ``--homotopy`` applied."""
    method = METHODS.create(args.method)
    if args.homotopy is None:
        return method
    choice = HomotopyChoice.lookup(args.homotopy)
    if not isinstance(method, Optimal):
        raise OptionError(
            f"--homotopy {args.homotopy!r} applies to the method 'optimal' only, "
            f"got --method {method.name!r} "
            "(exact and toppra always take the paper's class)"
        )
    return dataclasses.replace(method, homotopy=choice)


def _add_csv_options(parser: argparse.ArgumentParser, *, sampling: bool = True) -> None:
    """The CSV dialect options; with ``sampling``, also ``--sample-period`` and ``--max-rows``."""
    if sampling:
        parser.add_argument(
            "--sample-period", type=float, default=0.01, help="seconds between CSV rows (0.01)"
        )
    parser.add_argument("--delimiter", default=";", help="CSV field separator (';'); 'tab' for a tab")
    parser.add_argument("--decimal", default=".", choices=[".", ","], help="decimal mark ('.')")
    parser.add_argument(
        "--units", default="m", choices=[u.value for u in Units], help="length unit of the CSV (m)"
    )
    if sampling:
        parser.add_argument(
            "--max-rows",
            type=int,
            default=DEFAULT_MAX_ROWS,
            help=f"refuse a CSV profile of more rows than this ({DEFAULT_MAX_ROWS:,})",
        )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``trajgen`` command."""
    parser = _ArgumentParser(
        prog="trajgen", description="Collision-free schedules for two AGVs on a Y-track."
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_ArgumentParser)

    demo = commands.add_parser(
        "demo",
        help="run the built-in swap scenario end to end",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    demo.add_argument("--output", default="trajgen-demo", help="folder for CSV and plots (trajgen-demo)")
    _add_method(demo)
    demo.set_defaults(run=_command_demo)

    plan_parser = commands.add_parser("plan", help="print the planner's route for a scenario file")
    plan_parser.add_argument("scenario", help="scenario TOML file")
    plan_parser.add_argument("--json", action="store_true", help="print a machine-readable summary")
    plan_parser.set_defaults(run=_command_plan)

    schedule = commands.add_parser(
        "schedule",
        help="schedule, verify and export a scenario",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    schedule.add_argument("scenario", help="scenario TOML file")
    _add_method(schedule)
    schedule.add_argument("--csv", metavar="DIR", help="write DIR/<vehicle name>.csv per vehicle")
    schedule.add_argument(
        "--plot", metavar="DIR", help="write DIR/speed.png, DIR/separation.png, DIR/coordination.png"
    )
    schedule.add_argument("--json", action="store_true", help="print a machine-readable summary")
    _add_csv_options(schedule)
    schedule.set_defaults(run=_command_schedule)

    simulate = commands.add_parser(
        "simulate",
        help="run a scenario in closed loop under faults (exit 1 if it misses the goal or has violations)",
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
        "  goal:NAME@T=LEG:S  at T s a new goal LEG:S (metres from the junction) is requested",
    )
    simulate.add_argument(
        "--period", type=float, default=0.01, help="control period, seconds (0.002 to 0.1; 0.01)"
    )
    _add_method(simulate, what="timing method of the undisturbed plan", homotopy=False)
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
    _add_csv_options(simulate, sampling=False)
    simulate.set_defaults(run=_command_simulate)
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
