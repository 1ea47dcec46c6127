"""VDA 5050 references the exported orders are checked against, none of them trajgen's own code.

All three come from the ``vda5050-sdk`` package (MIT, the ``test`` extra), so a clone of this
repository needs nothing beside it:

- the official VDA 5050 2.1.0 JSON schemas, which the sdk bundles unchanged
  (``vda5050/validation/schemas/order.json`` and ``factsheet.json``), checked with jsonschema;
- the sdk's pydantic models of the messages (:class:`vda5050.model.order.Order`);
- the sdk's order acceptance (:class:`vda5050.domain.order.OrderAcceptancePolicy`, the decision of
  VDA 5050 figure 8), run by :class:`SimulatedVehicle`, a vehicle that reports the state the
  standard describes after each order it accepted.
"""

from __future__ import annotations

import functools
import json
from importlib import resources

from jsonschema import Draft202012Validator
from pydantic import BaseModel
from vda5050.domain.order import AcceptanceResult, OrderAcceptancePolicy
from vda5050.domain.sessions.vehicle_session import VehicleSession
from vda5050.identity import VehicleKey
from vda5050.model.order import Order
from vda5050.model.state import State

#: The sdk's folder of the official schemas, ``<name>.json`` each.
SCHEMA_FOLDER = resources.files("vda5050.validation") / "schemas"


@functools.cache
def schema_validator(name: str) -> Draft202012Validator:
    """The validator of one official VDA 5050 schema, with format checks.

    Parameters
    ----------
    name : str
        The message type, as the sdk names its schema files: ``"order"``, ``"factsheet"``, ``"state"``.

    Returns
    -------
    Draft202012Validator
        A validator of the schema, itself checked against the JSON Schema metaschema.
    """
    schema = json.loads((SCHEMA_FOLDER / f"{name}.json").read_text(encoding="utf-8"))
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema, format_checker=Draft202012Validator.FORMAT_CHECKER)


def schema_errors(document: dict, name: str = "order") -> list[str]:
    """The official schema's objections to a message, each with the path of the offending value.

    Parameters
    ----------
    document : dict
        The message as parsed JSON.
    name : str
        The schema to check it against (see :func:`schema_validator`).

    Returns
    -------
    list of str
        ``"<path>: <message>"`` per error, sorted; empty for a valid message.
    """
    errors = schema_validator(name).iter_errors(document)
    return sorted(f"{'/'.join(map(str, error.path))}: {error.message}" for error in errors)


def unknown_fields(model: BaseModel, where: str = "") -> list[str]:
    """The fields of a parsed message that its sdk model does not define, at any depth.

    The sdk's models keep unknown fields (vendor extensions) instead of refusing them, so a
    misspelt optional field (``maxspeed``) parses; this lists it.

    Parameters
    ----------
    model : BaseModel
        A parsed sdk model.
    where : str
        The path of ``model`` in the message, for the report.

    Returns
    -------
    list of str
        The path of each unknown field, e.g. ``"nodes[2].nodeID"``.
    """
    found = [f"{where}{'.' if where else ''}{key}" for key in model.model_extra or {}]
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        path = f"{where}{'.' if where else ''}{field.alias or name}"
        items = enumerate(value) if isinstance(value, list) else [(None, value)]
        for index, item in items:
            if isinstance(item, BaseModel):
                found += unknown_fields(item, path if index is None else f"{path}[{index}]")
    return found


def parse_order(document: dict) -> Order:
    """A message parsed by the sdk's pydantic ``Order``, which must hold all of it unchanged.

    Parameters
    ----------
    document : dict
        An order or order update as parsed JSON.

    Returns
    -------
    Order
        The sdk's model of the message.

    Raises
    ------
    pydantic.ValidationError
        If the sdk's model refuses the message (a missing field, a wrong type or enum value).
    ValueError
        If the message has a field the model does not define, or the model's wire form of it
        differs from the message (a value the model coerced).
    """
    order = Order.model_validate(document)
    unknown = unknown_fields(order)
    if unknown:
        raise ValueError(f"fields the VDA 5050 order model does not define: {unknown}")
    if order.to_wire() != document:
        raise ValueError("the VDA 5050 order model does not give the message back unchanged")
    return order


