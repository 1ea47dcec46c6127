"""Hypothesis strategies for tracks, positions and planning queries (shared by the tests)."""

from __future__ import annotations

from hypothesis import assume
from hypothesis import strategies as st

from topology import Configuration, Position, StarGraph, YGraph, retract

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


# -- junctions of 3 to 8 legs (STAR-JUNCTIONS.md) ------------------------------------------------------

#: Leg names of star tracks, counterclockwise; a track of k legs takes the first k.
STAR_LEG_NAMES = (
    ("N", "W", "S", "E", "U", "V", "X", "Y"),
    ("leg1", "leg2", "leg3", "leg4", "leg5", "leg6", "leg7", "leg8"),
)


@st.composite
def star_tracks(
    draw, min_legs: int = 4, max_legs: int = 8, min_length: float = 0.5, max_length: float = 50.0
) -> StarGraph:
    """A junction of ``min_legs`` to ``max_legs`` legs of random length in [min_length, max_length] metres."""
    count = draw(st.integers(min_legs, max_legs))
    names = draw(st.sampled_from(STAR_LEG_NAMES))[:count]
    lengths = [draw(st.floats(min_length, max_length)) for _ in names]
    return StarGraph(dict(zip(names, lengths, strict=True)))


@st.composite
def star_configurations(draw, graph: StarGraph, kind: str = "random") -> Configuration:
    """A configuration of ``graph``: ``random``, ``endpoints`` (a peak of G_k) or ``junction`` (one at O)."""
    if kind == "random":
        return draw(configurations(graph))
    first, second = draw(st.lists(st.sampled_from(graph.names), min_size=2, max_size=2, unique=True))
    if kind == "endpoints":
        return Configuration(graph.endpoint(first), graph.endpoint(second))
    other = draw(st.one_of(st.just(graph.endpoint(second)), positions(graph).filter(lambda p: p.s > 0)))
    pair = (graph.junction, other)
    return Configuration(*(pair if draw(st.booleans()) else pair[::-1]))


@st.composite
def star_queries(draw, min_legs: int = 4, max_legs: int = 8):
    """(graph, start, goal, min_separation) on a star; swaps, leg ends and the junction well represented."""
    graph = draw(star_tracks(min_legs, max_legs))
    how = draw(st.sampled_from(["random", "random", "swap", "endpoints", "junction", "mixed"]))
    if how in ("random", "swap"):
        start = draw(star_configurations(graph))
        goal = start.swapped() if how == "swap" else draw(star_configurations(graph))
    elif how == "mixed":
        kinds = st.sampled_from(["random", "endpoints", "junction"])
        start = draw(star_configurations(graph, draw(kinds)))
        goal = draw(star_configurations(graph, draw(kinds)))
    else:
        start = draw(star_configurations(graph, how))
        goal = draw(star_configurations(graph, how))
    ceiling = min(graph.shortest_leg, graph.separation(start), graph.separation(goal))
    separation = draw(st.one_of(st.just(0.0), st.just(ceiling), st.floats(0.0, ceiling)))
    return graph, start, goal, separation


def resolved(graph: StarGraph, positions, separation: float) -> bool:
    """Whether a query is within what a track graph resolves (each place and the separation to 1 µm).

    Each position at the junction or a leg's end or at least 1 µm from both, and a separation of at
    least 1 µm.

    A track graph holds a point within ``POINT_TOLERANCE`` (1 nm) of a node as the node; the queries
    above reach down to 5e-324 m, where a junction's own planner and verifier still tell the places apart.
    """
    if separation < 1e-6:
        return False
    for position in positions:
        if position.leg is None or position.s == 0.0:
            continue
        length = graph.lengths[graph.names.index(position.leg)]
        if position.s < 1e-6 or (position.s != length and length - position.s < 1e-6):
            return False
    return True


def planned_junction_route(query, homotopy: str):
    """The junction's route of a :func:`star_queries` query in ``homotopy``.

    A query a track graph does not resolve (:func:`resolved`), or with no other class (its
    retractions meet), is skipped (``assume``).
    """
    from topology import OptionError, plan

    star, start, goal, separation = query
    assume(resolved(star, (*start, *goal), separation))
    try:
        return plan(star, start, goal, min_separation=separation, homotopy=homotopy)
    except OptionError:
        assume(False)
        raise  # unreachable: assume(False) raises
