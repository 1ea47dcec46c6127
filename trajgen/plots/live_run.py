"""A live run as a picture: each vehicle's progress along its path under its released base, and the events."""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence

import numpy as np

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.plots.figure import drawing_area, finished, time_label
from trajgen.plots.speed import VEHICLE_COLOURS

__all__ = ["plot_live_run"]

logger = logging.getLogger(__name__)

#: The kinds of events a run carries (those of ``read_run_log``).
EVENT_KINDS = ("connection", "ignored", "goal", "replan")
#: Connection states that begin a connection loss; ``ONLINE`` ends it.
LOST_STATES = frozenset({"CONNECTIONBROKEN", "OFFLINE"})
#: Colours of the event marks.
OFFLINE_COLOUR = "tab:gray"
IGNORED_COLOUR = "tab:red"
LINE_COLOURS = {"goal": "tab:green", "replan": "tab:purple"}
#: Most goal / re-plan lines labelled with text per axis (the lines are all drawn).
MAX_EVENT_LABELS = 40
#: Characters of an event's detail shown in its label.
MAX_DETAIL_CHARS = 24
_WHAT = "live run picture"


def _check_names(names) -> tuple[str, str]:
    if (
        not isinstance(names, (tuple, list))
        or len(names) != 2
        or not all(isinstance(name, str) and name for name in names)
        or names[0] == names[1]
    ):
        raise InputError(
            f"{_WHAT}: names must be two different non-empty vehicle names (str), got {short_repr(names)}"
        )
    return names[0], names[1]


def _number_rows(rows, *, columns: int, what: str) -> np.ndarray:
    """``rows`` (a sequence of tuples of ``columns`` numbers) as a float array of shape (n, columns)."""
    if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence):
        raise InputError(f"{_WHAT}: {what} must be a list of tuples, got {short_repr(rows)}")
    if not rows:
        return np.empty((0, columns))
    try:
        array = np.array(rows)
    except (TypeError, ValueError):
        array = None
    if array is None or array.dtype.kind not in "biuf" or array.shape != (len(rows), columns):
        raise InputError(
            f"{_WHAT}: {what} must be tuples of {columns} numbers, got rows like {short_repr(rows[0])}"
        )
    array = array.astype(float)
    if not np.isfinite(array).all():
        row = int(np.nonzero(~np.isfinite(array).all(axis=1))[0][0])
        raise InputError(f"{_WHAT}: {what} has a non-finite number: {short_repr(rows[row])}")
    return array


def _in_time_order(array: np.ndarray) -> np.ndarray:
    if array.shape[0] > 1 and (np.diff(array[:, 0]) < 0).any():
        return array[np.argsort(array[:, 0], kind="stable")]
    return array


def _check_run(run, names: tuple[str, str]):
    """The run's states and orders per vehicle (float arrays in time order), its events and its end."""
    if not isinstance(run, Mapping):
        raise InputError(f"{_WHAT}: the run must be the dict of read_run_log, got {type(run).__name__}")
    missing = [key for key in ("states", "orders", "events", "end") if key not in run]
    if missing:
        raise InputError(f"{_WHAT}: the run has no {', '.join(missing)}; expected the dict of read_run_log")
    states, orders = run["states"], run["orders"]
    for key, table in (("states", states), ("orders", orders)):
        if not isinstance(table, Mapping):
            raise InputError(
                f"{_WHAT}: the run's {key} must map vehicle names to lists, got {short_repr(table)}"
            )
        strangers = sorted(str(name) for name in table if name not in names)
        if strangers:
            raise InputError(
                f"{_WHAT}: the log has {key} of {', '.join(strangers)}, not one of the vehicles {names}"
            )
    progress, frontiers = [], []
    for name in names:
        rows = _number_rows(states.get(name, []), columns=3, what=f"the states of {name}")
        if rows.shape[0] == 0:
            raise InputError(f"{_WHAT}: the log has no state of {name}: expected at least one")
        progress.append(_in_time_order(rows))
        frontiers.append(
            _in_time_order(_number_rows(orders.get(name, []), columns=2, what=f"the orders of {name}"))
        )
    events = _check_events(run["events"])
    end = run["end"]
    outcome, makespan, end_t = None, None, None
    if end is not None:
        if not isinstance(end, Mapping):
            raise InputError(f"{_WHAT}: the end record must be a dict or None, got {short_repr(end)}")
        outcome = end.get("outcome")
        makespan = end.get("makespan_s")
        end_t = end.get("t")
        for key, value in (("makespan_s", makespan), ("t", end_t)):
            if value is not None and (
                isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
            ):
                raise InputError(
                    f"{_WHAT}: the end record's {key} must be a finite number, got {short_repr(value)}"
                )
    return progress, frontiers, events, end is not None, (outcome, makespan, end_t)


