"""The executed motion of a simulation, spooled to temporary files, and decimated samples for its plot.

Memory does not grow with the simulated time: the trace is spooled to
temporary files a block of rows at a time, and the plot keeps at most
:data:`PLOT_SAMPLES` samples per curve.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator

import numpy as np

from topology import TrackGraph
from trajgen.export.csv import CsvOptions, format_block
from trajgen.export.rows import check_edge_names, header
from trajgen.model.state import TrackState

__all__ = ["PLOT_SAMPLES", "Decimated", "Trace"]

#: Most samples per curve kept for the plot.
PLOT_SAMPLES = 20_000
#: Rows formatted and spooled at a time.
_ROWS_PER_BLOCK = 5_000


class Trace:
    """The executed motion (true positions) of the vehicles, spooled to temporary files as CSV rows.

    Parameters
    ----------
    track : TrackGraph
        The schedule's track (:attr:`~trajgen.model.schedule.Schedule.track`): the rows are its
        generic CSV's (:func:`~trajgen.export.rows.header`).
    options : CsvOptions
        Dialect of the rows (the sample period is the simulation's control period).
    count : int, optional
        Number of vehicles (default 2).

    Raises
    ------
    OptionError
        An edge name the CSV could not hold as one field.
    """

    def __init__(self, track: TrackGraph, options: CsvOptions, count: int = 2) -> None:
        self.track = track
        self.options = options
        check_edge_names(track, options.delimiter)
        names = header(track, options.units.value)
        self._files = [tempfile.TemporaryFile() for _ in range(count)]  # noqa: SIM115 - closed by close()
        line = (options.delimiter.join(names) + "\r\n").encode("ascii")
        for handle in self._files:
            handle.write(line)
        self._rows: list[list[float]] = []
        self.rows = 0

    def add(self, t: float, bodies) -> None:
        """Record the vehicles' true states at time ``t``."""
        row = [t]
        for body in bodies:  # a star's body at its junction is on no leg: s = 0 on the first
            row.extend((body.axis, body.v, body.a, body.j, max(body.leg, 0), body.s))
        self._rows.append(row)
        self.rows += 1
        if len(self._rows) >= _ROWS_PER_BLOCK:
            self._flush()

    def _flush(self) -> None:
        if not self._rows:
            return
        data = np.array(self._rows)
        self._rows = []
        count = len(self._files)
        columns = {
            name: np.stack([data[:, 1 + 6 * v + k] for v in range(count)])
            for k, name in enumerate(("axis", "velocity", "acceleration", "jerk", "edge", "s"))
        }
        columns["edge"] = columns["edge"].astype(int)
        state = TrackState(data[:, 0], **columns)
        for v, handle in enumerate(self._files):
            handle.write(format_block(self.track, state, v, self.options))

    def chunks(self, vehicle: int) -> Iterator[bytes]:
        """The CSV of vehicle number ``vehicle``, a block at a time."""
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
