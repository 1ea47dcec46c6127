"""The picture of a live run: progress under the released base per vehicle, the events, clear errors."""

from __future__ import annotations

import copy
import io
import math

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from PIL import Image

from trajgen.errors import InputError
from trajgen.live.runlog import RunLog, read_run_log
from trajgen.plots import plot_live_run, png_bytes
from trajgen.plots.live_run import OFFLINE_COLOUR
from trajgen.plots.speed import VEHICLE_COLOURS, vehicle_colour


def live_run_png(*arguments, **options) -> bytes:
    """The PNG the pipeline writes of ``plot_live_run(...)``."""
    return png_bytes(plot_live_run(*arguments, **options))


NAMES = ("agv1", "agv2")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def synthetic_run() -> dict:
    """Two vehicles, 300 states each, orders stepping the frontier, a connection loss, an end record."""
    t = np.linspace(0.0, 30.0, 300)
    states = {
        "agv1": [(float(x), float(min(0.5 * x, 12.0)), bool(x < 24.0)) for x in t],
        "agv2": [(float(x), float(0.3 * max(x - 4.0, 0.0)), bool(x > 4.0)) for x in t],
    }
    orders = {
        "agv1": [(0.0, 4.0), (6.0, 8.0), (14.0, 12.0)],
        "agv2": [(0.5, 2.0), (9.0, 5.0), (20.0, 7.8)],
    }
    events = [
        (3.0, "connection", "agv1", "ONLINE"),
        (10.0, "connection", "agv2", "CONNECTIONBROKEN"),
        (13.5, "connection", "agv2", "ONLINE"),
        (11.0, "ignored", "agv1", "stale header id"),
        (15.0, "ignored", None, "unknown vehicle agv9"),
        (18.0, "goal", "agv1", "node 7"),
        (22.0, "replan", None, ""),
    ]
    end = {"t": 30.5, "event": "end", "outcome": "reached", "makespan_s": 29.8}
    return {"states": states, "orders": orders, "events": events, "end": end}


def decoded(png: bytes) -> Image.Image:
    assert png.startswith(PNG_SIGNATURE)
    image = Image.open(io.BytesIO(png))
    assert image.format == "PNG"
    image.load()  # decodes the pixels: a truncated or corrupt file fails here
    return image


def test_the_live_run_plot_draws_a_png_of_a_sensible_size():
    image = decoded(live_run_png(synthetic_run(), names=NAMES))
    width, height = image.size
    assert 800 <= width <= 2500
    assert 500 <= height <= 2000
    pixels = np.asarray(image.convert("RGB"), dtype=float) / 255.0
    for colour in VEHICLE_COLOURS:  # each vehicle's curves are drawn in its colour
        near = np.abs(pixels - np.array(to_rgb(colour))).max(axis=2) < 0.04
        assert near.sum() > 500, colour


def test_the_live_run_plot_leaves_the_run_unchanged():
    run = synthetic_run()
    before = copy.deepcopy(run)
    live_run_png(run, names=NAMES)
    assert run == before


def test_the_time_axis_is_the_runs_from_the_first_order_to_the_end():
    run = synthetic_run()
    run["states"] = {
        name: [(t + 2.0, along, driving) for t, along, driving in run["states"][name]] for name in NAMES
    }
    run["orders"] = {name: [(t + 2.0, frontier) for t, frontier in run["orders"][name]] for name in NAMES}
    figure = plot_live_run(
        run, names=NAMES
    )  # nothing before 2 s of the run: the axis starts at 0 all the same
    axis = figure.axes[-1]
    assert axis.get_xlim() == (0.0, 32.0)
    assert axis.get_xlabel() == "time of the run since the first order, s"
    assert any("makespan 29.80 s" in text.get_text() for text in figure.texts)


def test_the_live_run_plot_takes_a_run_without_orders_events_or_end():
    run = synthetic_run()
    run.update(orders={}, events=[], end=None)
    decoded(live_run_png(run, names=NAMES))


def test_the_live_run_plot_takes_one_state_per_vehicle_and_states_out_of_order():
    run = synthetic_run()
    run["states"] = {"agv1": [(2.0, 1.0, True)], "agv2": [(5.0, 2.0, True), (1.0, 0.0, False)]}
    run["events"].append((40.0, "connection", "agv1", "OFFLINE"))  # never back online: up to the end
    decoded(live_run_png(run, names=NAMES))


def test_the_live_run_plot_draws_the_most_states_a_log_keeps():
    t = np.linspace(0.0, 600.0, 8000)
    run = synthetic_run()
    run["states"] = {name: [(float(x), float(0.01 * x), True) for x in t] for name in NAMES}
    decoded(live_run_png(run, names=NAMES))


