"""The ``trajgen`` command line.

Exit status: 0 on success, 2 on bad input (message on stderr, nothing
written), 1 on an internal failure.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence

from topology import Configuration, Position, Route, YGraph, plan
from topology.errors import InputError

__all__ = ["main"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2

logger = logging.getLogger(__name__)


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports usage errors as bad input (exit 2) through our path."""

    def error(self, message: str):
        raise InputError(f"{self.prog}: {message}")


def route_summary(route: Route) -> dict:
    """A JSON-ready summary of a route."""
    return {
        "instruction": route.instruction.value,
        "waypoints": [[{"leg": p.leg, "s_m": p.s} for p in (w.first, w.second)] for w in route.waypoints],
        "regions": [str(r) for r in route.regions],
        "travel_m": list(route.travel),
        "min_separation_m": route.min_separation,
    }


def format_route(route: Route) -> str:
    """Human-readable multi-line description of a route."""
    lines = [
        f"instruction: {route.instruction.value}",
        f"homotopy class (regions): {' '.join(str(r) for r in route.regions) or '(one ray)'}",
        f"travel: vehicle 1 {route.travel[0]:g} m, vehicle 2 {route.travel[1]:g} m",
        "waypoints (vehicle 1, vehicle 2):",
    ]
    lines += [f"  {k:2d}  {w}" for k, w in enumerate(route.waypoints)]
    return "\n".join(lines)


def _swap_example() -> tuple[YGraph, Configuration, Configuration]:
    """ALGORITHM.md section 7: legs of 1 m, swap the vehicles parked at A and B."""
    track = YGraph({"A": 1.0, "B": 1.0, "C": 1.0})
    start = Configuration(Position("A", 1.0), Position("B", 1.0))
    return track, start, start.swapped()


def _command_demo(args: argparse.Namespace) -> int:
    track, start, goal = _swap_example()
    route = plan(track, start, goal)
    print("Swap example (ALGORITHM.md section 7): legs A, B, C of 1 m, vehicles at A:1 and B:1.")
    print(format_route(route))
    return EXIT_OK


def _parse_legs(text: str) -> dict[str, float]:
    legs = {}
    for item in text.split(","):
        name, _, length = item.partition("=")
        try:
            legs[name.strip()] = float(length)
        except ValueError:
            raise InputError(f"--legs item {item!r} is malformed: expected NAME=metres, e.g. A=10") from None
    return legs


def _command_plan(args: argparse.Namespace) -> int:
    track = YGraph(_parse_legs(args.legs))
    start = Configuration(Position.parse(args.start[0]), Position.parse(args.start[1]))
    goal = Configuration(Position.parse(args.goal[0]), Position.parse(args.goal[1]))
    route = plan(track, start, goal, min_separation=args.min_separation)
    print(json.dumps(route_summary(route), indent=2) if args.json else format_route(route))
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``trajgen`` command."""
    parser = _ArgumentParser(
        prog="trajgen", description="Collision-free schedules for two AGVs on a Y-track."
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_ArgumentParser)
    demo = commands.add_parser("demo", help="run the built-in swap example")
    demo.set_defaults(run=_command_demo)
    plan_parser = commands.add_parser("plan", help="plan a route between two configurations")
    plan_parser.add_argument("--legs", required=True, help="leg lengths, counterclockwise: A=10,B=10,C=10")
    plan_parser.add_argument(
        "--start", nargs=2, required=True, metavar=("FIRST", "SECOND"), help="e.g. A:10 B:10"
    )
    plan_parser.add_argument(
        "--goal", nargs=2, required=True, metavar=("FIRST", "SECOND"), help="e.g. B:10 A:10"
    )
    plan_parser.add_argument("--min-separation", type=float, default=0.0, help="metres along the track")
    plan_parser.add_argument("--json", action="store_true", help="print a machine-readable summary")
    plan_parser.set_defaults(run=_command_plan)
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
