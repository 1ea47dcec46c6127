"""Which homotopy classes ``optimal`` solves: an option the command line reads without the NLP code."""

from __future__ import annotations

from topology import Option

__all__ = ["HomotopyChoice"]


class HomotopyChoice(Option):
    """Which homotopy classes ``optimal`` solves."""

    #: the route's class and the other (the other way round a Y's boundary circle; the
    #: second-shortest route on ``G_k`` for more legs); the faster wins
    FASTEST = "fastest"
    PAPER = "paper"  #: the route's class only (the paper's instruction, for a route from ``plan``)
