"""A verified plan made ready to send, the run's id, and what "where the plan starts it" means.

Readying a plan (cutting each path into nodes, the release rule over them, the order elements as
vda5050-sdk models) takes a while on long paths: it is done where the plan is made, in the planning
thread, never while the master's lock is held.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass

from trajgen.export.vda5050.release import BaseRelease, OrderReleases, order_releases
from trajgen.live.clock import RunClock
from trajgen.live.orders import NODE_DEVIATION, path_elements
from trajgen.verification import VerifiedSchedule

__all__ = ["START_TOLERANCE", "ReadyPlan", "ready_plan", "run_id"]

#: How far along the track a vehicle may stand from where the plan starts it and still be there,
#: metres: the ``allowedDeviationXY`` of the nodes sent (a vehicle farther away refuses its order).
START_TOLERANCE = NODE_DEVIATION


@dataclass(frozen=True, slots=True)
class ReadyPlan:
    """A verified plan made ready to send.

    Attributes
    ----------
    verified : VerifiedSchedule
    releases : OrderReleases
        Each vehicle's path cut into nodes (:func:`~trajgen.export.vda5050.release.order_releases`).
    rule : BaseRelease
        The release rule over those paths, at its start (it changes as vehicles report nodes).
    elements : tuple
        Per vehicle, its path's nodes and edges as vda5050-sdk models
        (:func:`~trajgen.live.orders.path_elements`), their ``sequenceId`` from ``offsets``.
    offsets : tuple of int
        Per vehicle, the ``sequenceId`` of its path's first node.
    """

    verified: VerifiedSchedule
    releases: OrderReleases
    rule: BaseRelease
    elements: tuple
    offsets: tuple[int, ...]


def ready_plan(verified: VerifiedSchedule, offsets, *, spacing: float, map_id: str) -> ReadyPlan:
    """``verified`` ready to send: its order paths, release rule and order elements.

    Nodes at most ``spacing`` metres apart, ``nodePosition.mapId`` ``map_id``, each path numbered from
    its ``offsets``.
    """
    releases = order_releases(verified, spacing=spacing)
    rule = BaseRelease(releases.paths, verified.schedule.limits.min_separation)
    elements = tuple(
        path_elements(path, offset=offset, map_id=map_id)
        for path, offset in zip(releases.paths, offsets, strict=True)
    )
    return ReadyPlan(verified, releases, rule, elements, tuple(offsets))


def run_id(clock: RunClock) -> str:
    """A run's part of every ``orderId``: the UTC time its clock started, to the millisecond."""
    moment = datetime.datetime.strptime(clock.timestamp(0.0), "%Y-%m-%dT%H:%M:%S.%fZ")
    return moment.strftime("%Y%m%dT%H%M%S") + f"{moment.microsecond // 1000:03d}"
