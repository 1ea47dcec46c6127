"""Digests of every file the example track graphs export, to hold their bytes while the code below moves.

For each example graph and each of ``exact`` and ``toppra``: both vehicles' generic CSV, every table
dialect's tables (or that the dialect refuses the schedule), and every VDA 5050 file of the run.
Stored in ``tests/data/golden-graphs.json``, made at a1d9ece (before issue 49) and unchanged since.
"""

from __future__ import annotations

import hashlib
from datetime import UTC, datetime
from pathlib import Path

from tests.support.graph_cases import EXAMPLES
from trajgen import certify
from trajgen.errors import TrajgenError
from trajgen.export.csv import CsvOptions, render_profile
from trajgen.export.plc.dialects import DIALECTS, TableDialect
from trajgen.export.plc.files import plc_tables
from trajgen.export.vda5050.files import order_files
from trajgen.export.vda5050.options import Vda5050Options
from trajgen.methods import make_schedule
from trajgen.scenario import load_scenario

__all__ = ["GRAPHS", "METHODS", "digests"]

#: The example graphs and the methods whose files are held.
GRAPHS = ("h", "passing-loop", "ring-with-spurs", "main-line-with-sidings")
METHODS = ("exact", "toppra")
#: Where the VDA 5050 files are placed (only their paths below it count).
_FOLDER = Path("vda5050")


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def digests(name: str, method: str) -> dict[str, str]:
    """``{file: SHA-256}`` of every file ``name``'s scenario exports with ``method``."""
    scenario = load_scenario(EXAMPLES / f"{name}.toml")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=method))
    key = f"{name}-{method}"
    out = {
        f"{key}/generic/{vehicle}.csv": _sha(render_profile(verified, v, CsvOptions()))
        for v, vehicle in enumerate(scenario.names)
    }
    for dialect in DIALECTS:
        if not isinstance(dialect, TableDialect):
            continue
        try:
            tables = plc_tables(verified, dialect)
        except TrajgenError as error:
            out[f"{key}/{dialect.name.value}"] = f"refused: {type(error).__name__}"
            continue
        for vehicle, data in zip(scenario.names, tables.contents, strict=True):
            out[f"{key}/{dialect.name.value}/{vehicle}"] = _sha(data)
    options = Vda5050Options(start_time=datetime(2026, 5, 1, 8, 0, tzinfo=UTC))
    for path, data in order_files(verified, scenario.names, _FOLDER, options=options).items():
        out[f"{key}/vda5050/{path.relative_to(_FOLDER)}"] = _sha(data)
    return out
