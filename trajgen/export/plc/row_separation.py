"""The separation at the rows of a points-only table on a track graph (a generic CSV).

The verifier holds such a table to its tolerance between the rows, where the cubic is the
reader's; at the rows themselves the file says where the vehicles are, and the separation must
hold there to the file's round-off.
"""

from __future__ import annotations

import itertools

import numpy as np

from trajgen.export.plc.tables import ProfileTable
from trajgen.model.graph_paths import GraphPath
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.values import sorted_unique
from trajgen.verification import POSITION_TOLERANCE

__all__ = ["ROW_ROUND_OFF", "row_places", "row_separation"]

#: The most round-off a row's values are allowed at the rows of a points-only table, metres: a file
#: written to nanometres, as trajgen writes them. Fewer decimals buy no closer approach.
ROW_ROUND_OFF = 5e-10


def row_places(
    path: GraphPath, travel: np.ndarray, lengths: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where a vehicle's rows put it: edge, metres on it, and how far it is past what its path says.

    Past either end of its path it runs on along the end's edge (a vehicle creeping on); past the
    edge's end, or anywhere a vehicle that stays put moves, the track does not say which way: that
    distance is returned as the *overrun*, metres, to take off the separation (the track distance is
    1-Lipschitz in each position).
    """
    edge, s = path.locate(travel, extend=True)
    if path.edges.size == 0:
        return edge, s, np.abs(travel)
    on_edge = np.clip(s, 0.0, lengths[edge])
    return edge, on_edge, np.abs(s - on_edge)


def row_separation(tables: tuple[ProfileTable, ...], schedule: GraphSchedule) -> list[str]:
    """At the points of tables judged by their points only, every pair keeps the separation to round-off.

    The verifier holds such a table (a generic CSV) to its tolerance between the points, where the
    cubic is the reader's; at the points themselves the file says where the vehicles are. A vehicle
    the rows move past the end of its path's edge, or that moves at all where its path stays put,
    has that much less separation. The round-off allowed is at most a nanometre file's
    (:data:`ROW_ROUND_OFF`). The closest pair is reported.
    """
    if min(table.interpolation.closed_form for table in tables) > 0:
        return []
    times = sorted_unique(np.concatenate([table.times for table in tables]))
    travel = schedule.travel(times)[:, 0]
    track = schedule.track
    lengths = np.array([edge.length for edge in track.edges])
    places = [row_places(path, travel[v], lengths) for v, path in enumerate(schedule.paths)]
    round_off = min(max(t.round_off for t in tables), ROW_ROUND_OFF)
    allowed = schedule.limits.min_separation - POSITION_TOLERANCE - 2.0 * round_off
    worst = None
    for i, j in itertools.combinations(range(len(places)), 2):
        (edge_1, s_1, over_1), (edge_2, s_2, over_2) = places[i], places[j]
        apart = track.distances(edge_1, s_1, edge_2, s_2) - over_1 - over_2
        k = int(np.argmin(apart))
        if apart[k] < allowed and (worst is None or apart[k] < worst[0]):
            worst = (float(apart[k]), k, (i, j))
    if worst is None:
        return []
    gap, k, (i, j) = worst
    over = places[i][2][k] + places[j][2][k]
    past = f", {1e6 * over:.3g} µm of it off its path or where it stands" if over > 0.0 else ""
    return [
        f"separation {gap:.9g} m at the row at t={times[k]:.6f} s is below the minimum "
        f"{schedule.limits.min_separation:g} m (vehicle {i + 1} on {track.edges[places[i][0][k]].name!r}, "
        f"vehicle {j + 1} on {track.edges[places[j][0][k]].name!r}{past})"
    ]
