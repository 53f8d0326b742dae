"""The global planner: a search on the grid plus the paper's post-processing.

``plan_global`` is what the CLI, the fusion controller and the analysis call.
Its result carries the cell path, the world path, the key nodes and the
paper's metrics. For the traditional algorithm the key nodes are only the
turning points of the raw path (collinear nodes dropped); for the improved
one they are the safety-checked key nodes of section 2.3.3.

Two profiles (planner.core.profiles):

- ``paper``: the search on the map's obstacle cells; key nodes keep the safety
  distance (radius + margin) from obstacle-cell centres; the path runs from the
  start cell's centre to the goal cell's centre.
- ``default``: the search on the costmap of the AGV's clearance (planner.maps.costmap);
  key nodes keep the radius from obstacle squares, and the margin where there is
  room (planner.route.key_nodes); the path runs from the exact start to the exact goal.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from planner.core.path_metrics import path_length, total_turning_angle_deg, turning_times
from planner.core.profiles import DEFAULT, PAPER, check_profile
from planner.maps.clearance import CLEARANCE_CAP, Clearance, clearance_for
from planner.maps.costmap import Costmap
from planner.maps.grid import Cell, GridMap, Point
from planner.maps.segment_clearance import route_clearance
from planner.route.astar import search, search_costmap
from planner.route.centring import centred
from planner.route.key_nodes import (
    drop_collinear,
    drop_collinear_points,
    extract_key_nodes,
    extract_key_nodes_costmap,
)

ALGORITHMS = ("traditional", "improved")

# the default radius plus the default margin (planner.maps.clearance)
DEFAULT_SAFETY_DISTANCE = Clearance().safety_distance


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
    profile: str = PAPER
    clearance: float | None = None
    """m, least distance from the key-node route to an obstacle square or the map border
    (measured exactly, up to CLEARANCE_CAP); None when no path was found."""

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
    profile: str = DEFAULT,
    clearance: Clearance | None = None,
    safety_distance: float | None = None,
    costmap: Costmap | None = None,
    corner_cutting: bool = False,
) -> PlanResult:
    """Plan from ``start`` to ``goal`` (world frame, metres).

    ``profile``: ``"default"`` (footprint-safe, the default everywhere) or ``"paper"``
    (the paper's definitions; module doc). ``clearance``: the AGV's radius
    and margin (default 0.3 m + 0.2 m); ``safety_distance`` may be given instead of the
    margin (radius + margin; below the radius it is an error). ``costmap``: a prebuilt
    costmap of ``grid`` for that clearance (default profile; else the map's cached one).
    ``corner_cutting`` exists only for the paper profile's comparisons with peers.

    Raises ``MapError`` when start or goal is outside the map or in an obstacle,
    ``ValueError`` for an unknown algorithm or profile. An unreachable goal is not an
    error: it gives a result with ``found == False``.
    """
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r}: choose one of {', '.join(ALGORITHMS)}")
    check_profile(profile)
    if safety_distance is not None:
        if safety_distance < 0:
            raise ValueError(f"safety distance must be >= 0, got {safety_distance}")
        radius = clearance.radius if clearance is not None else Clearance().radius
        clearance = clearance_for(radius, safety_distance=safety_distance)
    clearance = clearance or Clearance()
    if profile == DEFAULT:
        if corner_cutting:
            raise ValueError("corner cutting exists only in the paper profile")
        return _plan_costmap(grid, start, goal, algorithm, clearance, costmap)
    return _plan_paper(grid, start, goal, algorithm, clearance.safety_distance, corner_cutting)


def _no_path(algorithm, start, goal, expansions: int, t0: float, profile: str) -> PlanResult:
    """The result of a search that found no path (timed from ``t0``)."""
    elapsed = time.perf_counter() - t0
    return PlanResult(
        algorithm, start, goal, False, expansions=expansions, time_s=elapsed, profile=profile
    )


def _plan_paper(grid, start, goal, algorithm, safety_distance, corner_cutting) -> PlanResult:
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
        return _no_path(algorithm, start, goal, result.expansions, t0, PAPER)
    if algorithm == "improved":
        key_cells = extract_key_nodes(grid, result.cells, safety_distance)
    else:
        key_cells = drop_collinear(result.cells)
    elapsed = time.perf_counter() - t0
    gap = route_clearance(grid.blocked, key_cells, CLEARANCE_CAP / grid.resolution)
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
        profile=PAPER,
        clearance=gap * grid.resolution,
    )


def _plan_costmap(grid, start, goal, algorithm, clearance, costmap) -> PlanResult:
    start_cell = grid.free_cell_of(start, "start")
    goal_cell = grid.free_cell_of(goal, "goal")
    t0 = time.perf_counter()
    if costmap is None:
        costmap = Costmap.for_grid(grid, clearance)
    elif costmap.grid is not grid or costmap.clearance != clearance:
        raise ValueError("the costmap given is not the costmap of this map and clearance")
    result = search_costmap(costmap, start_cell, goal_cell, improved=algorithm == "improved")
    if not result.found:
        return _no_path(algorithm, start, goal, result.expansions, t0, DEFAULT)
    # the path runs from the exact start through the inner cell centres to the exact goal
    inner = result.cells[1:-1]
    points = np.array(
        [grid.to_cell_units(start), *inner, grid.to_cell_units(goal)], dtype=np.float64
    )
    res = grid.resolution
    world = [start, *(grid.centre_of(c) for c in inner), goal]
    if algorithm == "improved":
        keep = extract_key_nodes_costmap(
            grid.blocked, points, clearance.radius / res, clearance.margin / res
        )
        cap = (clearance.radius + clearance.margin) / res
        key_points = centred(grid.blocked, points[keep], cap, res)
        key_nodes = [start, *(grid.from_cell_units(p) for p in key_points[1:-1]), goal]
    else:
        keep = drop_collinear_points(points)
        key_points = points[keep]
        key_nodes = [world[i] for i in keep]
    elapsed = time.perf_counter() - t0
    gap = route_clearance(grid.blocked, key_points, CLEARANCE_CAP / res)
    return PlanResult(
        algorithm,
        start,
        goal,
        True,
        cells=result.cells,
        path=world,
        key_nodes=key_nodes,
        expansions=result.expansions,
        time_s=elapsed,
        profile=DEFAULT,
        clearance=gap * res,
    )


def warm_up() -> None:
    """Load the compiled search and key-node kernels (numba's on-disk cache, or a
    compile on the very first use) so that later plans time only the planning."""
    grid = GridMap(np.zeros((2, 3), dtype=bool))
    for algorithm in ALGORITHMS:
        for profile in (PAPER, DEFAULT):
            plan_global(grid, (0.5, 0.5), (2.5, 1.5), algorithm, profile=profile)
    # a straight route has no inner key node to centre: the centring kernel, too
    centred(grid.blocked, np.array([[0.5, 0.5], [1.5, 0.5], [2.5, 1.5]]), 1.0, 1.0)
