"""Which homotopy classes ``optimal`` solves: an option the command line reads without the NLP code."""

from __future__ import annotations

from topology import Option
from topology.options import rename_values

__all__ = ["HomotopyChoice"]


class HomotopyChoice(Option):
    """Which homotopy classes ``optimal`` solves."""

    #: the route's class and the other (the other way round a Y's boundary circle; the
    #: second-shortest route on ``G_k`` for more legs); the faster wins
    FASTEST = "fastest"
    PLANNED = "planned"  #: the route's class only (the planner's instruction, for a route from ``plan``)
    PAPER = "planned"  #: deprecated name of :attr:`PLANNED` (0.7)


rename_values(HomotopyChoice, {"paper": "planned"}, "0.7")
