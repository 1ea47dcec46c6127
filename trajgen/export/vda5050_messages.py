"""The bytes of the VDA 5050 messages: each order and order update (header, nodes, edges), and the manifest.

A message's ``timestamp`` is the options' start time plus the ``send_at`` of
its release; its ``headerId`` is the options' ``first_header_id`` plus its
``orderUpdateId``. The manifest indexes a run's messages: each file, when and
on which event to send it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import PurePosixPath

from topology import JUNCTION_INDEX, JUNCTION_NAME, StarGraph
from trajgen.errors import OptionError
from trajgen.export.vda5050_options import Vda5050Options
from trajgen.export.vda5050_path import NodeKind, OrderPath, PathEdge, PathNode
from trajgen.export.vda5050_release import OrderPlan, Release, plan_orders
from trajgen.model.schedule import Schedule
from trajgen.scenario.naming import check_vehicle_names
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "VDA5050_VERSION",
    "OrderMessage",
    "edge_id",
    "node_id",
    "order_elements",
    "render_manifest",
    "render_orders",
]

#: The protocol version written into every message.
VDA5050_VERSION = "2.1.0"


def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def node_id(graph: StarGraph, leg: int, s: float) -> str:
    """The id of the node at ``s`` metres on leg ``leg``: ``"O"`` or ``"<leg name>:<metres>"`` (µm).

    Examples
    --------
    >>> node_id(StarGraph({"A": 10.0, "B": 10.0, "C": 10.0}), 0, 1.5)
    'A:1.5'
    >>> node_id(StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0}), 3, 10.0)
    'E:10'
    """
    if leg == JUNCTION_INDEX or s == 0.0:
        return JUNCTION_NAME
    return f"{graph.names[leg]}:{_number(s)}"


def edge_id(start: str, end: str) -> str:
    """The id of the edge from node ``start`` to node ``end``: ``"<start>-><end>"``."""
    return f"{start}->{end}"


def _timestamp(start: datetime, seconds: float) -> str:
    """ISO 8601 UTC with milliseconds, rounded up (a message is never stamped before it is safe)."""
    moment = start + timedelta(milliseconds=math.ceil(round(seconds * 1000.0, 6)))
    return moment.strftime("%Y-%m-%dT%H:%M:%S.") + f"{moment.microsecond // 1000:03d}Z"


def _coordinate(value: float) -> float:
    return round(value, 9) + 0.0  # nanometres, no "-0.0"


def _node_description(node: PathNode) -> str:
    parts = []
    for kind in node.kinds:
        if kind is NodeKind.HOLD:
            parts.append(f"hold: {_number(node.s)} m from the junction (the minimum separation)")
        else:
            parts.append(kind.value)
    return ", ".join(parts)


def _node_json(graph: StarGraph, node: PathNode, sequence: int, released: bool, map_id: str) -> dict:
    angle = math.radians(graph.angles_deg[node.leg]) if node.leg != JUNCTION_INDEX else 0.0
    return {
        "nodeId": node_id(graph, node.leg, node.s),
        "sequenceId": sequence,
        "nodeDescription": _node_description(node),
        "released": released,
        "nodePosition": {
            "x": _coordinate(node.s * math.cos(angle)),
            "y": _coordinate(node.s * math.sin(angle)),
            "mapId": map_id,
        },
        "actions": [],
    }


def _edge_json(graph: StarGraph, path: OrderPath, edge: PathEdge, released: bool) -> dict:
    start, end = path.nodes[edge.index], path.nodes[edge.index + 1]
    first, second = node_id(graph, start.leg, start.s), node_id(graph, end.leg, end.s)
    data = {
        "edgeId": edge_id(first, second),
        "sequenceId": 2 * edge.index + 1,
        "released": released,
        "startNodeId": first,
        "endNodeId": second,
        "maxSpeed": edge.max_speed,
        "length": _coordinate(edge.length),
        "orientation": math.pi if edge.backward else 0.0,
        "orientationType": "TANGENTIAL",
        "actions": [],
    }
    if start.leg == JUNCTION_INDEX and end.leg != JUNCTION_INDEX:
        data["direction"] = graph.names[end.leg]  # the leg taken at the junction
    return data


def order_elements(
    graph: StarGraph, path: OrderPath, *, first: int, decision_point: int, map_id: str
) -> tuple[list[dict], list[dict]]:
    """The ``nodes`` and ``edges`` of an order (update) of ``path``, as JSON documents.

    Parameters
    ----------
    graph : StarGraph
    path : OrderPath
    first : int
        Index of the first node sent: 0 for an order, the previous decision point for an update.
    decision_point : int
        Index of the last base node; the nodes and edges after it are the horizon.
    map_id : str
        ``nodePosition.mapId``.

    Returns
    -------
    nodes, edges : list of dict
        Node ``j`` has ``sequenceId`` ``2 j``, edge ``k`` ``2 k + 1``.
    """
    nodes = [
        _node_json(graph, node, 2 * j, j <= decision_point, map_id)
        for j, node in enumerate(path.nodes)
        if j >= first
    ]
    edges = [
        _edge_json(graph, path, edge, edge.index < decision_point)
        for edge in path.edges
        if edge.index >= first
    ]
    return nodes, edges


@dataclass(frozen=True, slots=True)
class OrderMessage:
    """One rendered message and when to send it.

    Attributes
    ----------
    vehicle : int
        0 or 1.
    release : Release
    header_id : int
    timestamp : str
        ISO 8601, UTC.
    path : PurePosixPath
        Where it is written, relative to the output folder: ``<vehicle name>/order-<update>.json``.
    data : bytes
        The JSON message, UTF-8.
    """

    vehicle: int
    release: Release
    header_id: int
    timestamp: str
    path: PurePosixPath
    data: bytes


def _dumps(document: dict) -> bytes:
    return (json.dumps(document, indent=2, ensure_ascii=False, allow_nan=False) + "\n").encode("utf-8")


def _checked(verified: object, names: Sequence[str], options: object, what: str):
    schedule = require_verified(verified, what).schedule
    names = check_vehicle_names(names)
    if not isinstance(options, Vda5050Options):
        raise OptionError(f"VDA 5050 options must be Vda5050Options, got {type(options).__name__}")
    return schedule, names


def render_orders(
    verified: VerifiedSchedule,
    names: Sequence[str],
    *,
    options: Vda5050Options,
    plan: OrderPlan | None = None,
) -> tuple[OrderMessage, ...]:
    """Every VDA 5050 order message of both vehicles, in the order they are sent.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of 2 str
        Vehicle names (folder names, default serial numbers).
    options : Vda5050Options
    plan : OrderPlan, optional
        ``plan_orders(verified)``, if already computed.

    Returns
    -------
    tuple of OrderMessage

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names or options.
    """
    schedule, names = _checked(verified, names, options, "render_orders")
    plan = plan_orders(verified) if plan is None else plan
    graph = schedule.route.graph
    messages = []
    for release in plan.releases:
        vehicle = release.vehicle
        path = plan.paths[vehicle]
        nodes, edges = order_elements(
            graph, path, first=release.first, decision_point=release.decision_point, map_id=options.map_id
        )
        header_id = options.first_header_id + release.update
        timestamp = _timestamp(options.start_time, release.send_at)
        document = {
            "headerId": header_id,
            "timestamp": timestamp,
            "version": VDA5050_VERSION,
            "manufacturer": options.manufacturers[vehicle],
            "serialNumber": options.serial_number(vehicle, names),
            "orderId": f"{options.order_id}-{names[vehicle]}",
            "orderUpdateId": release.update,
            "nodes": nodes,
            "edges": edges,
        }
        messages.append(
            OrderMessage(
                vehicle,
                release,
                header_id,
                timestamp,
                PurePosixPath(names[vehicle], f"order-{release.update:03d}.json"),
                _dumps(document),
            )
        )
    return tuple(messages)


def _manifest(schedule: Schedule, plan: OrderPlan, messages, names, options: Vda5050Options) -> dict:
    graph = schedule.route.graph

    def node_ref(vehicle: int, index: int) -> dict:
        node = plan.paths[vehicle].nodes[index]
        return {"node_id": node_id(graph, node.leg, node.s), "sequence_id": 2 * index}

    entries = []
    for message in messages:
        release = message.release
        trigger = None
        if release.trigger is not None:
            other, index = release.trigger
            trigger = {"vehicle": names[other], **node_ref(other, index)}
        entries.append(
            {
                "file": str(message.path),
                "vehicle": names[message.vehicle],
                "order_update_id": release.update,
                "header_id": message.header_id,
                "send_at_s": round(release.send_at, 6),
                "timestamp": message.timestamp,
                "trigger": trigger,
                "first_node": node_ref(message.vehicle, release.first),
                "decision_point": node_ref(message.vehicle, release.decision_point),
                "needed_at_s": None if release.needed_at is None else round(release.needed_at, 6),
                "wait_s": round(release.wait, 6),
            }
        )
    vehicles = {}
    for vehicle, name in enumerate(names):
        path = plan.paths[vehicle]
        vehicles[name] = {
            "manufacturer": options.manufacturers[vehicle],
            "serial_number": options.serial_number(vehicle, names),
            "order_id": f"{options.order_id}-{name}",
            "nodes": [node_id(graph, n.leg, n.s) for n in path.nodes],
            "messages": sum(1 for m in messages if m.vehicle == vehicle),
        }
    return {
        "format": "trajgen VDA 5050 orders",
        "version": VDA5050_VERSION,
        "start_time": _timestamp(options.start_time, 0.0),
        "map_id": options.map_id,
        "method": schedule.method.name,
        "min_separation_m": schedule.limits.min_separation,
        "schedule_duration_s": round(schedule.duration, 6),
        "planned_duration_s": round(plan.planned_duration, 6),
        "vehicles": vehicles,
        "messages": entries,
    }


def render_manifest(
    verified: VerifiedSchedule,
    names: Sequence[str],
    messages: Sequence[OrderMessage],
    *,
    options: Vda5050Options,
    plan: OrderPlan | None = None,
) -> bytes:
    """The index of a run's messages (``manifest.json``): each file, when and on which event to send it.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of 2 str
    messages : sequence of OrderMessage
        From :func:`render_orders` with the same arguments.
    options : Vda5050Options
    plan : OrderPlan, optional
        ``plan_orders(verified)``, if already computed.

    Returns
    -------
    bytes
        JSON, UTF-8.
    """
    schedule, names = _checked(verified, names, options, "render_manifest")
    plan = plan_orders(verified) if plan is None else plan
    return _dumps(_manifest(schedule, plan, messages, names, options))
