"""The exit codes and the argument parser class every ``trajgen`` command shares."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable

from trajgen.errors import InputError

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_OK", "CommandParser", "print_details"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2


class CommandParser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2) through our path."""

    def error(self, message: str):
        """Raise InputError with the usage message (argparse would exit)."""
        raise InputError(f"{self.prog}: {message}")


def print_details(details: Iterable[str]) -> None:
    """Print where each failure of a failed verification lies in the arrays (``--verbose``), to stderr."""
    for detail in details:
        print(f"trajgen: detail: {detail}", file=sys.stderr)
