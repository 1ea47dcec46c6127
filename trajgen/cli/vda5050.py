"""``trajgen export-vda5050``: a scenario's verified schedule as VDA 5050 orders and order updates."""

from __future__ import annotations

import argparse
import json
from datetime import UTC, datetime

from topology.validation import short_repr
from trajgen.cli.options import add_method, scenario_from, scenario_method
from trajgen.cli.parser import EXIT_OK
from trajgen.errors import OptionError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.vda5050.options import MANIFEST_NAME, Vda5050Options

__all__ = ["parse_start_time", "register"]


def parse_start_time(text: str | None) -> datetime:
    """``--start-time``: an ISO 8601 time with a time zone (``2025-05-01T08:00:00Z``); ``None``: now.

    Now is rounded down to the second, in UTC.

    Raises
    ------
    OptionError
        Not an ISO 8601 time, or no time zone.
    """
    if text is None:
        return datetime.now(UTC).replace(microsecond=0)
    try:
        moment = datetime.fromisoformat(text)
    except ValueError:
        raise OptionError(
            f"--start-time {short_repr(text)} is not an ISO 8601 time: expected e.g. 2025-05-01T08:00:00Z"
        ) from None
    if moment.utcoffset() is None:
        raise OptionError(
            f"--start-time {short_repr(text)} has no time zone: expected e.g. 2025-05-01T08:00:00Z or +02:00"
        )
    return moment


def _per_vehicle(values: list[str], names: tuple[str, ...], option: str, default: tuple[str, ...]):
    """``VALUE`` (every vehicle) or ``NAME=VALUE`` (one), repeatable, onto ``default``."""
    result = list(default)
    for value in values:
        name, equals, text = value.partition("=")
        if not equals:
            if option == "--serial-number":
                raise OptionError(
                    f"{option} {short_repr(value)} names no vehicle: expected NAME=SERIAL (vehicles "
                    "cannot share a serial number)"
                )
            result = [value] * len(names)
            continue
        if name not in names:
            raise OptionError(
                f"{option} {short_repr(value)} names no vehicle of the scenario: expected NAME=VALUE "
                f"with NAME one of {list(names)!r}"
            )
        result[names.index(name)] = text
    return tuple(result)


def _format(summary: dict) -> str:
    from trajgen.model.summary import format_provenance

    lines = [
        f"VDA 5050 orders of {summary['scenario']} ({format_provenance(summary)}, "
        f"schedule {summary['duration_s']:.2f} s, planned with waits {summary['planned_duration_s']:.2f} s), "
        f"start {summary['start_time']}:"
    ]
    for message in summary["messages"]:
        trigger = message["trigger"]
        when = (
            "at the start"
            if trigger is None
            else f"when {trigger['vehicle']} reaches {trigger['node_id']} "
            f"(sequenceId {trigger['sequence_id']})"
        )
        wait = f", waits {message['wait_s']:.2f} s" if message["wait_s"] > 0 else ""
        lines.append(
            f"  {message['file']}: t = {message['send_at_s']:.3f} s {when}, "
            f"base to {message['decision_point']['node_id']}{wait}"
        )
    lines.append(f"wrote {len(summary['files'])} files")
    return "\n".join(lines)


def _command_export(args: argparse.Namespace) -> int:
    from trajgen.export.vda5050.files import order_files, order_paths
    from trajgen.model.summary import provenance
    from trajgen.pipeline import run

    scenario = scenario_from(args.scenario)
    method = scenario_method(args, scenario)
    names = scenario.names
    options = Vda5050Options(
        start_time=parse_start_time(args.start_time),
        map_id=args.map_id,
        order_id=args.order_id,
        manufacturers=_per_vehicle(args.manufacturer, names, "--manufacturer", ("unspecified",) * len(names)),
        serial_numbers=_per_vehicle(args.serial_number, names, "--serial-number", names),
        first_header_id=args.first_header_id,
    )
    check_output_paths(order_paths(names, args.out))  # before anything is computed
    result = run(scenario, method=method)
    method = result.method
    files = order_files(result.verified, names, args.out, options=options)
    check_output_paths(files)
    written = commit_files(files)
    manifest = json.loads(next(data for path, data in files.items() if path.name == MANIFEST_NAME))
    schedule = result.verified.schedule
    summary = {
        "scenario": scenario.source,
        **provenance(schedule, method.name),
        "duration_s": schedule.duration,
        "planned_duration_s": manifest["planned_duration_s"],
        "start_time": manifest["start_time"],
        "vehicles": manifest["vehicles"],
        "messages": manifest["messages"],
        "files": [str(path) for path in written],
    }
    print(json.dumps(summary, indent=2) if args.json else _format(summary))
    return EXIT_OK


def register(commands) -> None:
    """Add ``export-vda5050`` to the sub-commands."""
    export = commands.add_parser(
        "export-vda5050",
        formatter_class=argparse.RawTextHelpFormatter,
    )
    export.add_argument("scenario", help="scenario TOML file")
    export.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help=f"write DIR/<vehicle name>/order-NNN.json per message and DIR/{MANIFEST_NAME}",
    )
    add_method(export)
    export.add_argument(
        "--start-time",
        metavar="ISO",
        help="when the schedule starts, ISO 8601 with a time zone (e.g. 2025-05-01T08:00:00Z);\n"
        "the messages' timestamps count from it (default: now, to the second, UTC;\n"
        "the same start time gives the same files)",
    )
    export.add_argument("--map-id", default="trajgen", help="nodePosition.mapId (trajgen)")
    export.add_argument(
        "--order-id", default="trajgen", help="orderId prefix: <PREFIX>-<vehicle name> (trajgen)"
    )
    export.add_argument(
        "--manufacturer",
        action="append",
        default=[],
        metavar="[NAME=]TEXT",
        help="manufacturer of both vehicles, or NAME=TEXT for one; repeatable (unspecified)",
    )
    export.add_argument(
        "--serial-number",
        action="append",
        default=[],
        metavar="NAME=SERIAL",
        help="serialNumber of vehicle NAME; repeatable (default: the vehicle name)",
    )
    export.add_argument(
        "--first-header-id",
        type=int,
        default=0,
        metavar="N",
        help="headerId of each vehicle's first message; one more with each message (0)",
    )
    export.add_argument("--json", action="store_true", help="print a machine-readable summary")
    export.set_defaults(run=_command_export)