class SimulatedVehicle:
    """A vehicle that decides on each order as the sdk's figure-8 acceptance does.

    It starts idle at a point of the map (no order, localized there). After accepting an order it
    drives to the order's decision point (its last released node) and reports the state the
    standard describes there: that node as its last node, the horizon's nodes and edges still to
    traverse. An order it does not accept leaves it as it was.

    Parameters
    ----------
    document : dict
        Any message to the vehicle (its first order): gives the header fields of its states.
    x, y : float
        Where the vehicle stands (m), on map ``map_id``.
    map_id : str
        The map the vehicle has, and the only one it accepts orders on.
    """

    def __init__(self, document: dict, x: float, y: float, map_id: str) -> None:
        self.manufacturer = document["manufacturer"]
        self.serial_number = document["serialNumber"]
        self.map_id = map_id
        self.policy = OrderAcceptancePolicy()
        self.session = VehicleSession(key=VehicleKey(self.manufacturer, self.serial_number))
        self.states_sent = 0
        self.x, self.y = x, y
        self.session.apply_state(self.state(order=None, x=x, y=y))

    def state(self, order: Order | None, x: float, y: float) -> State:
        """The state the vehicle reports standing at ``(x, y)`` after the accepted ``order``.

        Parameters
        ----------
        order : Order or None
            The last accepted order; ``None`` before the first (idle, on no node).
        x, y : float
            The vehicle's position (m).

        Returns
        -------
        State
            The state message; for an order, at its decision point with the horizon ahead.
        """
        wire = {
            "headerId": self.states_sent,
            "timestamp": "2025-05-01T08:00:00.000Z",
            "version": "2.1.0",
            "manufacturer": self.manufacturer,
            "serialNumber": self.serial_number,
            "orderId": "",
            "orderUpdateId": 0,
            "lastNodeId": "",
            "lastNodeSequenceId": 0,
            "nodeStates": [],
            "edgeStates": [],
            "agvPosition": {"positionInitialized": True, "x": x, "y": y, "theta": 0.0, "mapId": self.map_id},
            "driving": False,
            "actionStates": [],
            "batteryState": {"batteryCharge": 80.0, "charging": False},
            "operatingMode": "AUTOMATIC",
            "errors": [],
            "safetyState": {"eStop": "NONE", "fieldViolation": False},
        }
        if order is not None:
            decision = max(k for k, node in enumerate(order.nodes) if node.released)
            wire |= {
                "orderId": order.order_id,
                "orderUpdateId": order.order_update_id,
                "lastNodeId": order.nodes[decision].node_id,
                "lastNodeSequenceId": order.nodes[decision].sequence_id,
                "nodeStates": [
                    {"nodeId": node.node_id, "sequenceId": node.sequence_id, "released": node.released}
                    for node in order.nodes[decision + 1 :]
                ],
                "edgeStates": [
                    {"edgeId": edge.edge_id, "sequenceId": edge.sequence_id, "released": edge.released}
                    for edge in order.edges[decision:]
                ],
            }
        errors = schema_errors(wire, "state")
        if errors:  # the simulated vehicle itself must speak VDA 5050
            raise ValueError(f"the simulated state is not a valid VDA 5050 state: {errors}")
        return State.model_validate(wire)

    def receive(self, document: dict) -> AcceptanceResult:
        """The sdk's acceptance decision on one message; an accepted order is then driven.

        Parameters
        ----------
        document : dict
            An order or order update as parsed JSON (parsed with :func:`parse_order`).

        Returns
        -------
        AcceptanceResult
            The decision (``ACCEPT_NEW``, ``ACCEPT_UPDATE``, or why not) of the sdk's policy.
        """
        order = parse_order(document)
        result = self.policy.evaluate(order, self.session, available_map_ids={self.map_id})
        if result.accepted:
            self.session.apply_order(order)
            decision_point = [node for node in order.nodes if node.released][-1].node_position
            if decision_point is not None:  # a node without a position: the vehicle knows where it is
                self.x, self.y = decision_point.x, decision_point.y
            self.states_sent += 1
            self.session.apply_state(self.state(order, self.x, self.y))
        return result
