"""The options several ``trajgen`` commands take, and reading them: the scenario, the method, CSV.

The exit codes and the parser are in :mod:`trajgen.cli.parser`. Each command lives in its own
module of :mod:`trajgen.cli` with a ``register(commands)`` function that adds its sub-parser and
uses the ``add_*`` functions here; the parser's ``run`` default is the function that carries the
command out and returns its exit status.
"""

from __future__ import annotations

import argparse
import dataclasses

from trajgen.errors import OptionError
from trajgen.export import DEFAULT_MAX_ROWS, CsvOptions, Units
from trajgen.export.plc.dialects import DIALECTS
from trajgen.methods import METHODS
from trajgen.methods.optimal.choice import HomotopyChoice
from trajgen.model.schedule import TimingMethod
from trajgen.scenario import GraphScenario, Scenario, default_scenario, load_scenario

__all__ = [
    "add_csv_options",
    "add_dialect_options",
    "add_method",
    "csv_dialect",
    "csv_options",
    "method_from",
    "scenario_from",
]


def scenario_from(path: str | None) -> Scenario | GraphScenario:
    """The scenario of a file (a junction's or a track graph's), or the built-in one for ``None``.

    Every command plans it: a number of vehicles the planners do not take is refused here, at the
    door, naming the file (:class:`~trajgen.errors.VehicleCountError`, exit 2).
    """
    scenario = default_scenario() if path is None else load_scenario(path)
    scenario.check_planned()
    return scenario


#: The generic CSV's options and their defaults (``None`` in the parser, so a given one is known).
GENERIC_DEFAULTS = {
    "sample_period": 0.01,
    "delimiter": ";",
    "decimal": ".",
    "units": "m",
    "max_rows": DEFAULT_MAX_ROWS,
}


def _given(args: argparse.Namespace, name: str):
    value = getattr(args, name, None)
    return GENERIC_DEFAULTS[name] if value is None else value


def csv_dialect(args: argparse.Namespace) -> dict:
    """``--delimiter``, ``--decimal``, ``--units`` as keyword arguments of CsvOptions."""
    delimiter = _given(args, "delimiter")
    delimiter = "\t" if delimiter in ("tab", "\\t") else delimiter
    return {
        "delimiter": delimiter,
        "decimal": _given(args, "decimal"),
        "units": Units.lookup(_given(args, "units")),
    }


def csv_options(args: argparse.Namespace) -> CsvOptions:
    """The CsvOptions of ``--sample-period``, ``--max-rows`` and the dialect options.

    Raises
    ------
    OptionError
        One of them is given with a table ``--dialect`` (its format is the dialect's).
    """
    dialect = getattr(args, "dialect", "generic")
    given = [name for name in GENERIC_DEFAULTS if getattr(args, name, None) is not None]
    if given and DIALECTS.lookup(dialect).point_limit is not None:
        options = ", ".join("--" + name.replace("_", "-") for name in given)
        raise OptionError(
            f"{options} {'applies' if len(given) == 1 else 'apply'} to the generic CSV only: "
            f"dialect {dialect!r} writes its own fixed format "
            "(see docs/formats/); expected them only with --dialect generic"
        )
    return CsvOptions(
        sample_period=_given(args, "sample_period"), max_rows=_given(args, "max_rows"), **csv_dialect(args)
    )


def add_method(
    parser: argparse.ArgumentParser, *, what: str = "timing method", homotopy: bool = True
) -> None:
    """``--method`` (and, with ``homotopy``, ``--homotopy``)."""
    parser.add_argument(
        "--method",
        default=None,
        metavar="|".join(METHODS.names),
        help=f"{what}, one of:\n{METHODS.help()}\n(a track graph is timed by exact, its default there)",
    )
    if not homotopy:
        return
    parser.add_argument(
        "--homotopy",
        metavar="|".join(c.value for c in HomotopyChoice),
        help="optimal only: 'fastest' (default) solves the planned class and the other and keeps\n"
        "the faster: on a Y both ways round the configuration circle, on 4 to 8 legs the\n"
        "shortest and the second-shortest route on the retract graph G_k, on a track graph\n"
        "also where the other vehicle yields; 'planned' keeps the planned class (the class of\n"
        "the planner's route; on a Y the paper's instruction)",
    )


def scenario_method(args: argparse.Namespace, scenario) -> TimingMethod | None:
    """``--method`` for ``scenario``: ``None`` (the pipeline's default) on a track graph given none."""
    if (
        isinstance(scenario, GraphScenario)
        and args.method is None
        and getattr(args, "homotopy", None) is None
    ):
        return None
    return method_from(args)


def method_from(args: argparse.Namespace) -> TimingMethod:
    """The method object of ``--method`` with ``--homotopy`` applied."""
    method = METHODS.create(args.method)
    if getattr(args, "homotopy", None) is None:
        return method
    choice = HomotopyChoice.lookup(args.homotopy)
    if not any(field.name == "homotopy" for field in dataclasses.fields(method)):
        raise OptionError(
            f"--homotopy {args.homotopy!r} applies to the method 'optimal' only, "
            f"got --method {method.name!r} "
            "(exact and toppra always take the planned class)"
        )
    return dataclasses.replace(method, homotopy=choice)


def add_dialect_options(parser: argparse.ArgumentParser, *, dialect: str, points: str) -> None:
    """``--dialect`` (help ``dialect``, then the list of dialects) and ``--max-points`` (help ``points``)."""
    parser.add_argument(
        "--dialect",
        default="generic",
        metavar="|".join(DIALECTS.names),
        help=f"{dialect}, one of:\n{DIALECTS.help()}",
    )
    parser.add_argument("--max-points", type=int, help=points)


def add_csv_options(parser: argparse.ArgumentParser, *, sampling: bool = True) -> None:
    """The CSV dialect options; with ``sampling``, also ``--sample-period`` and ``--max-rows``."""
    if sampling:
        parser.add_argument(
            "--sample-period", type=float, help="seconds between CSV rows (0.01; generic only)"
        )
    parser.add_argument("--delimiter", help="CSV field separator (';'); 'tab' for a tab")
    parser.add_argument("--decimal", choices=[".", ","], help="decimal mark ('.')")
    parser.add_argument("--units", choices=[u.value for u in Units], help="length unit of the CSV (m)")
    if sampling:
        add_dialect_options(
            parser,
            dialect="PLC dialect of the --csv files",
            points="points per table of a table dialect (default: the dialect's limit)",
        )
        parser.add_argument(
            "--max-rows",
            type=int,
            help=f"refuse a CSV profile of more rows than this ({DEFAULT_MAX_ROWS:,}; generic only)",
        )
