"""Figures of live runs over VDA 5050 on an MQTT broker: release latency, message rates, makespan.

Each run is a :class:`trajgen.live.session.LiveDemo`: the amqtt broker, two simulated vehicles and
the master in this process (the worst case for latency: one interpreter, one lock, for all of them),
or an external broker with ``--broker``. Printed per scenario and method, over ``--runs`` runs:

- release latency: wall time from the master taking the state that allows a release to the
  order update being handed to the MQTT client (median, 90th percentile, worst), milliseconds;
- messages per second (wall) through the broker: states, orders and updates, all; their sizes
  (median, largest) and the bytes per second of the run;
- makespan of the run against the plan's (``planned``: when its releases bring both vehicles home),
  seconds of the run, and the separation's closest approach on the vehicles' true positions.

Every built-in scenario (the swap, the crossing, the H), each with the default method of its track.

Run: ``python benchmarks/bench_live.py [--runs 3] [--time-scale 5] [--state-rate 1]
[--method NAME] [--broker mqtt://HOST:PORT]``.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import threading
import time

import numpy as np

from trajgen.live.mqtt import BrokerSettings, make_client
from trajgen.live.session import LiveDemo, live_plan
from trajgen.scenario import BuiltinScenario, builtin_scenario


class Counter:
    """Counts the messages on the broker by topic kind, as a third client receives them."""

    def __init__(self, url: str) -> None:
        self.counts = {"state": 0, "order": 0, "connection": 0}
        self.sizes: dict[str, list[int]] = {}
        self.first = self.last = None
        ready = threading.Event()
        settings = BrokerSettings.from_url(url)
        self.client = make_client(settings, f"bench-counter-{id(self):x}")
        self.client.on_connect = lambda client, *_: (client.subscribe("uagv/#"), ready.set())
        self.client.on_message = self._count
        self.client.connect(settings.host, settings.port)
        self.client.loop_start()
        ready.wait(5.0)

    def _count(self, client, userdata, message) -> None:
        kind = message.topic.rsplit("/", 1)[-1]
        self.counts[kind] = self.counts.get(kind, 0) + 1
        self.sizes.setdefault(kind, []).append(len(message.payload))
        now = time.monotonic()
        self.first = now if self.first is None else self.first
        self.last = now

    def close(self) -> None:
        """Disconnect."""
        self.client.disconnect()
        self.client.loop_stop()


def one_run(scenario, verified, args) -> dict:
    with LiveDemo(scenario, verified, time_scale=args.time_scale, broker_url=args.broker) as demo:
        for vehicle in demo.vehicles:
            vehicle.state_rate = args.state_rate
        counter = Counter(args.broker or demo.broker.url)
        try:
            outcome = demo.run()
        finally:
            counter.close()
    seconds = max(counter.last - counter.first, 1e-9)
    outcome.log.close()
    return {
        "latency_ms": outcome.run.release_latency * 1e3,
        "rates": {kind: count / seconds for kind, count in counter.counts.items()},
        "sizes": counter.sizes,
        "bytes_per_run_second": {
            kind: sum(sizes) / outcome.run.makespan for kind, sizes in counter.sizes.items()
        },
        "all": sum(counter.counts.values()) / seconds,
        "makespan": outcome.run.makespan,
        "planned": outcome.run.planned,
        "outcome": outcome.run.outcome.value,
        "closest": outcome.closest,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--time-scale", type=float, default=5.0)
    parser.add_argument("--state-rate", type=float, default=1.0)
    parser.add_argument("--method", default=None, help="timing method (default: the track's, method_for)")
    parser.add_argument("--broker", default=None, help="an external broker (default: amqtt in this process)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.ERROR)
    print(
        f"time scale {args.time_scale:g}, state rate {args.state_rate:g} Hz of the run, "
        f"broker {args.broker or 'amqtt in this process'}, {args.runs} runs each"
    )
    for chosen in BuiltinScenario:
        scenario = builtin_scenario(chosen)
        verified = live_plan(scenario, method=args.method)
        runs = [one_run(scenario, verified, args) for _ in range(args.runs)]
        latency = np.concatenate([r["latency_ms"] for r in runs])
        method = verified.schedule.method.name
        print(f"\n{chosen.value} ({method}): plan {runs[0]['planned']:.3f} s of the run")
        print(
            f"  release latency: {latency.size} releases, median {np.median(latency):.2f} ms, "
            f"90th percentile {np.percentile(latency, 90):.2f} ms, worst {latency.max():.2f} ms"
        )
        for kind in ("state", "order"):
            rate = statistics.median(r["rates"][kind] for r in runs)
            sizes = [size for r in runs for size in r["sizes"].get(kind, [])]
            load = statistics.median(r["bytes_per_run_second"].get(kind, 0.0) for r in runs) / 1e3
            print(
                f"  {kind} messages per second: {rate:.1f} (median); {statistics.median(sizes) / 1e3:.1f} KB "
                f"at the median, {max(sizes) / 1e3:.1f} KB at most; {load:.1f} KB per second of the run"
            )
        print(f"  all messages per second: {statistics.median(r['all'] for r in runs):.1f} (median)")
        for k, r in enumerate(runs, 1):
            print(
                f"  run {k}: {r['outcome']}, makespan {r['makespan']:.3f} s "
                f"(plan + {100 * (r['makespan'] / r['planned'] - 1):.1f} %), "
                f"closest approach {r['closest']:.6f} m"
            )


if __name__ == "__main__":
    main()
