"""The ``trajgen`` command line (one module per group of sub-commands).

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure (nothing written).
"""

from trajgen.cli.main import build_parser, command_parsers, main
from trajgen.cli.options import EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_OK

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILURE", "EXIT_OK", "build_parser", "command_parsers", "main"]
