"""``trajgen check``: verify profile files against a scenario (exit 0 pass, 1 violations, 2 unreadable)."""

from __future__ import annotations

import argparse
import json

from trajgen.cli.options import add_dialect_options, scenario_from
from trajgen.cli.parser import EXIT_FAILURE, EXIT_OK, print_details
from trajgen.model.summary import closest_text

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
            f"{closest_text(summary['min_separation_m'])} (minimum {scenario.limits.min_separation:g} m); "
            f"class: {_class(verdict.check.route, scenario)}"
        )
        failures = summary["failures"]
        for failure in failures[:SHOWN_FAILURES]:
            print(f"violation: {failure}")
        if len(failures) > SHOWN_FAILURES:
            print(f"... and {len(failures) - SHOWN_FAILURES} more (--json lists all)")
        for note in _jerk_notes(verdict, args.ignore_jerk):
            print(f"note: {note}")
        if not verdict.passed:
            if getattr(args, "verbose", False):  # where each failure lies in the tables' arrays
                print_details(verdict.check.report.details)
            print("FAIL")
        elif verdict.jerk_checked:
            print("PASS: the files keep the separation and the limits")
        else:
            print("PASS: the files keep the separation and the velocity and acceleration limits")
    return EXIT_OK if verdict.passed else EXIT_FAILURE


def _class(route, scenario) -> str:
    """The class the files were checked along, in the words of every summary (``planned (...)``)."""
    from topology import GraphRoute, class_signature
    from trajgen.model.summary import class_label

    planned = None
    if isinstance(route, GraphRoute):  # the planner's route's class, or one where the other yields
        planned = class_signature(route) == class_signature(scenario.route())
    return class_label(route, planned=planned)


def _jerk_notes(verdict, ignored: bool) -> list[str]:
    """What the verdict's jerk check was, where it is news: not checked, or failed."""
    record = verdict.record
    if record is not None and not record.jerk_limited:
        return [
            f"the files record that their schedule is not jerk-limited (method {record.method}): "
            "jerk not checked"
        ]
    if verdict.passed or ignored or not any("max_jerk" in failure for failure in verdict.failures):
        return []
    if any("the file ends early" in failure for failure in verdict.failures):
        return []  # its jerk at the cut is the cut's: no flag to offer
    if record is not None:  # they claim a jerk-limited schedule: no flag to offer
        return [
            f"the files record that their schedule is jerk-limited (method {record.method}): "
            "they are held to the jerk limits"
        ]
    # files of a schedule without jerk limits that do not say so (a table dialect's, or older)
    return [
        "the files are held to the jerk limits (they do not both record a schedule without jerk "
        "limits); a schedule timed by toppra does not limit jerk: check its files for the "
        "separation, velocity and acceleration alone with --ignore-jerk"
    ]


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
    check.add_argument(
        "--ignore-jerk",
        action="store_true",
        help="do not hold the files to the jerk limits (a generic CSV that records a schedule\n"
        "without jerk limits, as toppra's do, is not held to them anyway)",
    )
    check.add_argument("--json", action="store_true", help="print a machine-readable verdict")
    check.set_defaults(run=_command_check)
