"""The ``trajgen`` command line: parses arguments, runs a command, maps errors to exit codes.

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure (nothing written). ``trajgen simulate``
also exits 1 when the simulated run missed its goal or had violations (its
trace and plot are written: they are the evidence).
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Sequence

from trajgen.cli import animate, check, schedule, simulate, vda5050
from trajgen.cli.options import EXIT_BAD_INPUT, EXIT_FAILURE, CommandParser
from trajgen.errors import InputError

__all__ = ["COMMAND_MODULES", "Commands", "build_parser", "command_parsers", "console_main", "main"]

logger = logging.getLogger(__name__)

#: The modules whose ``register(commands)`` adds the sub-commands, in help order.
COMMAND_MODULES = (schedule, check, simulate, vda5050, animate)


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
        self, name: str, *, help: str, formatter_class: type = argparse.HelpFormatter
    ) -> argparse.ArgumentParser:
        """Add the sub-command ``name`` and return its parser."""
        parser = self._action.add_parser(name, help=help, formatter_class=formatter_class)
        self.parsers[name] = (help, parser)
        return parser


def _build() -> tuple[argparse.ArgumentParser, Commands]:
    parser = CommandParser(
        prog="trajgen",
        description="Collision-free schedules for two AGVs on a junction of 3 to 8 legs (a Y, a crossing).",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    commands = Commands(parser.add_subparsers(dest="command", required=True, parser_class=CommandParser))
    for module in COMMAND_MODULES:
        module.register(commands)
    return parser, commands


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``trajgen`` command."""
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
