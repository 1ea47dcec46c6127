"""The rows of a generic CSV profile on a track graph: the edge by name and the metres along it.

Columns ``t_s, axis_m, v_mps, a_mps2, j_mps3, edge, s_m, x_m, y_m`` (lengths in millimetres with
``units = "mm"``): ``edge`` is the edge's name, ``s_m`` the metres from its ``from`` node; ``x_m`` and
``y_m`` only when the track's nodes have coordinates (on the straight line between the edge's nodes).
"""

from __future__ import annotations

import numpy as np

from limits import VehicleLimits
from topology import TrackGraph
from topology.validation import short_repr
from trajgen.errors import OptionError
from trajgen.export.limited import limited_columns
from trajgen.export.numbers import format_number_rows
from trajgen.model.graph_schedule import GraphState

__all__ = ["GRAPH_HEADER_NAMES", "check_edge_names", "format_graph_block", "graph_header"]

#: Column names per length unit (``"m"`` or ``"mm"``); the last two only with node coordinates.
GRAPH_HEADER_NAMES = {
    "m": ("t_s", "axis_m", "v_mps", "a_mps2", "j_mps3", "edge", "s_m", "x_m", "y_m"),
    "mm": ("t_s", "axis_mm", "v_mmps", "a_mmps2", "j_mmps3", "edge", "s_mm", "x_mm", "y_mm"),
}


def graph_header(track: TrackGraph, unit: str) -> tuple[str, ...]:
    """The header's column names for ``track`` in length unit ``unit`` (``"m"`` or ``"mm"``)."""
    names = GRAPH_HEADER_NAMES[unit]
    return names if track.coordinates is not None else names[:7]


def check_edge_names(track: TrackGraph, delimiter: str) -> None:
    """Refuse edge names a CSV reader could not take back as one field.

    Raises
    ------
    OptionError
        A name holds the delimiter, a quote, a control character or a non-ASCII one.
    """
    for edge in track.edges:
        name = edge.name
        if delimiter in name:
            raise OptionError(
                f"edge name {short_repr(name)} holds the CSV delimiter {delimiter!r}: expected another "
                "delimiter (--delimiter) or a name without it"
            )
        if not (name.isascii() and name.isprintable()) or any(c in name for c in "\"'"):
            raise OptionError(
                f"edge name {short_repr(name)} is not plain ASCII without quotes: expected a name a CSV "
                "reader takes as it is"
            )


def format_graph_block(
    track: TrackGraph,
    state: GraphState,
    vehicle: int,
    *,
    delimiter: str,
    decimal: str,
    scale: float,
    decimals: int,
    limits: VehicleLimits | None = None,
    jerk_limited: bool = True,
) -> bytes:
    """Rows of one vehicle's generic CSV on ``track`` for the sampled ``state``: ASCII, CRLF after each.

    Parameters
    ----------
    track : TrackGraph
    state : GraphState
        Both vehicles at n sample times.
    vehicle : int
        0 or 1.
    delimiter, decimal : str
        Field separator and decimal mark.
    scale : float
        Multiplier from metres of the length unit.
    decimals : int
        Decimal places of lengths (time has 6).
    limits : VehicleLimits, optional
        The vehicle's limits: its velocity, acceleration and (if ``jerk_limited``) jerk are held to
        them as written (:func:`~trajgen.export.limited.limited_columns`); ``None``: as they are.
    jerk_limited : bool, optional
        Whether the jerk is held to ``limits`` too (default True).
    """
    velocity, acceleration, jerk = limited_columns(state, vehicle, scale, decimals, limits, jerk_limited)
    before = [
        (state.t, 6),
        (state.axis[vehicle] * scale, decimals),
        (velocity, decimals),
        (acceleration, decimals),
        (jerk, decimals),
    ]
    after = [(state.s[vehicle] * scale, decimals)]
    xy = state.xy(track)
    if xy is not None:
        after += [(xy[vehicle, 0] * scale, decimals), (xy[vehicle, 1] * scale, decimals)]
    head = format_number_rows(before, (delimiter,) * 4 + ("\n",), decimal=decimal).split(b"\n")[:-1]
    tail = format_number_rows(after, (delimiter,) * (len(after) - 1) + ("\n",), decimal=decimal).split(b"\n")[
        :-1
    ]
    names = np.array([edge.name.encode("ascii") for edge in track.edges], dtype=object)[state.edge[vehicle]]
    separator = delimiter.encode("ascii")
    return b"".join(
        h + separator + n + separator + t + b"\r\n" for h, n, t in zip(head, names, tail, strict=True)
    )
