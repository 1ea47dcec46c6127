"""Live: drive two vehicles over VDA 5050 on an MQTT broker, releasing base by the frontier.

:class:`LiveMaster` sends each vehicle its order and releases more base as the
vehicles report their progress (:mod:`trajgen.live.master`);
:class:`SimulatedVehicle` is a VDA 5050 vehicle that drives its base with
Ruckig; :class:`LiveDemo` runs both with a broker (:class:`EmbeddedBroker`,
amqtt) in one process. The argument is in docs/live.md. Each name is imported
from its module when first used: paho-mqtt, amqtt and the VDA 5050 models load
only with a live run.
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.live.broker import EmbeddedBroker
    from trajgen.live.clock import RunClock
    from trajgen.live.faults import StopFault
    from trajgen.live.link import BrokerLink, LinkState
    from trajgen.live.master import LiveMaster
    from trajgen.live.mosquitto import MosquittoBroker, mosquitto_available
    from trajgen.live.mqtt import BrokerSettings, VehicleIdentity
    from trajgen.live.outcome import LiveOutcome, LiveRun
    from trajgen.live.runlog import RunLog, read_run_log
    from trajgen.live.session import DemoRun, LiveDemo, identities, live_plan, run_demo
    from trajgen.live.vehicle import SimulatedVehicle, VehicleSnapshot

__all__ = [
    "BrokerLink",
    "BrokerSettings",
    "DemoRun",
    "EmbeddedBroker",
    "LinkState",
    "LiveDemo",
    "LiveMaster",
    "LiveOutcome",
    "LiveRun",
    "MosquittoBroker",
    "RunClock",
    "RunLog",
    "SimulatedVehicle",
    "StopFault",
    "VehicleIdentity",
    "VehicleSnapshot",
    "identities",
    "live_plan",
    "mosquitto_available",
    "read_run_log",
    "run_demo",
]

_SOURCES = {
    "BrokerLink": "trajgen.live.link",
    "BrokerSettings": "trajgen.live.mqtt",
    "DemoRun": "trajgen.live.session",
    "EmbeddedBroker": "trajgen.live.broker",
    "LiveDemo": "trajgen.live.session",
    "LinkState": "trajgen.live.link",
    "LiveMaster": "trajgen.live.master",
    "LiveOutcome": "trajgen.live.outcome",
    "LiveRun": "trajgen.live.outcome",
    "MosquittoBroker": "trajgen.live.mosquitto",
    "RunClock": "trajgen.live.clock",
    "RunLog": "trajgen.live.runlog",
    "SimulatedVehicle": "trajgen.live.vehicle",
    "StopFault": "trajgen.live.faults",
    "VehicleIdentity": "trajgen.live.mqtt",
    "VehicleSnapshot": "trajgen.live.vehicle",
    "identities": "trajgen.live.session",
    "live_plan": "trajgen.live.session",
    "mosquitto_available": "trajgen.live.mosquitto",
    "read_run_log": "trajgen.live.runlog",
    "run_demo": "trajgen.live.session",
}

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
