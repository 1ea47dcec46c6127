"""The braking invariant, the executor's last defence: both vehicles can always stop apart.

Every cycle, before a pair of setpoints is issued, :class:`SafetyGuard` asks the
:class:`~trajgen.execution.braking_check.BrakingCheck` whether both vehicles, braking at
once from here (each anywhere between its service braking from the commanded
state and its emergency stop from the measured one), keep the separation until
both are at rest, certified between its samples too. A follower whose next
setpoint would break it holds (service braking, the motion the last cycle
certified) instead; if even that cannot be certified (a fault moved a vehicle
beyond the margins), both brake hard: an **emergency brake**, counted and
reported. A correct frontier never lets that happen.
"""

from __future__ import annotations

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
    """Certifies setpoint pairs against the braking invariant.

    Parameters
    ----------
    limits : Limits
        The vehicles' limits and the separation to keep, metres.
    graph : StarGraph or TrackGraph
        The track: a junction (places are a leg and metres from the junction) or a track graph
        (places are an edge and metres from its ``from`` node).
    """

    __slots__ = ("_check", "_limits", "_metric", "separation")

    def __init__(self, limits: Limits, graph: StarGraph | TrackGraph) -> None:
        vehicles = limits.vehicles
        self._metric = GraphMetric(graph) if isinstance(graph, TrackGraph) else None
        track = self._metric if self._metric is not None else graph.lengths
        self._check = BrakingCheck(vehicles, tuple(v.emergency_braking for v in vehicles), track)
        self._limits = vehicles
        self.separation = limits.min_separation

    def _distance(self, first: tuple[int, float], second: tuple[int, float]) -> float:
        """Track distance between two places, metres."""
        if self._metric is None:
            return indexed_separation((first[0], first[1], second[0], second[1]))
        return self._metric.distance(first[0], first[1], second[0], second[1])

    def required(self, measured) -> float:
        """The track distance to keep, metres: the separation, less if a fault already left them closer.

        Closer than the separation after a fault, the vehicles may only part (to round-off: no ratchet
        from cycle to cycle).

        Parameters
        ----------
        measured : tuple of 2 VehicleState
            Their ``leg`` and ``s`` (on a track graph: the edge and metres on it).
        """
        apart = self._distance((measured[0].leg, measured[0].s), (measured[1].leg, measured[1].s))
        return min(self.separation - SEPARATION_TOLERANCE, apart - 1e-12)

    def certifies(
        self,
        paths: tuple[VehiclePath, VehiclePath] | tuple[GraphVehiclePath, GraphVehiclePath],
        commanded: tuple[PathState, PathState],
        measured: tuple[PathState, PathState],
        required: float,
        *,
        hold: bool = False,
    ) -> bool:
        """Whether braking from ``commanded`` (service) and ``measured`` (emergency) keeps ``required``.

        ``hold``: the setpoints hold vehicles (they brake as the last cycle certified), checked to the
        millimetre; new motion is certified with the check's coarser intervals, whose pessimism keeps
        room for the holds that may follow (:meth:`~trajgen.execution.braking_check.BrakingCheck.clearance`).

        Vehicles far apart are certified at once: the track distance changes by at most the
        distance each vehicle drives, and none drives farther than its service stop from its
        commanded state (it starts there, or at most as far from its measured one as the two differ).
        """
        travel = 0.0
        for v in (0, 1):
            command, measure = commanded[v], measured[v]
            stop = stopping_distance(command.v, command.a, self._limits[v])
            travel += (
                stop + abs(command.p - measure.p) + measure.v * measure.v / self._limits[v].emergency_braking
            )
        gap = self._distance(paths[0].locate(commanded[0].p), paths[1].locate(commanded[1].p))
        if gap - travel >= required:
            return True
        return self._check.clearance(paths, commanded, measured, required, refine=hold)
