"""Vehicle faults count from the vehicle's first order, as the run's time does (issue 35, item 9).

A vehicle started well before the master still stops at the same point of the run, and a fault
whose time never came is said when the vehicle stops, not silently dropped.
"""

from __future__ import annotations

import json
import logging
import time
from datetime import datetime

import pytest

from tests.support.helpers import execution_plan
from tests.support.live import Tap
from trajgen.live.faults import StopFault
from trajgen.live.outcome import LiveOutcome
from trajgen.live.session import LiveDemo

pytestmark = pytest.mark.slow

SCALE = 25.0


def test_a_fault_counts_from_the_first_order_even_when_the_vehicle_started_long_before(caplog):
    caplog.set_level(logging.WARNING, logger="trajgen.live.vehicle")
    scenario, verified = execution_plan("swap", "exact")
    fault = StopFault(5.0, 6.0)  # before: 5 s after the vehicle started, long before any order
    demo = LiveDemo(
        scenario, verified, method="exact", time_scale=SCALE, faults=((fault,), ()), state_rate=4.0
    )
    demo.__enter__()
    tap = Tap(demo.broker.url)  # agv1's states as the master sees them: "paused" while held
    try:
        time.sleep(20.0 / SCALE)  # 20 s of the run pass before the master starts
        outcome = demo.run()
    finally:
        tap.close()
        demo.__exit__()
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    # each state's timestamp is the run's start plus its seconds of the run (RunClock.timestamp)
    states = [json.loads(p) for _, topic, p in tap.messages if topic.endswith("/agv1/state")]
    seconds = [
        datetime.fromisoformat(state["timestamp"].replace("Z", "+00:00")).timestamp() for state in states
    ]
    ordered = next(t for t, state in zip(seconds, states, strict=True) if state["orderId"])
    paused = [t for t, state in zip(seconds, states, strict=True) if state["paused"]]
    assert paused, "the fault never held the vehicle"
    assert min(paused) > ordered  # nothing held before its first order (it was, before the fix)
    # held from 5 s of the run after its first order, for 6 s (states at 4 Hz of the run)
    assert fault.at - 0.3 <= min(paused) - ordered <= fault.at + 0.6
    assert fault.duration - 0.6 <= max(paused) - min(paused) <= fault.duration + 0.3
    assert not [r for r in caplog.records if "never applied" in r.getMessage()]


def test_a_fault_that_never_applied_is_said(caplog):
    caplog.set_level(logging.WARNING, logger="trajgen.live.vehicle")
    scenario, verified = execution_plan("swap", "exact")
    late = StopFault(1000.0, 1.0)  # after the run's end
    demo = LiveDemo(
        scenario, verified, method="exact", time_scale=SCALE, faults=((late,), ()), state_rate=2.0
    )
    with demo:
        outcome = demo.run()
    assert outcome.run.outcome is LiveOutcome.GOALS_REACHED
    said = [r.getMessage() for r in caplog.records if "never applied" in r.getMessage()]
    assert len(said) == 1
    assert said[0].startswith("vehicle agv1: fault stop@1000+1 never applied (it ended ")
