"""Figures the docs quote are the code's own: computed here, looked up in the pages, so they cannot drift.

When a change moves a figure, this test names the page and the figure it now prints.
"""

from __future__ import annotations

import runpy

import numpy as np
import pytest

from tests.conftest import REPO
from trajgen import default_scenario, run
from trajgen.export.plc import plc_tables
from trajgen.export.plc.dialects import DIALECTS, TableDialect

DOCS = REPO / "docs"
TABLE_DIALECTS = [d for d in DIALECTS if isinstance(d, TableDialect)]


def _text(page: str) -> str:
    """The page with its whitespace collapsed (figures may wrap across lines)."""
    return " ".join((DOCS / page).read_text(encoding="utf-8").split())


def _mm(metres: float) -> str:
    """Millimetres to three significant digits, written out (``0.000138``, ``0.468``)."""
    return np.format_float_positional(1e3 * metres, precision=3, unique=False, fractional=False, trim="-")


@pytest.fixture(scope="module")
def demo_tables() -> dict[str, dict]:
    """Every table dialect's summary of the demo swap's default (optimal) schedule."""
    verified = run(default_scenario()).verified
    return {d.name.value: plc_tables(verified, d).summary() for d in TABLE_DIALECTS}


def _figures(summary: dict) -> tuple[str, str, str]:
    position, velocity = _mm(max(summary["position_error_m"])), _mm(max(summary["velocity_error_mps"]))
    scale = summary["time_scale"]
    slower = f"{100.0 * (scale - 1.0):.4f} %" if scale > 1.0 else "0"
    return position, velocity, slower


@pytest.mark.parametrize("name", [d.name.value for d in TABLE_DIALECTS])
def test_the_plc_tables_page_quotes_each_dialects_figures(demo_tables, name):
    summary = demo_tables[name]
    position, velocity, slower = _figures(summary)
    points = " and ".join(f"{p:,}" for p in summary["points"])
    page = (DOCS / "formats" / "plc-tables.md").read_text(encoding="utf-8")
    # the figures table: its first cell names the dialects in backticks, without a link
    rows = [
        line for line in page.splitlines() if line.startswith("| `") and f"`{name}`" in line.split("|")[1]
    ]
    assert len(rows) == 1, rows
    expected = f"| {points} | {position} mm | {velocity} mm/s | {slower} |"
    assert rows[0].endswith(expected), f"plc-tables.md row of {name} should end {expected!r}: {rows[0]!r}"


@pytest.mark.parametrize("name", ["twincat-cam", "codesys-xy", "siemens-xy", "velocity-profile"])
def test_each_dialects_page_quotes_its_figures(demo_tables, name):
    position, velocity, _ = _figures(demo_tables[name])
    points = demo_tables[name]["points"][0]
    expected = f"{points:,} points per vehicle, worst error {position} mm and {velocity} mm/s"
    assert expected in _text(f"formats/{name}.md"), f"formats/{name}.md should say {expected!r}"


def test_the_timing_page_quotes_example_06s_swap_in_both_classes(capsys):
    """Example 06's swap (legs 12/8/15 m, a fast vehicle and a slow one), as the example computes it."""
    example = runpy.run_path(str(REPO / "examples" / "06_two_different_vehicles.py"))
    capsys.readouterr()
    paper = example["in_planned_class"].schedule.duration
    fastest = example["fastest"].schedule.duration
    text = _text("timing.md")
    assert f"it takes {fastest:.2f} s against {paper:.2f} s in the paper's class" in text
    assert f"{fastest:.2f} s (other class; {paper:.2f} s in the paper's)" in text