def _check_events(events) -> list[tuple[float, str, str | None, str]]:
    if isinstance(events, (str, bytes)) or not isinstance(events, Sequence):
        raise InputError(f"{_WHAT}: the run's events must be a list of tuples, got {short_repr(events)}")
    checked = []
    for event in events:
        if not isinstance(event, (tuple, list)) or len(event) != 4:
            raise InputError(
                f"{_WHAT}: an event must be (t, kind, vehicle or None, detail), got {short_repr(event)}"
            )
        t, kind, vehicle, detail = event
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
            raise InputError(f"{_WHAT}: an event's time must be a finite number, got {short_repr(event)}")
        if kind not in EVENT_KINDS:
            raise InputError(
                f"{_WHAT}: an event's kind must be one of {', '.join(EVENT_KINDS)}, got {short_repr(event)}"
            )
        if vehicle is not None and not isinstance(vehicle, str):
            raise InputError(f"{_WHAT}: an event's vehicle must be a name or None, got {short_repr(event)}")
        checked.append((float(t), kind, vehicle, "" if detail is None else str(detail)))
    checked.sort(key=lambda event: event[0])  # stable: events at one time keep their order
    return checked


def _offline_spans(events, name: str, last_t: float) -> list[tuple[float, float]]:
    """From each connection loss of ``name`` (CONNECTIONBROKEN or OFFLINE) to its next ONLINE (or the end)."""
    spans, lost = [], None
    for t, kind, vehicle, detail in events:
        if kind != "connection" or vehicle != name:
            continue
        if detail in LOST_STATES and lost is None:
            lost = t
        elif detail == "ONLINE" and lost is not None:
            spans.append((lost, t))
            lost = None
    if lost is not None:
        spans.append((lost, last_t))
    return spans


def _mark_events(axis, events, name: str, names: tuple[str, str], last_t: float) -> None:
    """The events of ``name`` (and those of no vehicle of the run) on its axis."""
    mine = [event for event in events if event[2] == name or event[2] not in names]
    for number, (start, stop) in enumerate(_offline_spans(mine, name, last_t)):
        axis.axvspan(
            start,
            stop,
            color=OFFLINE_COLOUR,
            alpha=0.25,
            linewidth=0,
            label="offline" if number == 0 else None,
        )
    ignored = [t for t, kind, _, _ in mine if kind == "ignored"]
    if ignored:
        axis.plot(
            ignored,
            [0.97] * len(ignored),
            linestyle="none",
            marker="x",
            markersize=5,
            color=IGNORED_COLOUR,
            transform=axis.get_xaxis_transform(),
            label="message ignored",
        )
    labelled = 0
    for kind, colour in LINE_COLOURS.items():
        marks = [(t, detail) for t, what, _, detail in mine if what == kind]
        if not marks:
            continue
        axis.vlines(
            [t for t, _ in marks],
            0.0,
            0.93,
            transform=axis.get_xaxis_transform(),
            colors=colour,
            linestyles="-.",
            linewidth=1.1,
            label=kind,
        )
        for t, detail in marks:
            if labelled >= MAX_EVENT_LABELS:
                break
            labelled += 1
            text = f"{kind} {detail}".strip()
            if len(text) > MAX_DETAIL_CHARS:
                text = text[: MAX_DETAIL_CHARS - 1] + "…"
            time_label(axis, t, 0.91, text, colour=colour)
    if labelled < sum(kind in LINE_COLOURS for _, kind, _, _ in mine):
        logger.debug("%s: %s: only the first %d goal/replan lines labelled", _WHAT, name, MAX_EVENT_LABELS)


