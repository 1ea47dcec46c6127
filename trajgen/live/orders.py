"""The orders the live master sends: a vehicle's base up to its decision point, and a short horizon.

A vehicle drives only on its base; VDA 5050 makes the horizon optional. The master sends the
nodes past the decision point only as far as the vehicle needs to see them: its jerk-limited
stopping distance from full speed (at least one node, so that a vehicle short of its goal
always holds an unreleased node and never takes its decision point for the end of its order).
An order therefore grows with the base released, not with the length of the path.
"""

from __future__ import annotations

import bisect

from limits import VehicleLimits
from trajgen.export.vda5050.messages import VDA5050_VERSION, order_elements
from trajgen.live.view import VehicleView
from trajgen.model.coordination import stopping_distance

__all__ = ["NODE_DEVIATION", "horizon_length", "order_message", "path_elements"]

#: ``allowedDeviationXY`` of every node sent: how close a vehicle must be to count as on it, metres.
NODE_DEVIATION = 1e-3


def horizon_length(limits: VehicleLimits) -> float:
    """How far past its decision point a vehicle is shown its path: its stop from full speed, metres."""
    return stopping_distance(limits.max_velocity, 0.0, limits)


def path_elements(path, *, offset: int, map_id: str) -> list:
    """Each node and edge of ``path`` (an order path) as a vda5050-sdk model, as horizon and as base.

    Returns
    -------
    list
        ``[(nodes, edges) as horizon, (nodes, edges) as base]``, their ``sequenceId`` shifted by
        ``offset`` (a path stitched after a goal change continues the numbering).
    """
    last = len(path.nodes) - 1
    return [
        order_elements(
            path,
            first=0,
            decision_point=last if released else -1,
            map_id=map_id,
            sequence_offset=offset,
            node_deviation=NODE_DEVIATION,
        )
        for released in (False, True)
    ]


def order_message(
    view: VehicleView, *, first: int, decision_point: int, horizon_m: float, order_id: str, timestamp: str
):
    """The order (update) of ``view``'s vehicle from node ``first``, its base up to ``decision_point``.

    The horizon holds the nodes up to ``horizon_m`` metres past the decision point (at least one,
    unless the decision point is the goal). The view's ``header`` is counted up.
    """
    from vda5050.model.order import Order

    (horizon_nodes, horizon_edges), (base_nodes, base_edges) = view.elements
    arcs = view.arcs
    end = min(
        max(bisect.bisect_right(arcs, arcs[decision_point] + horizon_m) - 1, decision_point + 1),
        len(base_nodes) - 1,
    )
    nodes = [base_nodes[j] if j <= decision_point else horizon_nodes[j] for j in range(first, end + 1)]
    edges = [base_edges[k] if k < decision_point else horizon_edges[k] for k in range(first, end)]
    view.header += 1
    # its nodes and edges were validated once per plan (path_elements), its header is the master's
    return Order.model_construct(
        header_id=view.header,
        timestamp=timestamp,
        version=VDA5050_VERSION,
        manufacturer=view.identity.manufacturer,
        serial_number=view.identity.serial_number,
        order_id=order_id,
        order_update_id=view.update + 1,
        nodes=nodes,
        edges=edges,
    )
