"""The watched broker connection of the master and the vehicles (issue 35, items 2 and 5).

Closed-form expectations on real brokers: one line per change of the connection's state, never one
per retry; the first connection retried until the broker is there, whatever was started first.
"""

from __future__ import annotations

import itertools
import logging
import time

import pytest

from tests.support.helpers import execution_plan, scenario_vehicle
from trajgen.live.broker import EmbeddedBroker, MosquittoBroker, mosquitto_available
from trajgen.live.clock import RunClock
from trajgen.live.link import RETRY_MAX_S, BrokerLink, LinkState
from trajgen.live.master import LiveMaster
from trajgen.live.mqtt import BrokerSettings, make_client
from trajgen.live.outcome import LiveOutcome
from trajgen.live.session import ClosestApproach, LiveDemo, identities

pytestmark = pytest.mark.slow

#: The issue's longest gap between two starts, wall seconds.
GAP_S = 15.0
#: The gap between starts in the six orders: each waiting part has retried (0.5 s, then 1 s apart);
#: the issue's longest gap, 15 s (past the longest retry interval), is the test above.
LONG_GAP_S = 2.0


def _broker():
    """Mosquitto where it is installed, else amqtt in this process; not started."""
    return MosquittoBroker() if mosquitto_available() else EmbeddedBroker()


def _messages(caplog, text: str) -> list[str]:
    return [
        r.getMessage() for r in caplog.records if r.name == "trajgen.live.link" and text in r.getMessage()
    ]


def _until(condition, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def test_each_change_of_the_connection_is_said_once_and_retries_are_not(caplog):
    caplog.set_level(logging.INFO, logger="trajgen.live.link")
    broker = _broker()  # its port is chosen, nothing listens yet
    settings = BrokerSettings.from_url(broker.url)
    link = BrokerLink(make_client(settings, "trajgen-test-link"), settings, who="vehicle probe").start()
    try:
        assert _until(lambda: link.state is LinkState.UNREACHABLE, 5.0)
        time.sleep(3.0)  # several retries (0.5, 1, 2 s apart)
        assert len(_messages(caplog, "cannot reach")) == 1
        assert (
            f"cannot reach {broker.url}: connection refused; retrying" in _messages(caplog, "cannot reach")[0]
        )
        broker.start()
        assert _until(lambda: link.connected, RETRY_MAX_S + 2.0)

        said = f"vehicle probe: connected to {broker.url}"

        def said_connected() -> list:
            return [r for r in caplog.records if r.getMessage() == said]

        # the link says it just after its state changes, in its own thread
        assert _until(lambda: bool(said_connected()), 2.0)
        connected = said_connected()
        assert len(connected) == 1
        assert connected[0].levelno == logging.WARNING  # said loudly: it follows a problem
        broker.restart(down_for=1.0)
        assert _until(lambda: bool(_messages(caplog, "connected again")), 10.0)
        assert len(_messages(caplog, "lost the broker")) == 1
        assert len(_messages(caplog, "connected again")) == 1
        assert link.failure is None
    finally:
        link.close()
        broker.stop()
    assert link.state is LinkState.CLOSED


@pytest.mark.parametrize("method", ["exact"])
def test_vehicles_then_the_master_then_the_broker_with_long_gaps_complete_the_run(method, caplog):
    caplog.set_level(logging.WARNING, logger="trajgen.live.link")
    scenario, verified = execution_plan("swap", method)
    broker = _broker()
    scale = 25.0
    demo = LiveDemo(
        scenario, verified, method=method, time_scale=scale, broker_url=broker.url, state_rate=2.0
    )
    demo.__enter__()  # the vehicles start: no broker yet
    try:
        time.sleep(GAP_S)  # the vehicles keep trying, said once each
        assert len(_messages(caplog, "cannot reach")) == 2
        outcome = demo.run(
            at=[(5.0 * scale, lambda _demo: broker.start())]
        )  # the broker 5 s after the master
    finally:
        demo.__exit__()
        broker.stop()
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    assert outcome.run.error is None
    assert outcome.closest >= scenario.limits.min_separation
    assert len(_messages(caplog, "cannot reach")) == 3  # both vehicles and the master, once each


@pytest.mark.parametrize(
    "order", list(itertools.permutations(("broker", "master", "vehicles"))), ids="-".join
)
def test_any_start_order_of_broker_master_and_vehicles_completes_the_run(order):
    scenario, verified = execution_plan("swap", "exact")
    broker = _broker()
    settings = BrokerSettings.from_url(broker.url)
    clock = RunClock(25.0)
    ids = identities(scenario.names)
    approach = ClosestApproach(scenario.track)
    vehicles = [
        scenario_vehicle(
            scenario, v, ids[v], broker=settings, clock=clock, state_rate=2.0, observer=approach.observer(v)
        )
        for v in (0, 1)
    ]
    master = LiveMaster(scenario, plan=verified, identities=ids, broker=settings, clock=clock)
    start = {
        "broker": broker.start,
        "master": master.start,
        "vehicles": lambda: [vehicle.start() for vehicle in vehicles],
    }
    try:
        for number, part in enumerate(order):
            if number:
                time.sleep(LONG_GAP_S)
            start[part]()
        master.wait(timeout=4.0 * verified.schedule.duration + 60.0)
    finally:
        master.stop()
        for vehicle in vehicles:
            vehicle.stop()
        broker.stop()
    run = master.result()
    assert run.outcome is LiveOutcome.GOALS_REACHED, run
    assert approach.closest >= scenario.limits.min_separation
    # the run's time starts with the first orders, once all three are there: the waits (300 s of the
    # run) are reported apart, not in the makespan
    assert run.makespan <= run.planned * 1.05 + 1.0
    after_the_master = len(order) - 1 - order.index("master")
    waited = sum(run.waits.values())
    assert after_the_master * LONG_GAP_S * clock.time_scale * 0.9 <= waited
    assert waited <= (after_the_master * LONG_GAP_S + RETRY_MAX_S + 2.0) * clock.time_scale
