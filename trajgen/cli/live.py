"""``trajgen serve`` and ``trajgen vehicle``: drive vehicles over VDA 5050 on an MQTT broker.

``serve`` plans and verifies a scenario, then drives both vehicles, releasing
base by the frontier (:mod:`trajgen.live.master`); it commits its run log (and
picture) when the run ends. ``vehicle`` is a simulated VDA 5050 vehicle
(:mod:`trajgen.live.vehicle`). ``demo --live`` runs both, with a broker, in
one process (:func:`live_demo`).
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import re
import signal
import sys
import threading
import time
from pathlib import Path

from topology import Configuration, EdgePoint, Position, TrackGraph
from topology.validation import short_repr
from trajgen.cli.options import add_method, method_from, scenario_from
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


def _commit(log, log_path: str, plot_path: str | None, names) -> None:
    """The run log and the picture, committed together; a run too short to draw keeps its log.

    A picture that cannot be drawn (no vehicle ever reported a state: the broker or the vehicles
    were never reached) is skipped with a warning; the log is always written.
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
    commit_files(contents)


def _report(run, args: argparse.Namespace, *, planning: float, closest: float | None = None) -> int:
    from trajgen.model.summary import format_provenance

    summary = run.summary()
    summary["planning_s"] = planning
    if closest is not None:
        summary["closest_m"] = closest
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        latency = summary["release_latency_median_ms"]
        took = (
            f"in {summary['makespan_s']:.3f} s of the run"
            if summary["orders"]
            else "before any order was sent"
        )
        before = f"planning took {planning:.2f} s" + "".join(
            f", the {who} {summary[key]:.2f} s of the run"
            for who, key in (("broker", "broker_wait_s"), ("vehicles", "vehicle_wait_s"))
            if summary[key] is not None
        )
        print(
            f"live run: {summary['outcome']} {took} "
            f"(plan {summary['planned_s']:.3f} s, {format_provenance(summary)}; before the first order, "
            f"{before}); "
            f"{summary['orders']} orders and updates "
            f"({summary['resent']} sent again), {summary['ignored']} messages ignored, "
            f"{summary['replans']} re-plans"
            + (f"; release latency {latency:.2f} ms median" if latency is not None else "")
            + (f"; closest approach {closest_text(closest)}" if closest is not None else "")
        )
    if summary.get("error"):
        print(f"trajgen: error: {summary['error']}", file=sys.stderr)
        return EXIT_FAILURE
    if summary["outcome"] != "goals-reached":
        print("trajgen: the live run did not reach both goals in time", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _command_serve(args: argparse.Namespace) -> int:
    from trajgen.export.atomic import check_output_paths
    from trajgen.live.clock import RunClock
    from trajgen.live.master import LiveMaster
    from trajgen.live.session import live_plan

    require_live("paho", "trajgen serve")
    scenario = scenario_from(args.scenario)
    goals = sorted((_goal(text, scenario.track) for text in args.goal_at), key=lambda goal: goal[0])
    check_output_paths([args.log] + ([args.plot] if args.plot else []))
    settings = _settings(args)
    ids = _identities(args, scenario)
    began = time.perf_counter()
    verified = live_plan(scenario, method=method_from(args))
    planning = time.perf_counter() - began  # reported, never used to decide
    clock = RunClock(args.time_scale)  # the run's time (and --timeout) starts after planning
    master = LiveMaster(
        verified,
        scenario.names,
        identities=ids,
        broker=settings,
        method=method_from(args),
        clock=clock,
        order_id=args.order_id,
        map_id=args.map_id,
    )
    timeout = args.timeout if args.timeout is not None else 4.0 * verified.schedule.duration + 60.0
    try:
        master.start()
        for at, goal in goals:
            if master.wait(timeout=at - clock.now()):
                break  # both at their goals before it was due: it is never applied
            master.request_goal(goal)
        master.wait(timeout=timeout - clock.now())
    finally:
        master.stop()
    run = master.result()
    _commit(master.log, args.log, args.plot, scenario.names)
    master.log.close()
    return _report(run, args, planning=planning)


def _start(args: argparse.Namespace, scenario, v: int) -> Position | EdgePoint:
    """Where the vehicle stands when it starts: ``--start`` (a restart), else its scenario start."""
    track = scenario.track
    if isinstance(track, TrackGraph):
        return track.point(args.start.strip() if args.start is not None else scenario.start[v])
    if args.start is None:
        return (scenario.start.first, scenario.start.second)[v]
    return track.check(Position.parse(args.start))


def _command_vehicle(args: argparse.Namespace) -> int:
    from trajgen.errors import LiveError
    from trajgen.live.clock import RunClock
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
    clock = RunClock(args.time_scale)
    start, start_node = start_place(scenario.track, _start(args, scenario, v))
    vehicle = SimulatedVehicle(
        _identities(args, scenario)[v],
        scenario.limits.vehicles[v],
        start,
        start_node=start_node,
        broker=_settings(args),
        clock=clock,
        state_rate=args.state_rate,
        faults=faults,
        map_id=args.map_id,
    )
    stopped = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stopped.set())
    vehicle.start()
    timed_out = False
    try:
        while not stopped.wait(0.1):
            if args.exit_at_goal and vehicle.snapshot.finished:
                break
            if vehicle.link.failed.is_set():
                break
            if args.timeout is not None and clock.now() >= args.timeout:
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
    if timed_out and (args.exit_at_goal or not vehicle.link.ever_connected):
        why = "never reached the broker" if not vehicle.link.ever_connected else "not at its goal"
        print(f"trajgen: vehicle {args.name}: {why} within --timeout {args.timeout:g} s", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _show_progress(record: dict) -> None:
    """One line per release, connection change, ignored message and re-plan of a live run."""
    kind, t = record["event"], record["t"]
    if kind == "order" and not record["resent"]:
        what = "order" if record["update"] == 0 else f"update {record['update']}"
        line = f"{record['vehicle']}: {what}, base to {record['frontier_m']:.2f} m along its path"
    elif kind == "connection":
        line = f"{record['vehicle']} is {record['state']}"
    elif kind == "ignored":
        line = f"ignored a message on {record['topic']}: {record['reason']}"
    elif kind in ("goal", "replan"):
        line = f"{kind}: {record['goal']}"
    else:
        return
    print(f"{t:9.2f} s  {line}", flush=True)


def live_demo(
    scenario, *, method, time_scale: float, state_rate: float = 10.0, output: str, json_summary: bool = False
) -> int:
    """``trajgen demo --live``: a broker, two simulated vehicles and the master in this process."""
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
    began = time.perf_counter()
    demo = LiveDemo(
        scenario,
        method=method,
        time_scale=time_scale,
        state_rate=state_rate,
        log=RunLog(listener=None if json_summary else _show_progress),
    )
    planning = time.perf_counter() - began  # reported, never used to decide
    with demo:
        demo = demo.run()
    _commit(demo.log, log_path, plot_path, scenario.names)
    demo.log.close()
    status = _report(demo.run, argparse.Namespace(json=json_summary), planning=planning, closest=demo.closest)
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
    serve.add_argument("--order-id", default="trajgen", help="orderId: <prefix>-<vehicle name> (trajgen)")
    serve.add_argument("--map-id", default="trajgen", help="nodePosition.mapId (trajgen)")
    serve.add_argument(
        "--goal-at",
        action="append",
        default=[],
        metavar="T=LEG:S,LEG:S",
        help="at T s of the run, new goals for both vehicles (repeatable): both stop at\n"
        "their released base, then are re-planned from there (EDGE:S or a node on a track graph)",
    )
    serve.add_argument(
        "--timeout", type=float, help="seconds of the run, after planning, before giving up (4x plan + 60)"
    )
    serve.add_argument("--log", default="trajgen-live.jsonl", help="JSON-lines run log (trajgen-live.jsonl)")
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
        "--state-rate", type=float, default=10.0, metavar="HZ", help="states per second of the run (10)"
    )
    vehicle.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="stop@T+D",
        help="stop T s after its first order, for D s (repeatable)",
    )
    vehicle.add_argument(
        "--exit-at-goal", action="store_true", help="end once at the goal of an order (else: until Ctrl-C)"
    )
    vehicle.add_argument(
        "--start",
        metavar="LEG:S",
        help="where it stands at start (a restart mid-run; EDGE:S or a node on a track graph);\n"
        "default: its start in the scenario",
    )
    vehicle.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help="end after S s of the run (exit 1 if the broker was never reached or, with\n"
        "--exit-at-goal, the goal not reached)",
    )
    vehicle.set_defaults(run=_command_vehicle)
