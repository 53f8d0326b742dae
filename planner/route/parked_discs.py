"""Discs parked on the route: the cells a replan must go round.

The global planner knows the map and the sensed temporary cells, not the
moving discs (walkers, other AGVs), which DWA handles. A disc that has come
to rest on the route is a wall DWA can only stall in front of: a replan that
ignores it draws the same route through it again. ``blocking_cells`` turns
every disc at rest that leaves the body no room past it on the remaining
route into the grid cells it covers, for a replan to mark.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from planner.maps.grid import Cell, GridMap, Point, cells_in_disc
from planner.route.route_check import route_samples

AT_REST = 0.05  # m/s: a disc slower than this counts as parked


def covered_cells(grid: GridMap, centre: Point, radius: float) -> list[Cell]:
    """The grid cells whose square overlaps the disc (``centre``, ``radius``)."""
    res = grid.resolution
    ox, oy = grid.origin
    lo = grid.cell_of((centre[0] - radius, centre[1] - radius))
    hi = grid.cell_of((centre[0] + radius, centre[1] + radius))
    cells = []
    for col in range(lo[0], hi[0] + 1):
        for row in range(lo[1], hi[1] + 1):
            # nearest point of the cell's square to the centre
            nx = min(max(centre[0], ox + col * res), ox + (col + 1) * res)
            ny = min(max(centre[1], oy + row * res), oy + (row + 1) * res)
            if math.dist((nx, ny), centre) < radius and grid.contains_cell((col, row)):
                cells.append((col, row))
    return cells


def blocking_cells(
    grid: GridMap, discs: np.ndarray | None, route: Sequence[Point], radius: float
) -> list[Cell]:
    """The cells of every disc at rest (rows [x, y, vx, vy, r]) that comes closer than
    ``radius`` + its own radius to the polyline ``route`` (the AGV's remaining route)."""
    if discs is None or not len(discs) or len(route) < 2:
        return []
    points = route_samples(route, grid.resolution / 2)
    cells: list[Cell] = []
    for x, y, vx, vy, r in np.asarray(discs, dtype=float).reshape(-1, 5):
        if math.hypot(vx, vy) >= AT_REST:
            continue
        if np.hypot(points[:, 0] - x, points[:, 1] - y).min() < r + radius:
            cells += covered_cells(grid, (x, y), r)
    return cells


Parked = Sequence[tuple[Point, float, str]]
"""AGVs stopped for good as ((x, y), radius, who): who is a label naming the AGV."""


def held_point(grid: GridMap, points: dict[str, Point], parked: Parked) -> str | None:
    """ "goal (x, y) is held by <who>" for the first of ``points`` (what -> point) whose
    cell lies in the cells of a stopped AGV (as a global plan blocks them); None if none."""
    for what, point in points.items():
        if not grid.contains_point(point):
            continue
        cell = grid.cell_of(point)
        for centre, radius, who in parked:
            if cell in cells_in_disc(grid, centre, radius):
                return f"{what} ({point[0]:g}, {point[1]:g}) is held by {who}"
    return None
