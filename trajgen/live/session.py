"""A live run's parts from a scenario: the plan, the vehicles' identities and places, the demo.

:func:`live_plan` plans and verifies the run; :func:`identities` names each
vehicle on the broker (by default its scenario name as serial number);
:func:`position_xy` and :func:`track_position` convert between the track and
the map's x/y (the legs drawn at the scenario's angles), as the orders and
states carry positions; :func:`run_demo` runs a broker, two simulated
vehicles and the master in this process.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from topology import StarGraph, TrackGraph
from trajgen.errors import InputError
from trajgen.execution.goals import schedule_for_execution
from trajgen.live.clock import RunClock
from trajgen.live.geometry import position_xy, track_position
from trajgen.live.master import RELEASE_SPACING, LiveMaster, LiveRun
from trajgen.live.mqtt import (
    DEFAULT_INTERFACE,
    DEFAULT_VERSION,
    MASTER_SERIAL,
    BrokerSettings,
    VehicleIdentity,
)
from trajgen.live.places import scenario_starts, snapshot_point, start_place
from trajgen.live.runlog import RunLog
from trajgen.live.vehicle import SimulatedVehicle, StopFault, VehicleSnapshot
from trajgen.verification import VerifiedSchedule

__all__ = [
    "DEFAULT_MANUFACTURER",
    "ClosestApproach",
    "DemoRun",
    "LiveDemo",
    "identities",
    "live_plan",
    "position_xy",
    "run_demo",
    "track_position",
]

logger = logging.getLogger(__name__)

#: ``manufacturer`` of both vehicles when none is given (as the VDA 5050 file export writes).
DEFAULT_MANUFACTURER = "unspecified"


def live_plan(scenario, *, method=None) -> VerifiedSchedule:
    """The verified plan of ``scenario`` for a live run: the online executor's plan.

    The same plan :func:`~trajgen.execution.goals.schedule_for_execution` gives (``optimal`` with the
    braking rule in its problem, a position margin on the separation): what is planned is what
    both the executor and the live master carry out.
    """
    return schedule_for_execution(scenario, method=method)


def identities(
    names: Sequence[str],
    *,
    manufacturer: str = DEFAULT_MANUFACTURER,
    serial_numbers: Sequence[str] | None = None,
    interface: str = DEFAULT_INTERFACE,
    version: str = DEFAULT_VERSION,
) -> tuple[VehicleIdentity, VehicleIdentity]:
    """Both vehicles' identities: ``serial_numbers`` default to the vehicle names.

    Raises
    ------
    InputError
        Not two serial numbers, two equal ones, or a level an MQTT topic cannot carry.
    """
    serials = tuple(names if serial_numbers is None else serial_numbers)
    if len(serials) != len(names) or len(set(serials)) != len(serials):
        raise InputError(f"serial numbers {serials!r}: expected {len(names)} different ones, one per vehicle")
    if MASTER_SERIAL in serials:
        raise InputError(
            f"serial numbers {serials!r}: {MASTER_SERIAL!r} is the master's own (its connection topic); "
            "expected other serial numbers (--serial-numbers)"
        )
    return tuple(VehicleIdentity(manufacturer, serial, interface, version) for serial in serials)


@dataclass(frozen=True, slots=True)
class DemoRun:
    """What :func:`run_demo` did.

    Attributes
    ----------
    run : LiveRun
    log : RunLog
        Its run log (the caller closes it).
    closest : float
        The smallest track distance between the vehicles' true positions at every control cycle, metres
        (:class:`ClosestApproach`).
    vehicles : tuple of 2 SimulatedVehicle
        Stopped.
    """

    run: LiveRun
    log: RunLog
    closest: float
    vehicles: tuple[SimulatedVehicle, SimulatedVehicle]


class LiveDemo:
    """A broker (unless one is given), two simulated vehicles and the master, in this process.

    The broker is mosquitto when it is installed, else amqtt, on a free port of 127.0.0.1.

    Parameters
    ----------
    scenario : Scenario
    verified : VerifiedSchedule, optional
        The plan (default: :func:`live_plan` of ``scenario`` with ``method``).
    method : TimingMethod or str, optional
    time_scale : float
        Seconds of the run per wall-clock second.
    faults : tuple of 2 sequence of StopFault
        Per vehicle.
    broker_url : str, optional
        Use this broker instead of starting one.
    spacing : float
        Longest edge of the paths sent, metres.
    state_rate : float
        Each vehicle's state messages per second of the run, besides those on events.
    period : float
        The vehicles' control cycle, seconds of the run.
    log : RunLog, optional
        The master's run log (default: a new one).

    Examples
    --------
    Use it as a context manager; :meth:`run` drives the vehicles, ``at`` lists what to do when.

    >>> # with LiveDemo(scenario, time_scale=10) as demo:
    >>> #     outcome = demo.run(at=[(12.0, lambda demo: demo.broker.restart())])
    """

    def __init__(
        self,
        scenario,
        verified: VerifiedSchedule | None = None,
        *,
        method=None,
        time_scale: float = 1.0,
        faults: Sequence[Sequence[StopFault]] = ((), ()),
        broker_url: str | None = None,
        spacing: float = RELEASE_SPACING,
        state_rate: float = 1.0,
        period: float = 0.02,
        log: RunLog | None = None,
    ) -> None:
        self.scenario = scenario
        self.state_rate = state_rate
        self.period = period
        self.log = log if log is not None else RunLog()
        #: the closest approach of the vehicles' true positions, taken as they drive
        self.approach = ClosestApproach(scenario.track)
        self.verified = verified if verified is not None else live_plan(scenario, method=method)
        self.method = method
        self.clock = RunClock(time_scale)
        self.faults = faults
        self.broker_url = broker_url
        self.spacing = spacing
        self.broker = None
        self.vehicles: tuple[SimulatedVehicle, ...] = ()
        self.master: LiveMaster | None = None

    def __enter__(self) -> LiveDemo:
        from trajgen.live.broker import EmbeddedBroker, MosquittoBroker, mosquitto_available

        scenario = self.scenario
        if self.broker_url is None:
            self.broker = (MosquittoBroker() if mosquitto_available() else EmbeddedBroker()).start()
        url = self.broker_url if self.broker_url is not None else self.broker.url
        settings = BrokerSettings.from_url(url)
        ids = identities(scenario.names)
        starts = [start_place(scenario.track, position) for position in scenario_starts(scenario)]
        self.vehicles = tuple(
            SimulatedVehicle(
                ids[v],
                scenario.limits.vehicles[v],
                starts[v][0],
                start_node=starts[v][1],
                broker=settings,
                clock=self.clock,
                faults=self.faults[v],
                state_rate=self.state_rate,
                period=self.period,
                observer=self.approach.observer(v),
            )
            for v in (0, 1)
        )
        self.master = LiveMaster(
            scenario,
            identities=ids,
            broker=settings,
            method=self.method,
            plan=self.verified,
            clock=self.clock,
            log=self.log,
            spacing=self.spacing,
        )
        for vehicle in self.vehicles:
            vehicle.start()
        return self

    def run(self, *, timeout: float | None = None, at: Sequence = ()) -> DemoRun:
        """Drive both vehicles to their goals; ``at``: ``(seconds after the start, action(demo))`` pairs.

        ``timeout``: seconds of the run (default: four times the plan plus a minute).
        """
        limit = timeout if timeout is not None else 4.0 * self.verified.schedule.duration + 60.0
        master = self.master
        began = self.clock.now()
        master.start()
        try:
            for moment, action in sorted(at, key=lambda pair: pair[0]):
                if master.wait(timeout=began + moment - self.clock.now()):
                    break
                action(self)
            master.wait(timeout=began + limit - self.clock.now())
        finally:
            master.stop()
        run = master.result()
        for vehicle in self.vehicles:
            vehicle.stop()
        return DemoRun(run, master.log, self.approach.closest, self.vehicles)

    def __exit__(self, *exc) -> None:
        for vehicle in self.vehicles:
            vehicle.stop()
        if self.broker is not None:
            self.broker.stop()


def run_demo(
    scenario,
    *,
    method=None,
    time_scale: float = 1.0,
    faults: Sequence[Sequence[StopFault]] = ((), ()),
    timeout: float | None = None,
    broker_url: str | None = None,
) -> DemoRun:
    """Run ``scenario`` live in this process: a broker, two simulated vehicles and the master.

    See :class:`LiveDemo` for the parameters; ``timeout`` in seconds of the run.
    """
    demo = LiveDemo(scenario, method=method, time_scale=time_scale, faults=faults, broker_url=broker_url)
    with demo:
        return demo.run(timeout=timeout)


class ClosestApproach:
    """The smallest track distance between two simulated vehicles, taken cycle by cycle as they drive.

    Each vehicle hands in its snapshot of every control cycle (``SimulatedVehicle(observer=...)``);
    snapshots of the same moment are compared, and only those still waiting for the other
    vehicle's are kept (at most :attr:`MAX_WAITING` per vehicle): memory does not grow with the run.

    Parameters
    ----------
    graph : StarGraph or TrackGraph
    """

    #: Snapshots kept per vehicle while the other has not reached their moment.
    MAX_WAITING = 1000

    def __init__(self, graph: StarGraph | TrackGraph) -> None:
        self.graph = graph
        self.closest = math.inf
        self.compared = 0
        self._waiting: tuple[dict, dict] = ({}, {})
        self._lock = threading.Lock()

    @property
    def waiting(self) -> int:
        """Snapshots kept, waiting for the other vehicle's of the same moment."""
        with self._lock:
            return len(self._waiting[0]) + len(self._waiting[1])

    def _place(self, snapshot: VehicleSnapshot):
        """Where a snapshot puts its vehicle on the track: by its x/y on a junction, its nodes on a graph."""
        if isinstance(self.graph, TrackGraph):
            return snapshot_point(self.graph, snapshot.node, snapshot.next_node, snapshot.along)
        return track_position(self.graph, snapshot.x, snapshot.y)

    def observer(self, vehicle: int) -> Callable[[VehicleSnapshot], None]:
        """What vehicle ``vehicle`` (0 or 1) calls with each cycle's snapshot."""
        return lambda snapshot: self._add(vehicle, snapshot)

    def _add(self, vehicle: int, snapshot: VehicleSnapshot) -> None:
        moment = round(snapshot.time, 9)
        with self._lock:
            other = self._waiting[1 - vehicle].pop(moment, None)
            if other is None:
                mine = self._waiting[vehicle]
                mine[moment] = snapshot
                if len(mine) > self.MAX_WAITING:
                    del mine[next(iter(mine))]
                return
            for old in [m for m in self._waiting[1 - vehicle] if m < moment]:
                del self._waiting[1 - vehicle][old]  # never matched now: the vehicles step together
            distance = self.graph.distance(self._place(snapshot), self._place(other))
            self.closest = min(self.closest, distance)
            self.compared += 1
