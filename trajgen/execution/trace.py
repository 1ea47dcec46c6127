"""The executed motion of a simulation, spooled to temporary files, and decimated samples for its plot.

Memory does not grow with the simulated time: the trace is spooled to
temporary files a block of rows at a time, and the plot keeps at most
:data:`PLOT_SAMPLES` samples per curve.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator

import numpy as np

from topology import JUNCTION_INDEX, StarGraph, TrackGraph
from trajgen.export.csv import HEADER_NAMES, CsvOptions, format_rows
from trajgen.export.graph_rows import check_edge_names, format_graph_block, graph_header
from trajgen.model.graph_schedule import GraphState
from trajgen.model.schedule import ScheduleState

__all__ = ["PLOT_SAMPLES", "Decimated", "Trace"]

#: Most samples per curve kept for the plot.
PLOT_SAMPLES = 20_000
#: Rows formatted and spooled at a time.
_ROWS_PER_BLOCK = 5_000


class Trace:
    """The executed motion (true positions) of both vehicles, spooled to temporary files as CSV rows.

    Parameters
    ----------
    graph : StarGraph or TrackGraph
        The track (on a track graph the rows are a graph's generic CSV: edge and metres on it).
    options : CsvOptions
        Dialect of the rows (the sample period is the simulation's control period).

    Raises
    ------
    OptionError
        An edge name the CSV could not hold as one field.
    """

    def __init__(self, graph: StarGraph | TrackGraph, options: CsvOptions) -> None:
        self.graph = graph
        self.options = options
        if isinstance(graph, TrackGraph):
            check_edge_names(graph, options.delimiter)
            names = graph_header(graph, options.units.value)
        else:
            names = HEADER_NAMES[options.units]
        self._files = [tempfile.TemporaryFile(), tempfile.TemporaryFile()]  # noqa: SIM115 - closed by close()
        header = (options.delimiter.join(names) + "\r\n").encode("ascii")
        for handle in self._files:
            handle.write(header)
        self._rows: list[list[float]] = []
        self.rows = 0

    def add(self, t: float, bodies) -> None:
        """Record both vehicles' true state at time ``t``."""
        row = [t]
        graph = isinstance(self.graph, TrackGraph)
        for body in bodies:
            leg = body.leg if graph or body.s > 0.0 else JUNCTION_INDEX
            row.extend((body.axis, body.v, body.a, body.j, leg, body.s))
        self._rows.append(row)
        self.rows += 1
        if len(self._rows) >= _ROWS_PER_BLOCK:
            self._flush()

    def _flush(self) -> None:
        if not self._rows:
            return
        data = np.array(self._rows)
        self._rows = []
        t = data[:, 0]
        columns = {
            name: np.stack([data[:, 1 + 6 * v + k] for v in (0, 1)])
            for k, name in enumerate(("axis", "velocity", "acceleration", "jerk", "leg", "s"))
        }
        if isinstance(self.graph, TrackGraph):
            self._flush_graph(t, columns)
            return
        state = ScheduleState(
            t,
            columns["axis"],
            columns["velocity"],
            columns["acceleration"],
            columns["jerk"],
            columns["leg"].astype(int),
            columns["s"],
        )
        for v, handle in enumerate(self._files):
            lines = format_rows(self.graph, state, v, self.options)
            handle.write(("\r\n".join(lines) + "\r\n").encode("ascii"))

    def _flush_graph(self, t: np.ndarray, columns: dict) -> None:
        """Spool a block of rows on a track graph (the travel is not a column of the rows)."""
        state = GraphState(
            t,
            np.zeros_like(columns["axis"]),
            columns["axis"],
            columns["velocity"],
            columns["acceleration"],
            columns["jerk"],
            columns["leg"].astype(int),
            columns["s"],
        )
        units = self.options.units
        for v, handle in enumerate(self._files):
            handle.write(
                format_graph_block(
                    self.graph,
                    state,
                    v,
                    delimiter=self.options.delimiter,
                    decimal=self.options.decimal,
                    scale=units.scale,
                    decimals=units.decimals,
                )
            )

    def chunks(self, vehicle: int) -> Iterator[bytes]:
        """The CSV of ``vehicle`` (0 or 1), a block at a time."""
        self._flush()
        handle = self._files[vehicle]
        handle.seek(0)
        while block := handle.read(1 << 20):
            yield block

    def close(self) -> None:
        """Remove the temporary files."""
        for handle in self._files:
            handle.close()


class Decimated:
    """At most ``limit`` samples of a run of any length: every other sample is dropped when full."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.stride = 1
        self.count = 0
        self.rows: list[tuple] = []

    def add(self, row: tuple) -> None:
        """Offer one sample; every ``stride``-th is kept, and the stride doubles when the rows are full."""
        if self.count % self.stride == 0:
            self.rows.append(row)
            if len(self.rows) >= self.limit:
                self.rows = self.rows[::2]
                self.stride *= 2
        self.count += 1
