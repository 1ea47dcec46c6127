"""An independent check of a track graph's generic CSV profiles, from their rows and the scenario file alone.

Reads the scenario TOML itself (``tomllib``), takes the node-to-node distances from its own
Floyd–Warshall over the edges and the track distance of two rows from the four ways through the
edges' ends (and along one edge). Nothing of the package is used: a bug there cannot hide here.
"""

from __future__ import annotations

import csv
import io
import math
import tomllib
from pathlib import Path


class ScenarioFile:
    """The track, limits, starts and goals of a graph scenario file, as plain numbers."""

    def __init__(self, path: Path) -> None:
        data = tomllib.loads(Path(path).read_text())
        track = data["track"]
        coordinates = track.get("nodes", {})
        names = sorted({n for e in track["edges"].values() for n in (e["from"], e["to"])})
        self.index = {name: k for k, name in enumerate(names)}
        self.coordinates = {name: tuple(xy) for name, xy in coordinates.items()}
        self.edges = {}
        for name, edge in track["edges"].items():
            length = edge.get("length")
            if length is None:
                (x0, y0), (x1, y1) = self.coordinates[edge["from"]], self.coordinates[edge["to"]]
                length = math.hypot(x1 - x0, y1 - y0)
            self.edges[name] = (edge["from"], edge["to"], float(length))
        n = len(names)
        table = [[0.0 if i == j else math.inf for j in range(n)] for i in range(n)]
        for a, b, length in self.edges.values():
            i, j = self.index[a], self.index[b]
            table[i][j] = table[j][i] = min(table[i][j], length)
        for k in range(n):
            for i in range(n):
                for j in range(n):
                    if table[i][k] + table[k][j] < table[i][j]:
                        table[i][j] = table[i][k] + table[k][j]
        self.nodes = table
        self.separation = float(data["safety"]["min_separation"])
        self.vehicles = data["vehicle"]

    def where(self, text: str) -> tuple[str, float]:
        """A position of the file (``EDGE:s`` or a node) as (edge, s)."""
        if ":" in text:
            edge, s = text.split(":")
            return edge, float(s)
        for name, (a, b, length) in self.edges.items():
            if a == text:
                return name, 0.0
            if b == text:
                return name, length
        raise KeyError(text)

    def distance(self, first: tuple[str, float], second: tuple[str, float]) -> float:
        """The track distance between two points (edge, s)."""
        (e1, s1), (e2, s2) = first, second
        a1, b1, l1 = self.edges[e1]
        a2, b2, l2 = self.edges[e2]
        ways = [
            s1 + self.nodes[self.index[a1]][self.index[a2]] + s2,
            s1 + self.nodes[self.index[a1]][self.index[b2]] + (l2 - s2),
            (l1 - s1) + self.nodes[self.index[b1]][self.index[a2]] + s2,
            (l1 - s1) + self.nodes[self.index[b1]][self.index[b2]] + (l2 - s2),
        ]
        if e1 == e2:
            ways.append(abs(s1 - s2))
        return min(ways)


def read_rows(text: str) -> tuple[list[str], list[list[str]]]:
    """Header and rows of a generic CSV (``;``-separated, ``.`` decimals), after its record line if any."""
    if text.startswith("#"):  # a schedule without jerk limits records so on the first line
        text = text.split("\n", 1)[1]
    rows = list(csv.reader(io.StringIO(text), delimiter=";"))
    return rows[0], rows[1:]


def check_profiles(scenario: ScenarioFile, texts: tuple[str, str], *, jerk: bool) -> dict:
    """Check both vehicles' profiles row by row: separation, limits, start and goal, x/y on the edge.

    Returns the closest track distance and the worst ratio to each limit; raises AssertionError with
    the row on the first violation.
    """
    tables = [read_rows(text) for text in texts]
    header = tables[0][0]
    assert header[:7] == ["t_s", "axis_m", "v_mps", "a_mps2", "j_mps3", "edge", "s_m"], header
    assert len(tables[0][1]) == len(tables[1][1]), "both files have one row per sample time"
    closest = math.inf
    worst = {"v": 0.0, "a": 0.0, "j": 0.0}
    for vehicle, (_, rows) in enumerate(tables):
        limits = scenario.vehicles[vehicle]
        start = scenario.where(limits["start"])
        goal = scenario.where(limits["goal"])
        first, last = rows[0], rows[-1]
        assert scenario.distance((first[5], float(first[6])), start) < 1e-6, (vehicle, first)
        assert scenario.distance((last[5], float(last[6])), goal) < 1e-6, (vehicle, last)
        assert abs(float(last[2])) < 1e-6, "at rest at the goal"
        assert abs(float(first[2])) < 1e-6, "at rest at the start"
        for row in rows:
            v, a, j = (abs(float(x)) for x in row[2:5])
            worst["v"] = max(worst["v"], v / limits["max_velocity"])
            worst["a"] = max(worst["a"], a / limits["max_acceleration"])
            if jerk:
                worst["j"] = max(worst["j"], j / limits["max_jerk"])
            edge, s = row[5], float(row[6])
            a_node, b_node, length = scenario.edges[edge]
            assert -1e-9 <= s <= length + 1e-9, row
            if len(row) == 9:
                (x0, y0), (x1, y1) = scenario.coordinates[a_node], scenario.coordinates[b_node]
                f = s / length
                assert (
                    math.hypot(float(row[7]) - (x0 + f * (x1 - x0)), float(row[8]) - (y0 + f * (y1 - y0)))
                    < 1e-6
                )
    for row1, row2 in zip(tables[0][1], tables[1][1], strict=True):
        assert row1[0] == row2[0], "one time per row"
        gap = scenario.distance((row1[5], float(row1[6])), (row2[5], float(row2[6])))
        assert gap >= scenario.separation - 1e-6, (row1, row2, gap)
        closest = min(closest, gap)
    for name, ratio in worst.items():
        assert ratio <= 1.0 + 1e-6, (name, ratio)
    return {"closest": closest, **worst}
