"""A live run as a picture: each vehicle's progress along its path under its released base, and the events."""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence

import numpy as np

from topology.validation import short_repr
from trajgen.errors import InputError
from trajgen.live.runlog import EVENT_KINDS
from trajgen.plots.figure import drawing_area, finished, time_label
from trajgen.plots.speed import vehicle_colour

__all__ = ["plot_live_run"]

logger = logging.getLogger(__name__)

#: Events after which a vehicle's released base is not the one before: the shading and the frontier
#: break there (a vehicle back without its order lost its base; a re-plan gives new bases).
BREAKS = frozenset({"replan", "restart", "goal", "stop"})
#: Connection states that begin a connection loss; ``ONLINE`` ends it.
LOST_STATES = frozenset({"CONNECTIONBROKEN", "OFFLINE"})
#: Colours of the event marks.
OFFLINE_COLOUR = "tab:gray"
IGNORED_COLOUR = "tab:red"
LINE_COLOURS = {"goal": "tab:green", "replan": "tab:purple", "restart": "tab:brown", "stop": "black"}
#: Marks at the top of an axis: messages ignored, states off the plan.
CROSS_COLOURS = {"ignored": ("tab:red", "message ignored"), "off-plan": ("tab:pink", "off its plan")}
#: Most goal / re-plan lines labelled with text per axis (the lines are all drawn).
MAX_EVENT_LABELS = 40
#: Characters of an event's detail shown in its label.
MAX_DETAIL_CHARS = 24
_WHAT = "live run picture"


def _check_names(names) -> tuple[str, ...]:
    if (
        not isinstance(names, (tuple, list))
        or not names
        or not all(isinstance(name, str) and name for name in names)
        or len(set(names)) != len(names)
    ):
        raise InputError(
            f"{_WHAT}: names must be one or more different non-empty vehicle names (str), "
            f"got {short_repr(names)}"
        )
    return tuple(names)


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


def _check_run(run, names: tuple[str, ...]):
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


def _offline_spans(events, name: str, last_t: float, *, done_at: float | None) -> list:
    """From each connection loss of ``name`` (CONNECTIONBROKEN or OFFLINE) to its next ONLINE (or the end).

    ``done_at``: when the vehicle stood at the end of its last base (its goal); a loss after it that
    lasts to the end is a vehicle gone home, not offline.
    """
    spans, lost = [], None
    for t, kind, vehicle, detail in events:
        if kind != "connection" or vehicle != name:
            continue
        if detail in LOST_STATES and lost is None:
            lost = t
        elif detail == "ONLINE" and lost is not None:
            spans.append((lost, t))
            lost = None
    if lost is not None and (done_at is None or lost < done_at):
        spans.append((lost, last_t))
    return spans


def _done_at(states: np.ndarray, orders: np.ndarray) -> float | None:
    """Since when the vehicle stands at the frontier of its last order (its goal); ``None``: it does not."""
    if states.shape[0] == 0 or orders.shape[0] == 0:
        return None
    there = (states[:, 2] == 0.0) & (np.abs(states[:, 1] - orders[-1, 1]) <= 1e-6)
    if not there[-1]:
        return None
    moved = np.nonzero(~there)[0]  # the last state away from it, or driving
    return float(states[moved[-1] + 1 if moved.size else 0, 0])


