"""The ``trajgen`` command line: parses arguments, runs a command, maps errors to exit codes.

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure (nothing written). ``trajgen simulate``
also exits 1 when the simulated run missed its goal or had violations (its
trace and plot are written: they are the evidence).

``-v``/``--verbose``, before or after the command's name, logs progress to stderr, and with a
failed verification where each failure lies in the schedule's arrays (its details); without
it, messages say what is wrong in plain words only.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from collections.abc import Sequence

from trajgen.cli.logs import LogFormatter, log_to_stderr
from trajgen.cli.parser import EXIT_BAD_INPUT, EXIT_FAILURE, CommandParser, print_details
from trajgen.errors import InputError, LiveError, VerificationError

__all__ = ["COMMANDS", "Commands", "LogFormatter", "build_parser", "command_parsers", "console_main", "main"]

logger = logging.getLogger(__name__)


#: The help of ``-v``/``--verbose``, an option of ``trajgen`` and of each of its commands.
VERBOSE_HELP = (
    "log progress to stderr, and where a failed verification lies in the schedule's arrays (its details)"
)

#: Every sub-command, in help order: its one-line help and the module whose ``register(commands)``
#: adds its parser. A run imports only its own command's module: ``trajgen schedule`` loads no
#: plotting, VDA 5050 or closed-loop code.
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": (
        "run a built-in scenario end to end (the swap on a Y, or a 4-way crossing)",
        "trajgen.cli.schedule",
    ),
    "plan": ("print the planner's route for a scenario file", "trajgen.cli.schedule"),
    "schedule": ("schedule, verify and export a scenario", "trajgen.cli.schedule"),
    "check": (
        "verify profile files against a scenario (exit 1 on violations, 2 if unreadable)",
        "trajgen.cli.check",
    ),
    "simulate": (
        "run a scenario in closed loop under faults (exit 1 if it misses the goal or has violations)",
        "trajgen.cli.simulate",
    ),
    "export-vda5050": (
        "write VDA 5050 2.1.0 orders and order updates of a scenario's verified schedule",
        "trajgen.cli.vda5050",
    ),
    "animate": (
        "write an animated GIF of a scenario's verified schedule on the track",
        "trajgen.cli.animate",
    ),
    "serve": (
        "drive both vehicles over VDA 5050 on an MQTT broker, releasing base by the frontier",
        "trajgen.cli.live",
    ),
    "vehicle": ("a simulated VDA 5050 vehicle on an MQTT broker", "trajgen.cli.live"),
}


class Commands:
    """The sub-commands as they are registered: each one's parser and one-line help.

    Parameters
    ----------
    action
        What ``ArgumentParser.add_subparsers`` returned.
    """

    __slots__ = ("_action", "parsers")

    def __init__(self, action) -> None:
        self._action = action
        #: name -> (one-line help, its parser), in registration order
        self.parsers: dict[str, tuple[str, argparse.ArgumentParser]] = {}

    def add_parser(
        self, name: str, *, formatter_class: type = argparse.HelpFormatter
    ) -> argparse.ArgumentParser:
        """Add the sub-command ``name`` (one of :data:`COMMANDS`, with its help) and return its parser."""
        summary = COMMANDS[name][0]
        parser = self._action.add_parser(name, help=summary, formatter_class=formatter_class)
        # after the command's name too; unset unless given, so that ``trajgen -v COMMAND`` stays verbose
        parser.add_argument(
            "-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help=VERBOSE_HELP
        )
        self.parsers[name] = (summary, parser)
        return parser


def _chosen(argv: Sequence[str]) -> str | None:
    """The sub-command ``argv`` names (its first word that is not an option), if it is one."""
    word = next((arg for arg in argv if not arg.startswith("-")), None)
    return word if word in COMMANDS else None


def _build(command: str | None = None) -> tuple[argparse.ArgumentParser, Commands]:
    """The parser: every sub-command in full, or only ``command`` in full and the others by name."""
    parser = CommandParser(
        prog="trajgen",
        description="Collision-free schedules for two AGVs on a junction of 3 to 8 legs (a Y, a crossing).",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help=VERBOSE_HELP)
    commands = Commands(parser.add_subparsers(dest="command", required=True, parser_class=CommandParser))
    registered: set[str] = set()
    for name, (_, module) in COMMANDS.items():
        if command is not None and module != COMMANDS[command][1]:
            commands.add_parser(name)  # listed in --help; its options are never parsed in this run
        elif module not in registered:
            registered.add(module)
            importlib.import_module(module).register(commands)
    order = list(COMMANDS)
    commands.parsers = dict(sorted(commands.parsers.items(), key=lambda item: order.index(item[0])))
    return parser, commands


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``trajgen`` command, every sub-command in full."""
    return _build()[0]


def command_parsers() -> dict[str, tuple[str, argparse.ArgumentParser]]:
    """Every sub-command's one-line help and parser, by name, in help order."""
    return _build()[1].parsers


def console_main() -> int:
    """The ``trajgen`` console script: :func:`main`, and an exit that a stalled solver cannot spoil.

    A fatrop call the optimal method's watchdog abandoned keeps running in its thread; the normal
    interpreter shutdown would tear the solver down under it (``terminate called``, exit 134). The
    script then flushes its output and ends at once with the status :func:`main` returned.
    """
    status = main()
    solve = sys.modules.get("trajgen.methods.optimal.solve")
    if solve is not None and solve.abandoned_solver_calls():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


def _details(error: Exception, verbose: bool) -> None:
    """With ``--verbose``, where each failure of a failed verification lies in the schedule's arrays."""
    if verbose and isinstance(error, VerificationError):
        print_details(error.details)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    verbose = False
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        args = _build(_chosen(argv))[0].parse_args(argv)
        verbose = bool(args.verbose)
        log_to_stderr(logging.INFO if verbose else logging.WARNING)
        return args.run(args)
    except InputError as error:
        print(f"trajgen: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except LiveError as error:  # the environment (broker, network, certificates), not a bug
        print(f"trajgen: error: {error}", file=sys.stderr)
        return EXIT_FAILURE
    except Exception as error:
        logger.debug("internal failure", exc_info=True)
        print(f"trajgen: internal failure: {type(error).__name__}: {error}", file=sys.stderr)
        _details(error, verbose)
        return EXIT_FAILURE
