"""Occupancy grid in the world frame of DESIGN.md.

World frame: x right, y up, metres (ROS REP 103). ``origin`` (ox, oy) is the
world position of the map's bottom-left corner: for a ROS map_server map the
yaml ``origin``, so world coordinates are the ROS ``map`` frame as RViz shows
them; (0, 0) for text, matrix and MovingAI maps. Cell (col, row), row 0 at the
bottom, covers [ox + col*res, ox + (col+1)*res) x [oy + row*res, oy + (row+1)*res).
The array ``blocked`` is indexed ``[row, col]`` with row 0 the bottom row, so
``blocked[::-1]`` is the map as printed (top row first).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from planner.core.errors import MapError

Cell = tuple[int, int]
Point = tuple[float, float]


@dataclass(frozen=True)
class GridMap:
    """A 2-D occupancy grid. ``blocked[row, col]`` is True for an obstacle cell."""

    blocked: np.ndarray
    resolution: float = 1.0
    name: str = "map"
    origin: tuple[float, float] = (0.0, 0.0)
    _prefix: np.ndarray = field(init=False, repr=False, compare=False)
    # derived data built once per map (costmaps, passages, roadmaps by clearance): ``derived``
    cache: dict = field(init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        blocked = np.ascontiguousarray(self.blocked, dtype=bool)
        if blocked.ndim != 2 or blocked.shape[0] == 0 or blocked.shape[1] == 0:
            raise MapError(f"a map needs a non-empty 2-D grid, got shape {blocked.shape}")
        if not (self.resolution > 0 and math.isfinite(self.resolution)):
            raise MapError(f"map resolution must be a positive number, got {self.resolution}")
        try:
            origin = tuple(float(v) for v in self.origin)
        except (TypeError, ValueError):
            origin = ()
        if len(origin) != 2 or not all(math.isfinite(v) for v in origin):
            raise MapError(f"map origin must be two finite numbers (x, y), got {self.origin!r}")
        blocked.setflags(write=False)
        object.__setattr__(self, "blocked", blocked)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "_prefix", obstacle_prefix_sums(blocked))

    # --- construction -----------------------------------------------------------------
    @classmethod
    def from_rows_top_down(
        cls,
        rows: np.ndarray,
        resolution: float = 1.0,
        name: str = "map",
        origin: tuple[float, float] = (0.0, 0.0),
    ):
        """Build from a grid listed top row first (as text maps and images are printed)."""
        return cls(np.asarray(rows, dtype=bool)[::-1], resolution, name, origin)

    # --- size -------------------------------------------------------------------------
    @property
    def height(self) -> int:
        """Number of rows."""
        return int(self.blocked.shape[0])

    @property
    def width(self) -> int:
        """Number of columns."""
        return int(self.blocked.shape[1])

    @property
    def size_m(self) -> tuple[float, float]:
        """Extent (width, height) in metres."""
        return self.width * self.resolution, self.height * self.resolution

    @property
    def obstacle_ratio(self) -> float:
        return float(self.blocked.mean())

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the map in the world frame, metres."""
        w, h = self.size_m
        ox, oy = self.origin
        return ox, ox + w, oy, oy + h

    # --- frames -----------------------------------------------------------------------
    def cell_of(self, point: Point) -> Cell:
        """The (col, row) cell that contains a world point (no bounds check)."""
        return (
            math.floor((point[0] - self.origin[0]) / self.resolution),
            math.floor((point[1] - self.origin[1]) / self.resolution),
        )

    def centre_of(self, cell: Cell) -> Point:
        """World coordinates of a cell's centre."""
        return (
            self.origin[0] + (cell[0] + 0.5) * self.resolution,
            self.origin[1] + (cell[1] + 0.5) * self.resolution,
        )

    def to_cell_units(self, point: Point) -> Point:
        """A world point in cell units: cell (col, row)'s centre is (col, row)."""
        return (
            (point[0] - self.origin[0]) / self.resolution - 0.5,
            (point[1] - self.origin[1]) / self.resolution - 0.5,
        )

    def from_cell_units(self, point: Point) -> Point:
        """The world point of a point in cell units (the inverse of ``to_cell_units``)."""
        return (
            self.origin[0] + (point[0] + 0.5) * self.resolution,
            self.origin[1] + (point[1] + 0.5) * self.resolution,
        )

    def contains_cell(self, cell: Cell) -> bool:
        return 0 <= cell[0] < self.width and 0 <= cell[1] < self.height

    def contains_point(self, point: Point) -> bool:
        x0, x1, y0, y1 = self.extent
        return x0 <= point[0] < x1 and y0 <= point[1] < y1

    def is_free(self, cell: Cell) -> bool:
        """True for a cell inside the map that is not an obstacle."""
        return self.contains_cell(cell) and not self.blocked[cell[1], cell[0]]

    def free_cell_of(self, point: Point, what: str = "point") -> Cell:
        """The cell of ``point``; raises MapError naming ``what`` if it is outside or blocked."""
        x, y = point
        if not (math.isfinite(x) and math.isfinite(y)) or not self.contains_point(point):
            x0, x1, y0, y1 = self.extent
            raise MapError(
                f"{what} ({x:g}, {y:g}) is outside the map "
                f"(x in [{x0:g}, {x1:g}), y in [{y0:g}, {y1:g}) metres)"
            )
        cell = self.cell_of(point)
        if self.blocked[cell[1], cell[0]]:
            raise MapError(f"{what} ({x:g}, {y:g}) is inside an obstacle (cell {cell})")
        return cell

    # --- queries ----------------------------------------------------------------------
    def obstacles_in_rect(self, a: Cell, b: Cell) -> int:
        """Obstacle cells in the rectangle spanned by cells a and b (inclusive), O(1)."""
        c0, c1 = sorted((a[0], b[0]))
        r0, r1 = sorted((a[1], b[1]))
        p = self._prefix
        return int(p[r1 + 1, c1 + 1] - p[r0, c1 + 1] - p[r1 + 1, c0] + p[r0, c0])

    @property
    def prefix_sums(self) -> np.ndarray:
        """(H+1, W+1) int array: prefix[r, c] = obstacles in rows < r and cols < c."""
        return self._prefix

    def derived(self, key, build):
        """``build()``, built on first use and then kept with the map under ``key`` (maps
        are immutable, so every AGV of a run shares what is derived from its map)."""
        value = self.cache.get(key)
        if value is None:
            value = self.cache[key] = build()
        return value

    def with_blocked(self, cells) -> GridMap:
        """A copy with extra obstacle cells (col, row), e.g. temporary obstacles seen so far."""
        blocked = self.blocked.copy()
        for col, row in cells:
            if self.contains_cell((col, row)):
                blocked[row, col] = True
        return GridMap(blocked, self.resolution, self.name, self.origin)

    def to_text(self) -> str:
        """The grid as `.`/`#` rows, top row first."""
        return "\n".join("".join("#" if b else "." for b in row) for row in self.blocked[::-1])