def _mark_events(axis, events, name: str, names: tuple[str, ...], last_t: float, done_at) -> None:
    """The events of ``name`` (and those of no vehicle of the run) on its axis."""
    mine = [event for event in events if event[2] == name or event[2] not in names]
    for number, (start, stop) in enumerate(_offline_spans(mine, name, last_t, done_at=done_at)):
        axis.axvspan(
            start,
            stop,
            color=OFFLINE_COLOUR,
            alpha=0.25,
            linewidth=0,
            label="offline" if number == 0 else None,
        )
    for kind, (colour, label) in CROSS_COLOURS.items():
        crosses = [t for t, what, _, _ in mine if what == kind]
        if crosses:
            axis.plot(
                crosses,
                [0.97] * len(crosses),
                linestyle="none",
                marker="x",
                markersize=5,
                color=colour,
                transform=axis.get_xaxis_transform(),
                label=label,
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


def _breaks(events, name: str, names: tuple[str, ...], spans) -> np.ndarray:
    """Times after which ``name``'s released base is another: re-plans, its restarts, its losses."""
    times = [
        t for t, kind, vehicle, _ in events if kind in BREAKS and (vehicle == name or vehicle not in names)
    ]
    times += [edge for span in spans for edge in span]
    return np.unique(np.array(times, dtype=float))


def _progress(axis, states: np.ndarray, orders: np.ndarray, colour: str, last_t: float, breaks) -> None:
    """Progress along the path (solid) and the released base's frontier (dashed steps), the gap shaded.

    The frontier and the shading stop at each break and go on from the next order: a base lost or
    replaced is not drawn across the gap.
    """
    t, along = states[:, 0], states[:, 1]
    if states.shape[0]:
        axis.plot(t, along, color=colour, linewidth=1.5, label="progress")
    if orders.shape[0] == 0:
        return
    # per order, when it stops counting: the next order, the next break after it, or the run's end
    ends = np.append(orders[1:, 0], max(last_t, orders[-1, 0]))
    if breaks.size:
        following = np.searchsorted(breaks, orders[:, 0], side="right")
        cut = np.where(following < breaks.size, breaks[np.minimum(following, breaks.size - 1)], np.inf)
        ends = np.minimum(ends, cut)
    for k, (begin, end) in enumerate(zip(orders[:, 0], ends, strict=True)):
        axis.plot(
            [begin, end],
            [orders[k, 1]] * 2,
            color=colour,
            linestyle="--",
            linewidth=1.2,
            label="frontier" if k == 0 else None,
        )
        if k + 1 < orders.shape[0] and ends[k] == orders[k + 1, 0]:  # the step up to the next order
            axis.plot([end, end], orders[k : k + 2, 1], color=colour, linestyle="--", linewidth=1.2)
    if states.shape[0] == 0:
        return
    # the frontier in force at each state's time: the last order published at or before it, until its end
    index = np.searchsorted(orders[:, 0], t, side="right") - 1
    released = (index >= 0) & (t <= ends[np.maximum(index, 0)])
    frontier = np.where(released, orders[np.maximum(index, 0), 1], np.nan)
    segment = np.searchsorted(breaks, t, side="right")  # states between two breaks are shaded together
    labelled = False
    for part in np.unique(segment):
        inside = segment == part
        if not (inside & released).any():
            continue
        axis.fill_between(
            t[inside],
            along[inside],
            frontier[inside],
            where=released[inside],
            color=colour,
            alpha=0.12,
            linewidth=0,
            label=None if labelled else "released, not yet driven",
        )
        labelled = True


def plot_live_run(run: dict, *, names, figure=None):
    """A live run: each vehicle's progress along its path against time, and the events.

    One axis per vehicle (titled with its name, in its colour of
    :func:`~trajgen.plots.speed.vehicle_colour`), sharing the time axis, seconds of the run. On each:
    the distance the vehicle has travelled along its path, metres (solid), and the frontier of its
    released base, metres (dashed steps: each order or order update moves it; the vehicle may not pass
    it), with the gap between the two shaded. The frontier and the shading stop where the base is lost
    or replaced (a restart, a new goal, a re-plan, a stop, a connection loss) and go on from the next
    order. The events of that vehicle (and those of no vehicle of the run, on every axis): its
    connection losses as grey spans from ``CONNECTIONBROKEN`` or ``OFFLINE`` to its next ``ONLINE`` (or
    the end of the run; not after it stood at the end of its last base: a vehicle gone home),
    ignored messages and states off its plan as crosses at the top, goals, re-plans, restarts and a
    stop as dash-dotted vertical lines with a short label. A vehicle that sent no state has its axis,
    saying so. The title gives the outcome and the makespan, seconds, of the ``end`` record if there
    is one.

    Parameters
    ----------
    run : dict
        From :func:`trajgen.live.runlog.read_run_log`: ``states`` (per vehicle name, ``(t s,
        along_m m, driving)``), ``orders`` (per vehicle name, ``(t s, frontier_m m)``), ``events``
        (``(t s, kind, vehicle or None, detail)``, kind one of :data:`EVENT_KINDS`) and ``end`` (the
        end record, with ``outcome`` and ``makespan_s`` s, or ``None``).
    names : sequence of str
        The vehicles' names, as in the log, one axis each from the top.
    figure : matplotlib Figure or SubFigure, optional
        Where to draw the axes (default: a new Figure of 11 inches by 1 + 3.25 per vehicle).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        ``names`` is not one or more different strings; ``run`` is not such a dict, has states or
        orders of a vehicle not in ``names``, a malformed row or event, or a non-finite number.
    """
    names = _check_names(names)
    progress, frontiers, events, ended, (outcome, makespan, end_t) = _check_run(run, names)
    tables = [rows for rows in (*progress, *frontiers) if rows.shape[0]]
    times = [rows[-1, 0] for rows in tables] + [event[0] for event in events[-1:]]
    times += [float(end_t)] if end_t is not None else []
    last_t = max(times, default=0.0)
    first_t = min([rows[0, 0] for rows in tables] + [0.0])  # the run's time starts at the first order
    area = drawing_area(figure, figsize=(11, 1.0 + 3.25 * len(names)))
    axes = np.atleast_1d(area.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0])
    for vehicle, (axis, name) in enumerate(zip(axes, names, strict=True)):
        colour = vehicle_colour(vehicle)
        done_at = _done_at(progress[vehicle], frontiers[vehicle])
        mine = [event for event in events if event[2] == name or event[2] not in names]
        spans = _offline_spans(mine, name, last_t, done_at=done_at)
        breaks = _breaks(events, name, names, spans)
        _progress(axis, progress[vehicle], frontiers[vehicle], colour, last_t, breaks)
        _mark_events(axis, events, name, names, last_t, done_at)
        if progress[vehicle].shape[0] == 0:
            axis.text(
                0.5,
                0.5,
                f"no state of {name} in the log (it never took an order)",
                transform=axis.transAxes,
                ha="center",
                va="center",
                fontsize=9,
                color=colour,
            )
        axis.margins(y=0.1)  # room above the curves for the marks at the top
        axis.set_title(name, fontsize=11, fontweight="bold", color=colour, loc="left")
        axis.set_ylabel("along its path, m")
        axis.grid(True, alpha=0.3)
        if axis.get_legend_handles_labels()[0]:
            axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
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
