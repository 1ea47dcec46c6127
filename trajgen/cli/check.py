"""``trajgen check``: verify profile files against a scenario (exit 0 pass, 1 violations, 2 unreadable)."""

from __future__ import annotations

import argparse
import json

from trajgen.cli.options import add_dialect_options, scenario_from
from trajgen.cli.parser import EXIT_FAILURE, EXIT_OK

__all__ = ["SHOWN_FAILURES", "register"]

#: Violations printed without --json (the JSON lists all).
SHOWN_FAILURES = 10


def _command_check(args: argparse.Namespace) -> int:
    from trajgen.export.plc.check import check_profiles

    scenario = scenario_from(args.scenario)
    verdict = check_profiles(
        scenario, args.csv, dialect=args.dialect, jerk=not args.ignore_jerk, max_points=args.max_points
    )
    summary = verdict.summary()
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"scenario: {scenario.source}")
        print(f"files ({summary['dialect']}): {', '.join(summary['files'])}")
        print(
            f"points: {summary['points'][0]} and {summary['points'][1]}; closest approach "
            f"{summary['min_separation_m']:.4f} m (minimum {scenario.limits.min_separation:g} m); "
            + (
                f"homotopy class: {summary['homotopy']}"
                + (f" ({summary['class']})" if "class" in summary else "")
                if "homotopy" in summary
                else f"class: {summary['class']}"
            )
        )
        failures = summary["failures"]
        for failure in failures[:SHOWN_FAILURES]:
            print(f"violation: {failure}")
        if len(failures) > SHOWN_FAILURES:
            print(f"... and {len(failures) - SHOWN_FAILURES} more (--json lists all)")
        if not verdict.passed and not args.ignore_jerk and any("jerk" in failure for failure in failures):
            # a toppra schedule's files fail here by design: say how to check them for what it keeps
            print(
                "note: a schedule timed by toppra does not limit jerk; check its files for the "
                "separation, velocity and acceleration alone with --ignore-jerk"
            )
        print("PASS: the files keep the separation and the limits" if verdict.passed else "FAIL")
    return EXIT_OK if verdict.passed else EXIT_FAILURE


def register(commands) -> None:
    """Add ``check`` to the sub-commands."""
    check = commands.add_parser(
        "check",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    check.add_argument("scenario", help="scenario TOML file")
    check.add_argument("--csv", metavar="DIR", required=True, help="folder holding both vehicles' files")
    add_dialect_options(
        check,
        dialect="dialect of the files",
        points="most points per table the target takes (default: the dialect's limit)",
    )
    check.add_argument("--ignore-jerk", action="store_true", help="do not hold the files to the jerk limits")
    check.add_argument("--json", action="store_true", help="print a machine-readable verdict")
    check.set_defaults(run=_command_check)
