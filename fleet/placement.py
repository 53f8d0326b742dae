"""Where an AGV's body may stand: a start, a goal, a station."""

from __future__ import annotations

import math

from fleet.toml_schema import ScenarioError
from planner.core.errors import MapError
from planner.maps.clearance import keeps
from planner.maps.costmap import point_clearance
from planner.maps.grid import GridMap, Point


def check_room(grid: GridMap, point: Point, radius: float, who: str, what: str) -> None:
    """A ScenarioError naming ``who``'s ``what`` unless ``point`` is on a free cell at
    least ``radius`` from every obstacle and the map's edge."""
    try:
        grid.free_cell_of(point, what)
    except MapError as err:
        raise ScenarioError(f"{who}: {err}") from None
    room = point_clearance(grid, point, radius)
    if not keeps(room, radius):
        shown = math.floor(room * 1e4 + 1e-6) / 1e4  # not rounded up to the radius
        raise ScenarioError(
            f"{who}: {what} ({point[0]:g}, {point[1]:g}) is {shown:.4f} m from an obstacle "
            f"or the map's edge, less than the AGV radius {radius:g} m"
        )
