"""``trajgen serve`` and ``trajgen vehicle``: drive vehicles over VDA 5050 on an MQTT broker.

``serve`` connects and plans a scenario at once, then drives the vehicles,
releasing base by the frontier (:mod:`trajgen.live.master`), saying each event
on a line of its own (:mod:`trajgen.cli.timeline`); its run log is streamed to
``<log>.partial`` as the run goes and committed, with the picture, when the run
ends (also on SIGINT, SIGTERM and SIGHUP, which stop it in order). ``vehicle``
is a simulated VDA 5050 vehicle (:mod:`trajgen.live.vehicle`). ``demo --live``
runs both, with a broker, in one process (:func:`live_demo`).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import math
import re
import signal
import sys
import threading
from pathlib import Path
from typing import ClassVar

from topology import Configuration, EdgePoint, Position, TrackGraph
from topology.validation import short_repr
from trajgen.cli.options import add_method, scenario_from
from trajgen.cli.parser import EXIT_FAILURE, EXIT_OK
from trajgen.errors import InputError
from trajgen.live.mqtt import require_live
from trajgen.model.summary import closest_text

__all__ = ["live_demo", "register"]

logger = logging.getLogger(__name__)

_GOAL = re.compile(r"(?P<at>[^=]+)=(?P<first>[^,]+),(?P<second>.+)")


def _goal(text: str, track) -> tuple[float, Configuration | tuple[EdgePoint, EdgePoint]]:
    """``T=LEG:S,LEG:S`` (``T=EDGE:S,EDGE:S`` on a track graph): at T s of the run, both new goals."""
    match = _GOAL.fullmatch(text.strip())
    try:
        at = float(match["at"]) if match else float("nan")
    except ValueError:
        at = float("nan")
    if not match or not at >= 0.0 or at == float("inf"):
        form, example = (
            ("EDGE:S,EDGE:S", "20=C,b:2") if isinstance(track, TrackGraph) else ("LEG:S,LEG:S", "20=C:8,A:10")
        )
        raise InputError(
            f"--goal-at {short_repr(text)} cannot be read: expected T={form} (T seconds of the run "
            f">= 0, then both vehicles' new goals, e.g. {example})"
        )
    if isinstance(track, TrackGraph):  # checked here: a goal off the track is refused before connecting
        return at, (track.point(match["first"].strip()), track.point(match["second"].strip()))
    return at, Configuration(Position.parse(match["first"]), Position.parse(match["second"]))


def _add_broker_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--broker", required=True, metavar="URL", help="mqtt://HOST:PORT (mqtts:// for TLS)")
    parser.add_argument("--username", help="broker login")
    parser.add_argument("--password-file", metavar="FILE", help="file whose first line is the password")
    parser.add_argument("--tls", action="store_true", help="connect over TLS (as mqtts:// does)")
    parser.add_argument("--cafile", metavar="FILE", help="certificate authority file for TLS")
    parser.add_argument("--interface", default="uagv", help="VDA 5050 interface, first topic level (uagv)")
    parser.add_argument("--version", default="v2", help="VDA 5050 major version, second topic level (v2)")
    parser.add_argument("--manufacturer", default="unspecified", help="vehicles' manufacturer (unspecified)")
    parser.add_argument(
        "--time-scale",
        type=float,
        default=1.0,
        metavar="K",
        help="seconds of the run per wall-clock second (1); the same for the master and the vehicles",
    )


def _settings(args: argparse.Namespace):
    from trajgen.live.mqtt import BrokerSettings

    return BrokerSettings.from_url(
        args.broker,
        username=args.username,
        password_file=args.password_file,
        tls=args.tls,
        cafile=args.cafile,
    )


def _identities(args: argparse.Namespace, scenario):
    from trajgen.live.session import identities

    serials = None
    if args.serial_numbers is not None:
        serials = tuple(part.strip() for part in args.serial_numbers.split(","))
    return identities(
        scenario.names,
        manufacturer=args.manufacturer,
        serial_numbers=serials,
        interface=args.interface,
        version=args.version,
    )


def _commit(log, log_path: str, plot_path: str | None, names) -> bool:
    """The run log and the picture, committed together; whether they were (the log is then closed).

    A picture that cannot be drawn is skipped with a warning; the log is always written. A commit
    that fails keeps the log streamed as the run went (``<log>.partial``) and says where it is.
    """
    from trajgen.export.atomic import commit_files

    contents = {Path(log_path): log.chunks()}
    if plot_path is not None:
        from trajgen.live.runlog import read_run_log
        from trajgen.plots import plot_live_run, png_bytes

        try:
            figure = plot_live_run(read_run_log(log.records()), names=tuple(names))
            contents[Path(plot_path)] = png_bytes(figure)
        except InputError as error:
            logger.warning("the picture of the run %s is not drawn: %s", plot_path, error)
    try:
        commit_files(contents)
    except Exception:
        if log.partial is not None:
            logger.error("the run log could not be committed; it is kept as %s", log.partial)
        log.close(keep=True)
        raise
    log.close()
    return True


def _report(run, args: argparse.Namespace, *, closest_true: float | None = None) -> int:
    """Print the run's summary (``--json``: the JSON alone on stdout); the exit status of the run."""
    from trajgen.model.summary import format_provenance

    summary = run.summary()
    if closest_true is not None:
        summary["closest_true_m"] = closest_true
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        latency = summary["release_latency_median_ms"]
        took = (
            f"in {summary['makespan_s']:.3f} s of the run"
            if summary["orders"]
            else "before any order was sent"
        )
        before = f"planning took {summary['planning_s']:.2f} s" + "".join(
            f", the {who} {summary[key]:.2f} s of the run"
            for who, key in (("broker", "broker_wait_s"), ("vehicles", "vehicle_wait_s"))
            if summary[key] is not None
        )
        closest = summary["closest_m"]
        approach = "" if closest is None else f"; closest approach {closest_text(closest)} (reported places)"
        if closest_true is not None:
            approach += f", {closest_text(closest_true)} (true positions)"
        plan = (
            f"plan {summary['planned_s']:.3f} s, {format_provenance(summary)}"
            if "computed_by" in summary
            else "no plan made yet"
        )
        print(
            f"live run: {summary['outcome']} {took} ({plan}; before the first order, {before}); "
            f"{summary['orders']} orders and updates "
            f"({summary['resent']} sent again), {summary['ignored']} messages ignored, "
            f"{summary['replans']} re-plans"
            + (f"; release latency {latency:.2f} ms median" if latency is not None else "")
            + approach
        )
    if summary["outcome"] == "interrupted":  # asked for: said, not an error
        print(f"trajgen: {summary['error']}", file=sys.stderr)
        return EXIT_FAILURE
    if summary.get("error"):
        print(f"trajgen: error: {summary['error']}", file=sys.stderr)
        return EXIT_FAILURE
    if summary["outcome"] != "goals-reached":
        print("trajgen: the live run did not reach every goal in time", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


class _Signals:
    """SIGINT, SIGTERM and SIGHUP while a run goes: noted (the first one), never raised.

    The run then stops in order (its vehicles told, its log committed) and the command ends with
    ``128 + the signal's number`` (130, 143, 129), a status of its own. Outside the main thread
    (a host program running :func:`~trajgen.cli.main` in a thread) no handler is installed.
    """

    NAMES: ClassVar[dict[int, str]] = {
        signal.SIGINT: "SIGINT",
        signal.SIGTERM: "SIGTERM",
        signal.SIGHUP: "SIGHUP",
    }

    def __init__(self) -> None:
        self.received: int | None = None
        self._before: dict = {}

    def _take(self, signum, frame) -> None:
        if self.received is None:
            self.received = signum
        else:
            logger.warning("%s again: the run is already stopping", self.NAMES.get(signum, signum))

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for signum in self.NAMES:
                self._before[signum] = signal.signal(signum, self._take)
        return self

    def __exit__(self, *exc) -> None:
        for signum, handler in self._before.items():
            signal.signal(signum, handler)

    @property
    def name(self) -> str | None:
        """The signal received, by name; ``None``: none."""
        return None if self.received is None else self.NAMES.get(self.received, str(self.received))

    @property
    def status(self) -> int:
        """The exit status of a run stopped by the signal received."""
        return 128 + int(self.received)


#: Wall seconds a stopped run waits for its vehicles to show the ``cancelOrder`` it sent them.
TELL_WAIT_S = 3.0


def _drive(master, goals, *, timeout: float | None, signals: _Signals) -> None:
    """Run ``master`` until it is over, a signal comes or the time runs out; ask for ``goals`` when due.

    ``timeout``: seconds of the run's clock from the start; ``None``: 60 s plus four times the plan,
    from when the plan is made.
    """
    pending = list(goals)
    limit = timeout
    step = master.clock.time_scale * 0.05  # 50 ms of wall time, in seconds of the run
    while not master.over() and signals.received is None:
        if limit is None and master.planned_duration is not None:
            limit = master.elapsed + 4.0 * master.planned_duration + 60.0
        if limit is not None and master.elapsed >= limit:
            return
        run_time = master.run_time
        while pending and run_time is not None and run_time >= pending[0][0]:
            at, goal = pending.pop(0)
            try:
                master.request_goal(goal)
            except InputError as error:
                logger.warning("--goal-at %g: the goal is not taken: %s", at, error)
        master.wait(timeout=step)


def _command_serve(args: argparse.Namespace) -> int:
    from trajgen.cli.options import scenario_method
    from trajgen.cli.timeline import Timeline
    from trajgen.export.atomic import check_output_paths
    from trajgen.live.clock import RunClock
    from trajgen.live.master import LiveMaster
    from trajgen.live.runlog import RunLog

    require_live("paho", "trajgen serve")
    scenario = scenario_from(args.scenario)
    goals = sorted((_goal(text, scenario.track) for text in args.goal_at), key=lambda goal: goal[0])
    if args.timeout is not None and not args.timeout > 0.0:
        raise InputError(f"serve --timeout {args.timeout!r} is not positive: expected run seconds > 0")
    check_output_paths([args.log] + ([args.plot] if args.plot else []))
    settings = _settings(args)
    ids = _identities(args, scenario)
    method = scenario_method(args, scenario)
    clock = RunClock(args.time_scale)
    timeline = None if args.json else Timeline(clock)
    log = RunLog.streamed(args.log, listener=timeline)
    master = LiveMaster(
        scenario,
        identities=ids,
        broker=settings,
        method=method,
        clock=clock,
        order_id=args.order_id,
        map_id=args.map_id,
        log=log,
    )
    quiet = timeline.quiet_duplicates() if timeline is not None else contextlib.nullcontext()
    with _Signals() as signals, quiet:
        try:
            master.start()  # connects and plans at once
            _drive(master, goals, timeout=args.timeout, signals=signals)
            if signals.received is not None:
                master.interrupt(signals.name)
                master.wait_told(TELL_WAIT_S)
        finally:
            master.stop()
            run = master.result()  # the end record, whatever ended the run
    _commit(log, args.log, args.plot, scenario.names)
    status = _report(run, args)
    return signals.status if signals.received is not None else status


def _start(args: argparse.Namespace, scenario, v: int, identity) -> Position | EdgePoint:
    """Where the vehicle stands at start: ``--start`` (``last``: its memory), else its scenario start."""
    from trajgen.live.memory import memory_path, remembered_place

    track = scenario.track
    given = args.start.strip() if args.start is not None else None
    if given == "last":
        return remembered_place(track, memory_path(identity, _settings(args)))
    if isinstance(track, TrackGraph):
        return track.point(given if given is not None else scenario.start[v])
    if given is None:
        return (scenario.start.first, scenario.start.second)[v]
    return track.check(Position.parse(given))


def _command_vehicle(args: argparse.Namespace) -> int:
    from trajgen.errors import LiveError
    from trajgen.live.clock import RunClock
    from trajgen.live.memory import memory_path
    from trajgen.live.places import start_place
    from trajgen.live.vehicle import SimulatedVehicle, StopFault

    require_live("paho", "trajgen vehicle")
    scenario = scenario_from(args.scenario)
    if args.name not in scenario.names:
        raise InputError(
            f"vehicle {short_repr(args.name)} is not in the scenario: expected one of {list(scenario.names)}"
        )
    v = scenario.names.index(args.name)
    faults = [StopFault.parse(text) for text in args.fault]
    if args.timeout is not None and not args.timeout > 0.0:
        raise InputError(f"vehicle --timeout {args.timeout!r} is not positive: expected run seconds > 0")
    identity = _identities(args, scenario)[v]
    settings = _settings(args)
    clock = RunClock(args.time_scale)
    start, start_node = start_place(scenario.track, _start(args, scenario, v, identity))
    vehicle = SimulatedVehicle(
        identity,
        scenario.limits.vehicles[v],
        start,
        start_node=start_node,
        broker=settings,
        clock=clock,
        state_rate=args.state_rate,
        faults=faults,
        map_id=args.map_id,
        memory=memory_path(identity, settings),
    )
    stopped = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stopped.set())
    vehicle.start()
    timed_out = False
    over = None
    try:
        while not stopped.wait(0.1):
            if args.exit_at_goal and vehicle.snapshot.finished:
                break
            over = vehicle.over
            if args.exit_at_goal and over is not None:
                break
            if vehicle.link.failed.is_set():
                break
            since = vehicle.since_first_order  # the time out counts from its first order (or its start)
            if args.timeout is not None and (since if since is not None else clock.now()) >= args.timeout:
                timed_out = True
                break
    finally:
        vehicle.stop()
    if vehicle.link.failure is not None:
        raise LiveError(vehicle.link.failure)
    snapshot = vehicle.snapshot
    run_time = vehicle.since_first_order
    places = [f"x={snapshot.x:.3f} m, y={snapshot.y:.3f} m"] if not math.isnan(snapshot.x) else []
    if snapshot.node:  # where its orders give no x/y, its node says where it is
        places.append(f"{snapshot.along:.3f} m past node {snapshot.node}")
    where = ", ".join(places) or "an unknown place"
    print(
        f"vehicle {args.name}: stopped at {where} "
        + (f"{run_time:.3f} s after its first order" if run_time is not None else "without any order")
        + f" ({'at its goal' if snapshot.finished else 'not at a goal'})"
    )
    if args.exit_at_goal and over is not None and not snapshot.finished:
        print(f"trajgen: vehicle {args.name}: {over}, not at its goal", file=sys.stderr)
        return EXIT_FAILURE
    if timed_out and (args.exit_at_goal or not vehicle.link.ever_connected):
        why = "never reached the broker" if not vehicle.link.ever_connected else "not at its goal"
        print(f"trajgen: vehicle {args.name}: {why} within --timeout {args.timeout:g} s", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def live_demo(
    scenario, *, method, time_scale: float, state_rate: float = 1.0, output: str, json_summary: bool = False
) -> int:
    """``trajgen demo --live``: a broker, the simulated vehicles and the master in this process."""
    from trajgen.cli.timeline import Timeline
    from trajgen.export.atomic import check_output_paths
    from trajgen.live.runlog import RunLog
    from trajgen.live.session import LiveDemo

    require_live("paho", "trajgen demo --live")
    log_path, plot_path = str(Path(output) / "live-run.jsonl"), str(Path(output) / "live-run.png")
    check_output_paths([log_path, plot_path])
    if not json_summary:  # with --json, stdout is the summary alone
        print(
            f"Live demo: {scenario.source} over VDA 5050 on an MQTT broker in this process, "
            f"{time_scale:g}x real time ..."
        )
    log = RunLog.streamed(log_path)
    demo = LiveDemo(scenario, method=method, time_scale=time_scale, state_rate=state_rate, log=log)
    timeline = None if json_summary else Timeline(demo.clock)
    log.listener = timeline
    quiet = timeline.quiet_duplicates() if timeline is not None else contextlib.nullcontext()
    with quiet, demo:
        outcome = demo.run()
    _commit(outcome.log, log_path, plot_path, scenario.names)
    status = _report(outcome.run, argparse.Namespace(json=json_summary), closest_true=outcome.closest)
    if not json_summary:
        print(f"Run log and picture: {log_path}, {plot_path}")
    return status


def register(commands) -> None:
    """Add ``serve`` and ``vehicle`` to the sub-commands."""
    serve = commands.add_parser("serve", formatter_class=argparse.RawTextHelpFormatter)
    serve.add_argument("scenario", help="scenario TOML file")
    _add_broker_options(serve)
    serve.add_argument(
        "--serial-numbers", metavar="A,B", help="both vehicles' serial numbers (default: their names)"
    )
    add_method(serve, what="timing method of the plan", homotopy=False)
    serve.add_argument(
        "--order-id", default="trajgen", help="orderId: <prefix>-<vehicle name>-<run's UTC time> (trajgen)"
    )
    serve.add_argument("--map-id", default="trajgen", help="nodePosition.mapId (trajgen)")
    serve.add_argument(
        "--goal-at",
        action="append",
        default=[],
        metavar="T=LEG:S,LEG:S",
        help="at T s of the run (from its first orders), new goals for both vehicles (repeatable):\n"
        "both stop at their released base, then are re-planned from there (EDGE:S or a node on\n"
        "a track graph)",
    )
    serve.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help="seconds of the run from serve's start (planning included) before giving up;\n"
        "default: 60 s and four times the plan, from when the plan is made",
    )
    serve.add_argument(
        "--log",
        default="trajgen-live.jsonl",
        help="JSON-lines run log (trajgen-live.jsonl), written to FILE.partial as the run goes\n"
        "and committed with the picture when it ends",
    )
    serve.add_argument("--plot", metavar="FILE", help="PNG picture of the run: progress, releases, events")
    serve.add_argument("--json", action="store_true", help="print a machine-readable summary")
    serve.set_defaults(run=_command_serve)

    vehicle = commands.add_parser("vehicle", formatter_class=argparse.RawTextHelpFormatter)
    vehicle.add_argument("scenario", help="scenario TOML file (the vehicle's limits and start)")
    vehicle.add_argument("name", help="the vehicle's name in the scenario")
    _add_broker_options(vehicle)
    vehicle.add_argument("--serial-numbers", metavar="A,B", help="both vehicles' serial numbers (names)")
    vehicle.add_argument("--map-id", default="trajgen", help="agvPosition.mapId (trajgen)")
    vehicle.add_argument(
        "--state-rate",
        type=float,
        default=1.0,
        metavar="HZ",
        help="states per second of the run besides those on events (each node reached, ...) (1)",
    )
    vehicle.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="stop@T+D",
        help="stop T s after its first order, for D s (repeatable)",
    )
    vehicle.add_argument(
        "--exit-at-goal",
        action="store_true",
        help="end once at the goal of an order (exit 0), or once its run is over without it: its\n"
        "order cancelled by the master, or the master gone (exit 1); else: until Ctrl-C",
    )
    vehicle.add_argument(
        "--start",
        metavar="LEG:S",
        help="where it stands at start (a restart mid-run; EDGE:S or a node on a track graph);\n"
        "'last': where it last said it stood (kept by every vehicle process, see docs/live.md);\n"
        "default: its start in the scenario",
    )
    vehicle.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help="end S s of the run after its first order (before one: after its start); exit 1 if\n"
        "the broker was never reached or, with --exit-at-goal, the goal not reached",
    )
    vehicle.set_defaults(run=_command_vehicle)
