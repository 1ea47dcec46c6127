"""The bytes of the VDA 5050 messages: each order and order update (header, nodes, edges), and the manifest.

A message's ``timestamp`` is the options' start time plus the ``send_at`` of
its release; its ``headerId`` is the options' ``first_header_id`` plus its
``orderUpdateId``. The manifest indexes a run's messages: each file, when and
on which event to send it.
"""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import PurePosixPath

from trajgen.errors import OptionError
from trajgen.export.vda5050.graph_path import GraphOrderPath
from trajgen.export.vda5050.options import Vda5050Options
from trajgen.export.vda5050.path import OrderPath, node_id
from trajgen.export.vda5050.release import OrderReleases, Release, order_releases
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.schedule import Schedule
from trajgen.scenario.naming import check_vehicle_names
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = [
    "VDA5050_VERSION",
    "OrderMessage",
    "edge_id",
    "node_id",
    "order_document",
    "order_elements",
    "path_node_id",
    "render_manifest",
    "render_orders",
]

#: The protocol version written into every message.
VDA5050_VERSION = "2.1.0"


def edge_id(start: str, end: str) -> str:
    """The id of the edge from node ``start`` to node ``end``: ``"<start>-><end>"``."""
    return f"{start}->{end}"


def _timestamp(start: datetime, seconds: float) -> str:
    """ISO 8601 UTC with milliseconds, rounded up (a message is never stamped before it is safe)."""
    moment = start + timedelta(milliseconds=math.ceil(round(seconds * 1000.0, 6)))
    return moment.strftime("%Y-%m-%dT%H:%M:%S.") + f"{moment.microsecond // 1000:03d}Z"


def _coordinate(value: float) -> float:
    return round(value, 9) + 0.0  # nanometres, no "-0.0"


def _order_node(path, index: int, sequence: int, released: bool, map_id: str, deviation):
    """Node ``index`` of ``path`` (either kind of order path: they answer the same questions)."""
    from vda5050.model.order import Node

    xy = path.node_xy(index)
    position = None
    if xy is not None:  # a track without coordinates, or a point inside a curved edge, has none to give
        position = {
            "x": _coordinate(xy[0]),
            "y": _coordinate(xy[1]),
            "allowed_deviation_xy": deviation,
            "map_id": map_id,
        }
    return Node(
        node_id=path.node_id(index),
        sequence_id=sequence,
        node_description=path.node_description(index),
        released=released,
        node_position=position,
        actions=[],
    )


def _order_edge(path, index: int, sequence: int, released: bool):
    """Edge ``index`` of ``path``, between its nodes' ids (the leg or track edge it leaves a junction by)."""
    from vda5050.model.order import Edge

    edge = path.edges[index]
    first, second = path.node_id(index), path.node_id(index + 1)
    return Edge(
        edge_id=edge_id(first, second),
        sequence_id=sequence,
        released=released,
        start_node_id=first,
        end_node_id=second,
        max_speed=edge.max_speed,
        length=_coordinate(edge.length),
        orientation=math.pi if edge.backward else 0.0,
        orientation_type="TANGENTIAL",
        direction=path.edge_direction(index),
        actions=[],
    )


def path_node_id(path: OrderPath | GraphOrderPath, index: int) -> str:
    """The id of node ``index`` of ``path`` (each kind of path knows its track)."""
    return path.node_id(index)


def order_elements(
    path: OrderPath | GraphOrderPath,
    *,
    first: int,
    decision_point: int,
    map_id: str,
    last: int | None = None,
    sequence_offset: int = 0,
    node_deviation: float | None = None,
) -> tuple[list, list]:
    """The ``nodes`` and ``edges`` of an order (update) of ``path``, as vda5050-sdk models.

    The one builder of VDA 5050 order elements: the file export (:func:`render_orders`) and the
    live master (:mod:`trajgen.live.orders`) both take theirs from here.

    Parameters
    ----------
    path : OrderPath or GraphOrderPath
        A vehicle's path on a junction or on a track graph (each knows its track).
    first : int
        Index of the first node sent: 0 for an order, the previous decision point for an update.
    decision_point : int
        Index of the last base node; the nodes and edges after it are the horizon.
    map_id : str
        ``nodePosition.mapId``.
    last : int, optional
        Index of the last node sent (default: the path's last).
    sequence_offset : int, optional
        Added to every ``sequenceId`` (a path stitched after a goal change continues the numbering).
    node_deviation : float, optional
        ``nodePosition.allowedDeviationXY``, metres (default: none written).

    Returns
    -------
    nodes : list of vda5050.model.order.Node
        Node ``j`` has ``sequenceId`` ``2 j`` (plus the offset).
    edges : list of vda5050.model.order.Edge
        Edge ``k`` has ``sequenceId`` ``2 k + 1`` (plus the offset).
    """
    last = len(path.nodes) - 1 if last is None else last
    nodes = [
        _order_node(path, j, sequence_offset + 2 * j, j <= decision_point, map_id, node_deviation)
        for j in range(first, last + 1)
    ]
    edges = [
        _order_edge(path, k, sequence_offset + 2 * k + 1, k < decision_point) for k in range(first, last)
    ]
    return nodes, edges