def obstacle_prefix_sums(blocked: np.ndarray) -> np.ndarray:
    """2-D prefix sums of obstacle cells, padded with a zero row and column."""
    prefix = np.zeros((blocked.shape[0] + 1, blocked.shape[1] + 1), dtype=np.int64)
    prefix[1:, 1:] = np.cumsum(np.cumsum(blocked, axis=0, dtype=np.int64), axis=1)
    return prefix


def cells_in_disc(grid: GridMap, centre: Point, radius: float) -> set[Cell]:
    """The cells of ``grid`` whose square a disc overlaps (an AGV body as obstacle cells)."""
    col0, row0 = grid.cell_of((centre[0] - radius, centre[1] - radius))
    col1, row1 = grid.cell_of((centre[0] + radius, centre[1] + radius))
    res, (ox, oy) = grid.resolution, grid.origin
    cells = set()
    for col in range(max(col0, 0), min(col1, grid.width - 1) + 1):
        for row in range(max(row0, 0), min(row1, grid.height - 1) + 1):
            nx = min(max(centre[0], ox + col * res), ox + (col + 1) * res)
            ny = min(max(centre[1], oy + row * res), oy + (row + 1) * res)
            if math.hypot(nx - centre[0], ny - centre[1]) < radius:
                cells.add((col, row))
    return cells