def _progress(axis, states: np.ndarray, orders: np.ndarray, colour: str, last_t: float) -> None:
    """Progress along the path (solid) and the released base's frontier (dashed steps), the gap shaded."""
    t, along = states[:, 0], states[:, 1]
    axis.plot(t, along, color=colour, linewidth=1.5, label="progress")
    if orders.shape[0] == 0:
        return
    steps_t = np.append(orders[:, 0], max(last_t, orders[-1, 0]))
    steps_f = np.append(orders[:, 1], orders[-1, 1])
    axis.step(steps_t, steps_f, where="post", color=colour, linestyle="--", linewidth=1.2, label="frontier")
    # the frontier in force at each state's time: the last order published at or before it
    index = np.searchsorted(orders[:, 0], t, side="right") - 1
    released = index >= 0
    frontier = np.where(released, orders[np.maximum(index, 0), 1], np.nan)
    axis.fill_between(
        t,
        along,
        frontier,
        where=released,
        color=colour,
        alpha=0.12,
        linewidth=0,
        label="released, not yet driven",
    )


def plot_live_run(run: dict, *, names: tuple[str, str], figure=None):
    """A live run: each vehicle's progress along its path against time, and the events.

    Each vehicle's progress along its path against time with its released base (frontier) as a step
    line above it, and the run's events. One axis per vehicle (titled with its name, in its colour of
    :data:`~trajgen.plots.speed.VEHICLE_COLOURS`), sharing the time axis, seconds of the run. On each:
    the distance the vehicle has travelled along its path, metres (solid), and the frontier of its
    released base, metres (dashed steps: each order or order update moves it; the vehicle may not pass
    it), drawn to the last time of the run, with the gap between the two shaded. The events of that
    vehicle (and those of no vehicle of the run, on both): its connection losses as grey spans from
    ``CONNECTIONBROKEN`` or ``OFFLINE`` to its next ``ONLINE`` (or the end of the run), ignored
    messages as red crosses at the top, goals and re-plans as dash-dotted vertical lines with a short
    label. The title gives the outcome and the makespan, seconds, of the ``end`` record if there is one.

    Parameters
    ----------
    run : dict
        From :func:`trajgen.live.runlog.read_run_log`: ``states`` (per vehicle name, ``(t s,
        along_m m, driving)``), ``orders`` (per vehicle name, ``(t s, frontier_m m)``), ``events``
        (``(t s, kind, vehicle or None, detail)``, kind one of ``connection``, ``ignored``, ``goal``,
        ``replan``) and ``end`` (the end record, with ``outcome`` and ``makespan_s`` s, or ``None``).
    names : pair of str
        The two vehicles' names, as in the log: the first is drawn above in the first colour.
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the two axes (default: a new Figure of 11 x 7.5 inches).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        ``names`` is not two different strings; ``run`` is not such a dict, has no state of a
        vehicle, states or orders of a vehicle not in ``names``, a malformed row or event, or a
        non-finite number.
    """
    names = _check_names(names)
    progress, frontiers, events, ended, (outcome, makespan, end_t) = _check_run(run, names)
    times = [rows[-1, 0] for rows in progress] + [rows[-1, 0] for rows in frontiers if rows.shape[0]]
    times += [event[0] for event in events[-1:]] + ([float(end_t)] if end_t is not None else [])
    last_t = max(times)
    first_t = min([rows[0, 0] for rows in progress] + [rows[0, 0] for rows in frontiers if rows.shape[0]])
    area = drawing_area(figure, figsize=(11, 7.5))
    axes = area.subplots(2, 1, sharex=True)
    for vehicle, (axis, name) in enumerate(zip(axes, names, strict=True)):
        colour = VEHICLE_COLOURS[vehicle]
        _progress(axis, progress[vehicle], frontiers[vehicle], colour, last_t)
        _mark_events(axis, events, name, names, last_t)
        axis.margins(y=0.1)  # room above the curves for the marks at the top
        axis.set_title(name, fontsize=11, fontweight="bold", color=colour, loc="left")
        axis.set_ylabel("along its path, m")
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    first_t = min(first_t, 0.0)  # the run's time starts at the first order
    if last_t > first_t:
        axes[0].set_xlim(first_t, last_t)
    axes[-1].set_xlabel("time of the run since the first order, s")
    if not ended:
        heading = "live run: no end record (still running, or cut short)"
    else:
        heading = f"live run: {outcome if outcome is not None else 'ended'}"
        if makespan is not None:
            heading += f", makespan {makespan:.2f} s"
    area.suptitle(
        f"{heading}\n(solid: progress along the path; dashed: the released base's frontier, "
        "not to be passed; grey: offline)",
        fontsize=10,
    )
    return finished(area, laid_out=figure is None)
