"""The ``trajgen`` command line (one module per group of sub-commands).

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure (nothing written).
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.cli.entry import build_parser, command_parsers, main
    from trajgen.cli.parser import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK

#: ``import trajgen.cli`` loads nothing more: the parser and each command's modules load when used.
_SOURCES = {
    "EXIT_BAD_INPUT": "trajgen.cli.parser",
    "EXIT_FAILURE": "trajgen.cli.parser",
    "EXIT_OK": "trajgen.cli.parser",
    "build_parser": "trajgen.cli.entry",
    "command_parsers": "trajgen.cli.entry",
    "main": "trajgen.cli.entry",
}

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_OK", "build_parser", "command_parsers", "main"]

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