def test_the_live_run_plot_of_a_run_log():
    log = RunLog()
    try:
        log.write({"t": 0.0, "event": "plan", "method": "exact", "planned_s": 20.0, "nodes": [5, 4]})
        for vehicle, name in enumerate(NAMES):
            log.write(
                {
                    "t": 0.1 * vehicle,
                    "event": "order",
                    "vehicle": name,
                    "update": 0,
                    "first": 0,
                    "decision_point": 2,
                    "frontier_m": 3.0,
                    "resent": False,
                }
            )
            log.write({"t": 0.0, "event": "connection", "vehicle": name, "state": "ONLINE"})
        for step in range(200):
            t = 0.1 * step
            for vehicle, name in enumerate(NAMES):
                along = min(0.2 * t, 3.0) if t < 8.0 else min(0.2 * t, 6.0)
                log.write(
                    {
                        "t": t,
                        "event": "state",
                        "vehicle": name,
                        "x": along,
                        "y": float(vehicle),
                        "node": int(along),
                        "along_m": along,
                        "driving": along < 6.0,
                    }
                )
            if step == 80:
                for name in NAMES:
                    log.write(
                        {
                            "t": t,
                            "event": "order",
                            "vehicle": name,
                            "update": 1,
                            "first": 2,
                            "decision_point": 4,
                            "frontier_m": 6.0,
                            "resent": False,
                        }
                    )
            if step == 50:
                log.write({"t": t, "event": "connection", "vehicle": "agv2", "state": "CONNECTIONBROKEN"})
            if step == 70:
                log.write({"t": t, "event": "connection", "vehicle": "agv2", "state": "ONLINE"})
            if step == 120:
                log.write(
                    {"t": t, "event": "ignored", "topic": "state", "vehicle": "agv1", "reason": "old header"}
                )
        log.write({"t": 20.0, "event": "end", "outcome": "reached", "makespan_s": 19.9})
        run = read_run_log(log.records())
    finally:
        log.close()
    assert len(run["states"]["agv1"]) == 200
    assert run["orders"]["agv2"] == [(0.1, 3.0), (8.0, 6.0)]
    assert (12.0, "ignored", "agv1", "old header") in [(round(e[0], 6), *e[1:]) for e in run["events"]]
    decoded(live_run_png(run, names=NAMES))


def _broken(change):
    run = synthetic_run()
    change(run)
    return run


BAD_NAMES = [
    pytest.param("agv1", id="a-string"),
    pytest.param((), id="no-name"),
    pytest.param(("agv1", 2), id="not-a-string"),
    pytest.param(("agv1", ""), id="empty-name"),
    pytest.param(("agv1", "agv1"), id="same-name-twice"),
]


@pytest.mark.parametrize("names", BAD_NAMES)
def test_bad_names_are_refused(names):
    with pytest.raises(InputError, match="names must be one or more different non-empty vehicle names"):
        live_run_png(synthetic_run(), names=names)


BAD_RUNS = [
    pytest.param(["not", "a", "dict"], "must be the dict of read_run_log, got list", id="not-a-dict"),
    pytest.param(
        _broken(lambda run: run.pop("orders")), r"the run has no orders; expected", id="no-orders-key"
    ),
    pytest.param(
        _broken(lambda run: run["states"].update(agv9=[(0.0, 0.0, True)])),
        "the log has states of agv9, not one of the vehicles",
        id="a-stranger-vehicle",
    ),
    pytest.param(
        _broken(lambda run: run["states"]["agv1"].append((31.0, math.nan, True))),
        "the states of agv1 has a non-finite number: \\(31.0, nan, True\\)",
        id="nan-along",
    ),
    pytest.param(
        _broken(lambda run: run["orders"]["agv2"].append((math.inf, 9.0))),
        "the orders of agv2 has a non-finite number",
        id="infinite-order-time",
    ),
    pytest.param(
        _broken(lambda run: run["states"]["agv1"].append((31.0, "far", True))),
        "the states of agv1 must be tuples of 3 numbers",
        id="text-for-a-number",
    ),
    pytest.param(
        _broken(lambda run: run["orders"]["agv1"].append((31.0,))),
        "the orders of agv1 must be tuples of 2 numbers",
        id="short-order",
    ),
    pytest.param(
        _broken(lambda run: run["events"].append((math.nan, "goal", "agv1", "x"))),
        "an event's time must be a finite number",
        id="nan-event-time",
    ),
    pytest.param(
        _broken(lambda run: run["events"].append((1.0, "teleport", "agv1", ""))),
        "an event's kind must be one of connection, ignored, goal, replan, restart, off-plan, stop",
        id="unknown-event-kind",
    ),
    pytest.param(
        _broken(lambda run: run["events"].append((1.0, "goal"))),
        r"an event must be \(t, kind, vehicle or None, detail\)",
        id="short-event",
    ),
    pytest.param(
        _broken(lambda run: run["end"].update(makespan_s=math.inf)),
        "the end record's makespan_s must be a finite number, got inf",
        id="infinite-makespan",
    ),
]


