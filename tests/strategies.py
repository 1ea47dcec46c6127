"""Hypothesis strategies for tracks, positions and planning queries (shared by the tests)."""

from __future__ import annotations

from hypothesis import assume
from hypothesis import strategies as st

from topology import Configuration, Position, YGraph, retract

LEG_NAMES = (("A", "B", "C"), ("north", "west", "east"), ("1", "2", "3"))


@st.composite
def tracks(draw, min_length: float = 0.5, max_length: float = 50.0) -> YGraph:
    """A Y-track with legs of random length in [min_length, max_length] metres."""
    names = draw(st.sampled_from(LEG_NAMES))
    lengths = [draw(st.floats(min_length, max_length)) for _ in names]
    return YGraph(dict(zip(names, lengths, strict=True)))


@st.composite
def positions(draw, graph: YGraph) -> Position:
    """A position on ``graph``; junction and endpoints are drawn often on purpose."""
    kind = draw(st.sampled_from(["junction", "endpoint", "interior", "interior", "interior"]))
    if kind == "junction":
        return graph.junction
    leg = draw(st.sampled_from(graph.names))
    if kind == "endpoint":
        return graph.endpoint(leg)
    return Position(leg, draw(st.floats(0.0, graph.length(leg), exclude_min=True)))


@st.composite
def configurations(draw, graph: YGraph) -> Configuration:
    """A configuration with the vehicles at distinct points."""
    configuration = Configuration(draw(positions(graph)), draw(positions(graph)))
    assume(graph.separation(configuration) > 0.0)
    return configuration


def scaled(graph: YGraph, configuration: Configuration, factor: float) -> Configuration:
    """Both vehicles pulled toward the junction by ``factor`` in (0, 1] (stays in one fibre)."""
    return Configuration(*(Position(p.leg, p.s * factor) if p.leg is not None else p for p in configuration))


@st.composite
def queries(draw):
    """(graph, start, goal, min_separation): valid, with swaps and antipodal goals well represented."""
    graph = draw(tracks())
    start = draw(configurations(graph))
    how = draw(st.sampled_from(["random", "random", "swap", "antipodal fibre"]))
    if how == "random":
        goal = draw(configurations(graph))
    elif how == "swap":
        goal = start.swapped()
    else:  # a goal whose boundary image is the swapped boundary start
        boundary = retract(graph, start)[-1].swapped()
        goal = scaled(graph, boundary, draw(st.floats(0.05, 1.0)))
        assume(graph.separation(goal) > 0.0)
    ceiling = min(graph.shortest_leg, graph.separation(start), graph.separation(goal))
    separation = draw(st.one_of(st.just(0.0), st.just(ceiling), st.floats(0.0, ceiling)))
    return graph, start, goal, separation
