"""A grid oracle for the graph planner, written apart from its code: breadth-first search over grid pairs.

The track is cut into steps of :data:`GRID` metres (every length, position and separation of a
case is a multiple of it). The track distance of two grid points is a breadth-first search of the
grid (SciPy's, on the grid's own adjacency), and a pair of grid points (one per vehicle) is safe
iff their distance is at least the separation. A step moves one vehicle to an adjacent grid point.
Along an edge, the track distance from a fixed point is the minimum of affine functions, or
``|s - s_q|`` on the fixed point's own edge, whose kink is a grid point; so a step between two safe
pairs is safe all along, and the fewest steps, times :data:`GRID`, is the shortest one-at-a-time
route (both vehicles' travel).

Also here: the random trees and graphs with loops the planner is compared on (seeded).
"""

from __future__ import annotations

import itertools
import random

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

#: Metres between two grid points.
GRID = 0.5


class GridTrack:
    """The grid points of a track ``{edge: (from, to, length)}`` and their track distances in steps."""

    def __init__(self, edges: dict[str, tuple[str, str, float]]) -> None:
        self.point_of: dict[tuple[str, int], int] = {}
        nodes: dict[str, int] = {}
        links: list[tuple[int, int]] = []
        count = 0

        def node(name: str) -> int:
            nonlocal count
            if name not in nodes:
                nodes[name] = count
                count += 1
            return nodes[name]

        for name, (start, end, length) in edges.items():
            steps = round(length / GRID)
            assert abs(steps * GRID - length) < 1e-12, (name, length)
            chain = [node(start)]
            for _ in range(1, steps):
                chain.append(count)
                count += 1
            chain.append(node(end))
            for k, point in enumerate(chain):
                self.point_of[(name, k)] = point
            links += list(itertools.pairwise(chain))
        self.count = count
        rows = [a for a, _ in links] + [b for _, b in links]
        cols = [b for _, b in links] + [a for a, _ in links]
        self.adjacency = sparse.csr_matrix(
            (np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(count, count)
        )
        self.steps = csgraph.shortest_path(self.adjacency, unweighted=True)

    def index(self, edge: str, s: float) -> int:
        """The grid point ``s`` metres along ``edge`` from its ``from`` node."""
        steps = round(s / GRID)
        assert abs(steps * GRID - s) < 1e-12, (edge, s)
        return self.point_of[(edge, steps)]


def shortest_route(
    grid: GridTrack, start: tuple[int, int], goal: tuple[int, int], separation: float
) -> float | None:
    """Metres of the shortest one-at-a-time route (both vehicles' travel), or ``None`` if none exists."""
    apart = grid.steps >= round(separation / GRID) - 1e-9
    if not (apart[start] and apart[goal]):
        return None
    seen = np.zeros((grid.count, grid.count), dtype=bool)
    seen[start] = True
    frontier = seen.copy()
    level = 0
    while not seen[goal]:
        moving = frontier.astype(np.int8)
        # vehicle 1 moves: its grid point (the row) changes; vehicle 2 moves: the column changes
        reached = (grid.adjacency @ moving > 0) | (moving @ grid.adjacency > 0)
        frontier = reached & apart & ~seen
        if not frontier.any():
            return None
        seen |= frontier
        level += 1
    return level * GRID


def random_track(rng: random.Random, *, junctions: int, loops: int, leaf_steps=(1, 12)) -> dict:
    """A random tree of ``junctions`` junctions (each of degree 3 or more), plus ``loops`` extra edges.

    Inner edges are 2 to 12 m, leaves ``leaf_steps`` grid steps; extra edges join two junctions (a
    parallel edge is a passing loop).
    """
    edges: dict[str, tuple[str, str, float]] = {}
    junction_names = ["J0"]
    for j in range(1, junctions):
        parent = rng.choice(junction_names)
        edges[f"e{len(edges)}"] = (parent, f"J{j}", rng.randint(4, 24) * GRID)
        junction_names.append(f"J{j}")
    degree = dict.fromkeys(junction_names, 0)
    for start, end, _ in edges.values():
        degree[start] += 1
        degree[end] += 1
    leaves = 0
    for name in junction_names:
        while degree[name] < 3:
            edges[f"e{len(edges)}"] = (name, f"L{leaves}", rng.randint(*leaf_steps) * GRID)
            leaves += 1
            degree[name] += 1
    for _ in range(loops):
        start, end = rng.sample(junction_names, 2) if len(junction_names) > 1 else ("J0", "L0")
        edges[f"e{len(edges)}"] = (start, end, rng.randint(4, 24) * GRID)
    return edges


def random_case(seed: int, *, loops: bool):
    """``(edges, start, goal, separation)`` of a seeded random case, or ``None`` (no apart pair found).

    Trees have 1 to 7 junctions, graphs with loops 2 to 4 junctions and 1 or 2 extra edges; the
    separation is 1, 1.5, 2, 3 or 4 m; start and goal are grid points ``EDGE:s``.
    """
    rng = random.Random(f"graph-{'loops' if loops else 'tree'}-{seed}")
    junctions = rng.randint(2, 4) if loops else rng.randint(1, 7)
    edges = random_track(rng, junctions=junctions, loops=rng.randint(1, 2) if loops else 0)
    separation = rng.choice([1.0, 1.5, 2.0, 3.0, 4.0])
    grid = GridTrack(edges)
    names = list(edges)
    for _ in range(50):
        places = []
        for _ in range(4):
            name = rng.choice(names)
            places.append((name, rng.randint(0, round(edges[name][2] / GRID)) * GRID))
        ids = [grid.index(*place) for place in places]
        if (
            grid.steps[ids[0], ids[1]] * GRID >= separation
            and grid.steps[ids[2], ids[3]] * GRID >= separation
        ):
            text = [f"{name}:{s:g}" for name, s in places]
            return edges, (text[0], text[1]), (text[2], text[3]), separation
    return None
