"""The global planner: a search on the grid plus the paper's post-processing.

``plan_global`` is what the CLI, the fusion controller and the analysis call.
Its result carries the cell path, the world path, the key nodes and the
paper's metrics. For the traditional algorithm the key nodes are only the
turning points of the raw path (collinear nodes dropped); for the improved
one they are the safety-checked key nodes of section 2.3.3.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from planner.astar import search
from planner.grid_map import Cell, GridMap, Point
from planner.key_nodes import drop_collinear, extract_key_nodes
from planner.path_metrics import path_length, total_turning_angle_deg, turning_times

ALGORITHMS = ("traditional", "improved")

# AGV radius 0.3 m (Table-1-sized AGV) plus a 0.2 m margin
DEFAULT_SAFETY_DISTANCE = 0.5


@dataclass(frozen=True)
class PlanResult:
    """One global plan. When ``found`` is False every path is empty: no path exists."""

    algorithm: str
    start: Point
    goal: Point
    found: bool
    cells: list[Cell] = field(default_factory=list)
    path: list[Point] = field(default_factory=list)
    key_nodes: list[Point] = field(default_factory=list)
    expansions: int = 0
    time_s: float = 0.0

    @property
    def length(self) -> float:
        """Length (m) of the path the AGV is meant to drive: through the key nodes."""
        return path_length(self.key_nodes)

    @property
    def turns(self) -> int:
        return turning_times(self.key_nodes)

    @property
    def turning_angle_deg(self) -> float:
        return total_turning_angle_deg(self.key_nodes)


def plan_global(
    grid: GridMap,
    start: Point,
    goal: Point,
    algorithm: str = "improved",
    *,
    safety_distance: float = DEFAULT_SAFETY_DISTANCE,
    corner_cutting: bool = False,
) -> PlanResult:
    """Plan from ``start`` to ``goal`` (world frame, metres).

    Raises ``MapError`` when start or goal is outside the map or in an obstacle,
    ``ValueError`` for an unknown algorithm. An unreachable goal is not an
    error: it gives a result with ``found == False``.
    """
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r}: choose one of {', '.join(ALGORITHMS)}")
    if safety_distance < 0:
        raise ValueError(f"safety distance must be >= 0, got {safety_distance}")
    start_cell = grid.free_cell_of(start, "start")
    goal_cell = grid.free_cell_of(goal, "goal")
    t0 = time.perf_counter()
    result = search(
        grid,
        start_cell,
        goal_cell,
        improved=algorithm == "improved",
        corner_cutting=corner_cutting,
    )
    if not result.found:
        return PlanResult(
            algorithm,
            start,
            goal,
            False,
            expansions=result.expansions,
            time_s=time.perf_counter() - t0,
        )
    if algorithm == "improved":
        key_cells = extract_key_nodes(grid, result.cells, safety_distance)
    else:
        key_cells = drop_collinear(result.cells)
    elapsed = time.perf_counter() - t0
    return PlanResult(
        algorithm,
        start,
        goal,
        True,
        cells=result.cells,
        path=[grid.centre_of(c) for c in result.cells],
        key_nodes=[grid.centre_of(c) for c in key_cells],
        expansions=result.expansions,
        time_s=elapsed,
    )


def warm_up() -> None:
    """Load the compiled search and key-node kernels (numba's on-disk cache, or a
    compile on the very first use) so that later plans time only the planning."""
    grid = GridMap(np.zeros((2, 3), dtype=bool))
    for algorithm in ALGORITHMS:
        plan_global(grid, (0.5, 0.5), (2.5, 1.5), algorithm)