@pytest.mark.parametrize(("run", "message"), BAD_RUNS)
def test_bad_runs_are_refused_with_what_is_wrong(run, message):
    with pytest.raises(InputError, match=message):
        live_run_png(run, names=NAMES)


def test_the_input_error_is_a_value_error():
    with pytest.raises(ValueError, match="live run picture"):
        live_run_png({"states": {}, "orders": {}, "events": [(0.0, "?", None, "")], "end": None}, names=NAMES)


# -- issue 48, item 6: a picture for every run, and bands only where they are true ----------------------


def _offline_spans_drawn(axis) -> list[tuple[float, float]]:
    """The grey spans on ``axis``: (start, end) of each."""
    grey = np.array(to_rgb(OFFLINE_COLOUR))
    spans = []
    for patch in axis.patches:
        if np.allclose(patch.get_facecolor()[:3], grey):
            box = patch.get_bbox()  # a span is a rectangle in data x
            spans.append((float(box.x0), float(box.x1)))
    return spans


def _shaded(axis) -> list[tuple[float, float]]:
    """The x range of each shaded part (released, not yet driven) on ``axis``."""
    return [
        (float(path.vertices[:, 0].min()), float(path.vertices[:, 0].max()))
        for collection in axis.collections
        for path in collection.get_paths()
    ]


def test_a_run_where_no_vehicle_sent_a_state_is_drawn_saying_so():
    figure = plot_live_run({"states": {}, "orders": {}, "events": [], "end": None}, names=NAMES)
    texts = [text.get_text() for axis in figure.axes for text in axis.texts if "no state" in text.get_text()]
    assert texts == [f"no state of {name} in the log (it never took an order)" for name in NAMES]


def test_a_vehicle_without_a_state_has_its_axis_and_the_other_its_curves():
    run = synthetic_run()
    run["states"]["agv2"] = []
    run["orders"]["agv2"] = []
    figure = plot_live_run(run, names=NAMES)
    assert [axis.get_title(loc="left") for axis in figure.axes] == list(NAMES)
    said = [text.get_text() for text in figure.axes[1].texts if "no state" in text.get_text()]
    assert said == ["no state of agv2 in the log (it never took an order)"]
    assert figure.axes[0].lines  # agv1's progress and frontier


def test_three_vehicles_get_three_axes_in_three_colours():
    run = synthetic_run()
    run["states"]["agv3"] = run["states"]["agv2"]
    run["orders"]["agv3"] = run["orders"]["agv2"]
    figure = plot_live_run(run, names=("agv1", "agv2", "agv3"))
    assert [axis.get_title(loc="left") for axis in figure.axes] == ["agv1", "agv2", "agv3"]
    colours = [axis.lines[0].get_color() for axis in figure.axes]  # each one's progress
    assert colours == [vehicle_colour(k) for k in range(3)]
    assert len(set(colours)) == 3


def test_no_offline_band_after_a_vehicle_stood_at_its_goal_but_one_while_it_still_had_base():
    run = synthetic_run()
    # agv1 stands at its last frontier (12 m) from 24 s: going offline at 26 s is going home
    run["events"].append((26.0, "connection", "agv1", "OFFLINE"))
    assert _offline_spans_drawn(plot_live_run(run, names=NAMES).axes[0]) == []
    # agv2 still drives towards its frontier at 28 s: offline there is a loss, drawn to the end
    run["events"].append((28.0, "connection", "agv2", "CONNECTIONBROKEN"))
    spans = _offline_spans_drawn(plot_live_run(run, names=NAMES).axes[1])
    assert (28.0, 30.5) in [(round(a, 6), round(b, 6)) for a, b in spans]


def test_the_shading_and_the_frontier_break_at_a_restart_and_a_replan():
    run = synthetic_run()
    run["events"] += [(12.0, "restart", "agv1", "a:2"), (16.0, "replan", None, "(D, A)")]
    run["orders"]["agv1"] = [(0.0, 4.0), (6.0, 8.0), (16.5, 12.0)]
    axis = plot_live_run(run, names=NAMES).axes[0]
    for low, high in _shaded(axis):  # no shaded part spans a break
        assert not low < 12.0 < high, (low, high)
        assert not low < 16.0 < high, (low, high)
    frontier = [line for line in axis.lines if line.get_linestyle() == "--"]
    spans = [(min(line.get_xdata()), max(line.get_xdata())) for line in frontier]
    assert all(not (low < 12.0 < high) for low, high in spans)  # the base lost at the restart ends there
    assert (6.0, 12.0) in spans
