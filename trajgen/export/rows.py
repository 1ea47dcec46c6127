"""The rows of a generic CSV profile, on any track: where each vehicle is and how it moves.

Columns ``t_s, axis_m, v_mps, a_mps2, j_mps3, edge, s_m, x_m, y_m`` (lengths in millimetres with
``units = "mm"``): ``edge`` is the edge's name, ``s_m`` the metres from its ``from`` node; ``x_m`` and
``y_m`` only when the track's nodes have coordinates (``start + s * direction`` of the edge). On a
track with numbered legs (a star's, :attr:`~topology.TrackGraph.numbered_legs`) the column is ``leg``
and holds the leg's number, 1 for the first and 0 at the junction, as a star's profiles always have.
"""

from __future__ import annotations

from limits import VehicleLimits
from topology import TrackGraph
from topology.validation import short_repr
from trajgen.errors import OptionError
from trajgen.export.limited import limited_columns
from trajgen.export.numbers import format_number_rows
from trajgen.model.state import TrackState

__all__ = ["GRAPH_HEADER_NAMES", "LEG_HEADER_NAMES", "check_edge_names", "format_rows_block", "header"]

#: Column names per length unit (``"m"`` or ``"mm"``) on a track of named edges; the last two only
#: with node coordinates.
GRAPH_HEADER_NAMES = {
    "m": ("t_s", "axis_m", "v_mps", "a_mps2", "j_mps3", "edge", "s_m", "x_m", "y_m"),
    "mm": ("t_s", "axis_mm", "v_mmps", "a_mmps2", "j_mmps3", "edge", "s_mm", "x_mm", "y_mm"),
}
#: Column names per length unit on a track of numbered legs (a star's).
LEG_HEADER_NAMES = {
    unit: tuple("leg" if name == "edge" else name for name in names)
    for unit, names in GRAPH_HEADER_NAMES.items()
}


def header(track: TrackGraph, unit: str) -> tuple[str, ...]:
    """The header's column names for ``track`` in length unit ``unit`` (``"m"`` or ``"mm"``)."""
    names = (LEG_HEADER_NAMES if track.numbered_legs else GRAPH_HEADER_NAMES)[unit]
    return names if track.coordinates is not None else names[:7]


def check_edge_names(track: TrackGraph, delimiter: str) -> None:
    """Refuse edge names a CSV reader could not take back as one field (numbered legs: none is written).

    Raises
    ------
    OptionError
        A name holds the delimiter, a quote, a control character or a non-ASCII one.
    """
    if track.numbered_legs:
        return
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


def format_rows_block(
    track: TrackGraph,
    state: TrackState,
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
        The schedule's track (:attr:`~trajgen.model.schedule.Schedule.track`).
    state : TrackState
        The vehicles at n sample times.
    vehicle : int
        Index of the vehicle.
    delimiter, decimal : str
        Field separator and decimal mark.
    scale : float
        Multiplier from metres of the length unit.
    decimals : int
        Decimal places of lengths (time has 6).
    limits : VehicleLimits, optional
        The vehicle's limits: its velocity, acceleration and (if ``jerk_limited``) jerk are held to
        them as written (:func:`~trajgen.export.limited.limited_columns`); ``None``: as they are
        (executed motion).
    jerk_limited : bool, optional
        Whether the jerk is held to ``limits`` too (default True).

    Returns
    -------
    bytes
        n rows.
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
    labels = state.labels(track)[vehicle]
    separator = delimiter.encode("ascii")
    return b"".join(
        h + separator + n + separator + t + b"\r\n" for h, n, t in zip(head, labels, tail, strict=True)
    )
