"""How the master sends orders when vehicles refuse them or are known from earlier runs (issue 35).

Items 3 and 10: an order a vehicle refuses (an ``orderError`` in its state) is reported at once,
naming the vehicle and the reason; re-sends back off and each carries a new ``headerId``; a
retained ``ONLINE`` of an earlier run sends no second order.
"""

from __future__ import annotations

import json
import logging
import time

from tests.helpers import execution_plan
from tests.test_live import FakeVehicles, _broker, _master_and_fakes, _until
from trajgen.live.master import LiveMaster
from trajgen.live.mqtt import BrokerSettings, Topic, make_client
from trajgen.live.session import identities

REFUSAL = "first node 'A:0.228571' is not trivially reachable"


def _orders_of(fake: FakeVehicles, serial: str) -> list[dict]:
    return [order for order in fake.orders if order["serialNumber"] == serial]


def test_a_refused_order_is_reported_at_once_and_its_resends_back_off_with_new_header_ids(caplog):
    caplog.set_level(logging.WARNING, logger="trajgen.live.master")
    scenario, verified = execution_plan("swap", "exact")
    name = scenario.names[0]
    with _master_and_fakes(scenario, verified) as (master, fake):
        assert _until(lambda: len(_orders_of(fake, name)) >= 1, 5.0)
        first = _orders_of(fake, name)[0]
        error = {"errorType": "orderError", "errorLevel": "WARNING", "errorDescription": REFUSAL}

        def refusing() -> bytes:  # the vehicle holds no order and says why
            return fake.state(0, first, 0, orderId="", orderUpdateId=0, lastNodeId="", errors=[error])

        began = time.monotonic()
        fake.publish(0, refusing())
        assert _until(lambda: any(r["event"] == "vehicle-error" for r in master.log.records()), 5.0)
        assert time.monotonic() - began < 5.0  # the issue: within 5 s
        for _ in range(30):  # the refusal stands for 3 s, a state every 0.1 s
            fake.publish(0, refusing())
            time.sleep(0.1)
        time.sleep(0.2)
        sent = _orders_of(fake, name)
    records = [r for r in master.log.records() if r["event"] == "vehicle-error"]
    assert len(records) == 1
    assert records[0]["vehicle"] == name
    assert records[0]["type"] == "orderError"
    assert records[0]["description"] == REFUSAL
    warnings = [r.getMessage() for r in caplog.records if REFUSAL in r.getMessage()]
    assert warnings == [f"master: {name} reports orderError: {REFUSAL}"]
    # 0.25, 0.5, 1, 2 s apart (not 12 re-sends at 0.25 s): the first order and at most 5 more
    assert 2 <= len(sent) <= 6, len(sent)
    headers = [order["headerId"] for order in sent]
    assert headers == sorted(set(headers)), headers  # one headerId per message, increasing


def test_a_retained_online_of_an_earlier_run_sends_no_second_order():
    scenario, verified = execution_plan("swap", "exact")
    ids = identities(scenario.names)
    with _broker() as broker:
        settings = BrokerSettings.from_url(broker.url)
        earlier = make_client(settings, "an-earlier-vehicle")
        earlier.connect(settings.host, settings.port)
        earlier.loop_start()
        for identity in ids:
            online = {
                "headerId": 7,
                "timestamp": "2026-11-26T10:00:00.000Z",
                "version": "2.1.0",
                "manufacturer": identity.manufacturer,
                "serialNumber": identity.serial_number,
                "connectionState": "ONLINE",
            }
            topic = identity.topic(Topic.CONNECTION)
            earlier.publish(topic, json.dumps(online).encode(), qos=1, retain=True).wait_for_publish(2.0)
        earlier.disconnect()
        earlier.loop_stop()
        fake = FakeVehicles(broker.url, ids)
        master = LiveMaster(verified, scenario.names, identities=ids, broker=settings).start()
        try:
            assert _until(lambda: len(fake.orders) >= 2, 5.0)
            time.sleep(1.0)  # time for a redundant order, if one were sent
        finally:
            master.stop()
            fake.close()
    assert sorted(order["serialNumber"] for order in fake.orders) == sorted(scenario.names)
