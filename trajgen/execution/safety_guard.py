"""The braking invariant, the executor's last defence: every two vehicles can always stop apart.

Every cycle, before the setpoints are issued, :class:`SafetyGuard` asks the
:class:`~trajgen.execution.braking_check.BrakingCheck` of each pair of vehicles whether both, braking at
once from here (each anywhere between its service braking from the commanded
state and its emergency stop from the measured one), keep the separation until
both are at rest, certified between its samples too. A follower whose next
setpoint would break it holds (service braking, the motion the last cycle
certified) instead; if even that cannot be certified (a fault moved a vehicle
beyond the margins), both brake hard: an **emergency brake**, counted and
reported. A correct frontier never lets that happen.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

from limits import Limits
from topology import StarGraph, TrackGraph
from topology.indexed import separation as indexed_separation
from trajgen.execution.braking_check import BrakingCheck, PathState
from trajgen.model.coordination import stopping_distance
from trajgen.model.graph_vehicle_path import GraphMetric, GraphVehiclePath
from trajgen.model.paths import VehiclePath

__all__ = ["SEPARATION_TOLERANCE", "SafetyGuard"]

#: Track distance by which the separation may be missed (round-off of a plan parked at a leg's end, and
#: a drive's noise at rest), metres: the 1 µm the simulation counts a violation beyond.
SEPARATION_TOLERANCE = 1e-6


class SafetyGuard:
    """Certifies setpoints of every vehicle against the braking invariant, pair by pair.

    Parameters
    ----------
    limits : Limits
        The vehicles' limits and the separation to keep, metres.
    graph : StarGraph or TrackGraph
        The track: a junction (places are a leg and metres from the junction) or a track graph
        (places are an edge and metres from its ``from`` node).
    """

    __slots__ = ("_checks", "_limits", "_metric", "_pairs", "separation")

    def __init__(self, limits: Limits, graph: StarGraph | TrackGraph) -> None:
        vehicles = limits.vehicles
        self._metric = GraphMetric(graph) if isinstance(graph, TrackGraph) else None
        track = self._metric if self._metric is not None else graph.lengths
        emergency = tuple(v.emergency_braking for v in vehicles)
        #: every pair of vehicles, in the order of ``itertools.combinations``, and its braking check
        self._pairs = tuple(itertools.combinations(range(len(vehicles)), 2))
        self._checks = tuple(
            BrakingCheck((vehicles[i], vehicles[j]), (emergency[i], emergency[j]), track)
            for i, j in self._pairs
        )
        self._limits = vehicles
        self.separation = limits.min_separation

    def _distance(self, first: tuple[int, float], second: tuple[int, float]) -> float:
        """Track distance between two places, metres."""
        if self._metric is None:
            return indexed_separation((first[0], first[1], second[0], second[1]))
        return self._metric.distance(first[0], first[1], second[0], second[1])

    def required(self, measured) -> tuple[float, ...]:
        """The track distance each pair keeps, metres: the separation, less if a fault left them closer.

        Closer than the separation after a fault, two vehicles may only part (to round-off: no ratchet
        from cycle to cycle).

        Parameters
        ----------
        measured : sequence of VehicleState
            One per vehicle: its ``leg`` and ``s`` (on a track graph: the edge and metres on it).

        Returns
        -------
        tuple of float
            One per pair of vehicles, in the order of ``itertools.combinations``.
        """
        return tuple(
            min(
                self.separation - SEPARATION_TOLERANCE,
                self._distance((measured[i].leg, measured[i].s), (measured[j].leg, measured[j].s)) - 1e-12,
            )
            for i, j in self._pairs
        )

    def certifies(
        self,
        paths: Sequence[VehiclePath] | Sequence[GraphVehiclePath],
        commanded: Sequence[PathState],
        measured: Sequence[PathState],
        required: Sequence[float],
        *,
        hold: bool = False,
    ) -> bool:
        """Whether braking from ``commanded`` (service) and ``measured`` (emergency) keeps ``required``.

        Every pair of vehicles is checked against its own ``required`` distance (:meth:`required`).
        ``hold``: the setpoints hold vehicles (they brake as the last cycle certified), checked to the
        millimetre; new motion is certified with the check's coarser intervals, whose pessimism keeps
        room for the holds that may follow (:meth:`~trajgen.execution.braking_check.BrakingCheck.clearance`).

        Vehicles far apart are certified at once: the track distance changes by at most the
        distance each vehicle drives, and none drives farther than its service stop from its
        commanded state (it starts there, or at most as far from its measured one as the two differ).
        """
        reach = []
        for v, (command, measure) in enumerate(zip(commanded, measured, strict=True)):
            stop = stopping_distance(command.v, command.a, self._limits[v])
            reach.append(
                stop + abs(command.p - measure.p) + measure.v * measure.v / self._limits[v].emergency_braking
            )
        for (i, j), check, need in zip(self._pairs, self._checks, required, strict=True):
            gap = self._distance(paths[i].locate(commanded[i].p), paths[j].locate(commanded[j].p))
            if gap - (reach[i] + reach[j]) >= need:
                continue
            pair = (paths[i], paths[j])
            if not check.clearance(
                pair, (commanded[i], commanded[j]), (measured[i], measured[j]), need, refine=hold
            ):
                return False
        return True