#: Key order of each kind of object in the files (the sdk's models order some fields otherwise).
_FILE_KEYS = {
    "order": (
        "headerId",
        "timestamp",
        "version",
        "manufacturer",
        "serialNumber",
        "orderId",
        "orderUpdateId",
        "nodes",
        "edges",
    ),
    "node": ("nodeId", "sequenceId", "nodeDescription", "released", "nodePosition", "actions"),
    "edge": (
        "edgeId",
        "sequenceId",
        "released",
        "startNodeId",
        "endNodeId",
        "maxSpeed",
        "length",
        "orientation",
        "orientationType",
        "actions",
        "direction",
    ),
}


def _in_file_order(document: dict, kind: str) -> dict:
    keys = _FILE_KEYS[kind]
    ordered = {key: document[key] for key in keys if key in document}
    ordered.update((key, value) for key, value in document.items() if key not in ordered)
    return ordered


def order_document(order) -> dict:
    """An order model (vda5050-sdk ``Order``) as the JSON document of the files, keys in their order."""
    document = _in_file_order(order.model_dump(mode="json", by_alias=True, exclude_none=True), "order")
    document["nodes"] = [_in_file_order(node, "node") for node in document["nodes"]]
    document["edges"] = [_in_file_order(edge, "edge") for edge in document["edges"]]
    return document


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
    names = check_vehicle_names(names, count=schedule.limits.count)
    if not isinstance(options, Vda5050Options):
        raise OptionError(f"VDA 5050 options must be Vda5050Options, got {type(options).__name__}")
    options.check_vehicles(schedule.limits.count)
    return schedule, names


def _releases(
    verified, releases: OrderReleases | None, plan: OrderReleases | None, caller: str
) -> OrderReleases:
    """``releases``, or the deprecated ``plan``, or computed from ``verified``."""
    if plan is not None:
        warnings.warn(
            f"{caller}(plan=...) is deprecated: the keyword is now releases=",
            DeprecationWarning,
            stacklevel=3,
        )
        releases = plan if releases is None else releases
    return order_releases(verified) if releases is None else releases


def render_orders(
    verified: VerifiedSchedule,
    names: Sequence[str],
    *,
    options: Vda5050Options,
    releases: OrderReleases | None = None,
    plan: OrderReleases | None = None,
) -> tuple[OrderMessage, ...]:
    """Every VDA 5050 order message of every vehicle, in the order they are sent.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of str
        Vehicle names (folder names, default serial numbers).
    options : Vda5050Options
    releases : OrderReleases, optional
        ``order_releases(verified)``, if already computed.
    plan : OrderReleases, optional
        Deprecated name of ``releases`` (trajgen 0.6).

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
    from vda5050.model.order import Order

    _, names = _checked(verified, names, options, "render_orders")
    plan = _releases(verified, releases, plan, "render_orders")
    messages = []
    for release in plan.releases:
        vehicle = release.vehicle
        path = plan.paths[vehicle]
        nodes, edges = order_elements(
            path, first=release.first, decision_point=release.decision_point, map_id=options.map_id
        )
        header_id = options.first_header_id + release.update
        timestamp = _timestamp(options.start_time, release.send_at)
        order = Order(
            header_id=header_id,
            timestamp=timestamp,
            version=VDA5050_VERSION,
            manufacturer=options.manufacturer(vehicle),
            serial_number=options.serial_number(vehicle, names),
            order_id=f"{options.order_id}-{names[vehicle]}",
            order_update_id=release.update,
            nodes=nodes,
            edges=edges,
        )
        document = order_document(order)
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


def _manifest(
    schedule: Schedule | GraphSchedule, plan: OrderReleases, messages, names, options: Vda5050Options
) -> dict:
    def node_ref(vehicle: int, index: int) -> dict:
        return {"node_id": plan.paths[vehicle].node_id(index), "sequence_id": 2 * index}

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
            "manufacturer": options.manufacturer(vehicle),
            "serial_number": options.serial_number(vehicle, names),
            "order_id": f"{options.order_id}-{name}",
            "nodes": [path.node_id(index) for index in range(len(path.nodes))],
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
    releases: OrderReleases | None = None,
    plan: OrderReleases | None = None,
) -> bytes:
    """The index of a run's messages (``manifest.json``): each file, when and on which event to send it.

    Parameters
    ----------
    verified : VerifiedSchedule
    names : sequence of str
    messages : sequence of OrderMessage
        From :func:`render_orders` with the same arguments.
    options : Vda5050Options
    releases : OrderReleases, optional
        ``order_releases(verified)``, if already computed.
    plan : OrderReleases, optional
        Deprecated name of ``releases`` (trajgen 0.6).

    Returns
    -------
    bytes
        JSON, UTF-8.
    """
    schedule, names = _checked(verified, names, options, "render_manifest")
    plan = _releases(verified, releases, plan, "render_manifest")
    return _dumps(_manifest(schedule, plan, messages, names, options))
