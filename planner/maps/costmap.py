"""The costmap of the default profile: where an AGV of a given radius fits, and where it
would rather not go (after Nav2 costmap_2d's inflation layer).

For every cell, ``distance`` is the exact Euclidean distance from the cell's centre to
the nearest obstacle *square* (its edges, not its centre) or to the map's border
(outside the map counts as obstacle). Then, for an AGV of radius r and margin m:

- lethal: distance < r (up to float rounding, ``clearance.keeps``). An AGV centred
  there would overlap an obstacle (Nav2's "inscribed" cost, lethal for a round robot).
  Obstacle cells have distance 0.
- penalty: a cost that decays linearly from ``COST_WEIGHT`` at distance r to 0 at
  r + m (Nav2 decays exponentially out to its inflation radius). A search step into a
  cell costs its length times (1 + penalty), so routes keep off walls where there is
  room and keep to the middle of passages narrower than 2 (r + m).

Why this is enough for the AGV's body on the grid: a search that enters only non-lethal
cells and takes a diagonal step only when both side cells are non-lethal keeps at least
r from every obstacle square along its whole polyline of cell centres, not only at the
centres (squares have half-integer edges, so along each half-step the distance to a
square is smallest at an end: a cell centre or a corner shared by four non-lethal cells,
and such a corner is never closer to a square than the nearest of those four centres).

``Costmap.for_grid`` builds a costmap once per map and clearance and keeps it in the
map's cache (every AGV of a run shares it); ``with_blocked`` is the costmap of the map
plus temporary obstacles seen so far. The build is O(cells): two passes of an exact
distance transform on a half-cell lattice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.core.errors import MapError
from planner.maps.clearance import Clearance, keeps
from planner.maps.distance_field import edt_1d
from planner.maps.grid import Cell, GridMap, Point
from planner.maps.segment_clearance import route_clearance

COST_WEIGHT = 1.0
"""Penalty at the lethal edge: a step there costs (1 + COST_WEIGHT) times its length."""


@dataclass(frozen=True, eq=False)
class Costmap:
    """Lethal cells and step penalties of one map for one AGV clearance (see module doc)."""

    grid: GridMap
    clearance: Clearance
    distance: np.ndarray  # (H, W) float64, metres, centre -> nearest obstacle square/border
    lethal: np.ndarray  # (H, W) bool
    penalty: np.ndarray  # (H, W) float64 >= 0

    @classmethod
    def build(cls, grid: GridMap, clearance: Clearance) -> Costmap:
        """A new costmap of ``grid`` (no cache; see ``for_grid``)."""
        distance = centre_distances(grid.blocked) * grid.resolution
        lethal, penalty = _costs(distance, clearance)
        for array in (distance, lethal, penalty):
            array.setflags(write=False)
        return cls(grid, clearance, distance, lethal, penalty)

    @classmethod
    def for_grid(cls, grid: GridMap, clearance: Clearance) -> Costmap:
        """The costmap of ``grid`` for ``clearance``, built on first use and then cached
        with the map (maps are immutable)."""
        return grid.derived(("costmap", clearance), lambda: cls.build(grid, clearance))

    def with_blocked(self, cells) -> Costmap:
        """The costmap of the map plus obstacle cells (col, row): temporary obstacles sensed.

        The result is cached with the new map, so planning on it again reuses it."""
        cells = list(cells)
        if not cells:
            return self
        grid = self.grid.with_blocked(cells)
        return Costmap.for_grid(grid, self.clearance)

    # --- queries --------------------------------------------------------------------
    def is_lethal(self, cell: Cell) -> bool:
        return bool(self.lethal[cell[1], cell[0]])

    def passable(self, start: Cell, goal: Cell) -> np.ndarray:
        """(H, W) uint8, 1 where a search may not enter: the lethal cells, except an escape
        from a start or goal cell that lies inside the lethal band but not in an obstacle.

        An AGV that DWA has brought closer to a wall than its radius (or a goal given
        there) must still be able to plan: from such a cell the cells reachable by steps
        that strictly increase the distance to obstacles are opened, which leads out of
        the band the shortest way and never along it (so never through a gap the body
        does not fit). An obstacle cell stays closed: a MapError there.
        """
        state = self.lethal.view(np.uint8).copy()
        for what, cell in (("start", start), ("goal", goal)):
            if self.grid.blocked[cell[1], cell[0]]:
                raise MapError(f"{what} cell {cell} is an obstacle cell")
            if state[cell[1], cell[0]]:
                _open_escape(state, self.distance, cell[0], cell[1])
        return state


def point_clearance(grid: GridMap, point: Point, cap: float) -> float:
    """Exact distance (m) from a world point to the nearest obstacle square or the map's
    edge, or ``cap`` itself if it is farther (not ``cap`` turned into cells and back,
    which can round below it)."""
    cap_cells = cap / grid.resolution
    cells = route_clearance(grid.blocked, [grid.to_cell_units(point)], cap_cells)
    return cap if cells >= cap_cells else cells * grid.resolution


def _costs(distance: np.ndarray, clearance: Clearance) -> tuple[np.ndarray, np.ndarray]:
    radius, margin = clearance.radius, clearance.margin
    lethal = ~keeps(distance, radius)
    if margin > 0:
        penalty = COST_WEIGHT * np.clip((radius + margin - distance) / margin, 0.0, 1.0)
    else:
        penalty = np.zeros_like(distance)
    penalty[lethal] = COST_WEIGHT
    return lethal, penalty


@numba.njit(cache=True)
def _open_escape(state, distance, col, row):
    """Open (state 0) the lethal cells reachable from (col, row) by strictly rising distance."""
    height, width = state.shape
    stack = [(col, row)]
    state[row, col] = 0
    while stack:
        c, r = stack.pop()
        here = distance[r, c]
        for dc in (-1, 0, 1):
            for dr in (-1, 0, 1):
                cc = c + dc
                rr = r + dr
                if (dc == 0 and dr == 0) or cc < 0 or cc >= width or rr < 0 or rr >= height:
                    continue
                if state[rr, cc] == 1 and distance[rr, cc] > here:
                    state[rr, cc] = 0
                    stack.append((cc, rr))


@numba.njit(cache=True)
def centre_distances(blocked):
    """(H, W) exact distance, in cells, from each cell centre to the nearest obstacle
    square or the map border (an obstacle cell gives 0).

    Pass 1, per column: k = rows to the nearest obstacle cell in the column (the rows
    beyond the border count), so the vertical gap to its square is k - 1/2. Pass 2, per
    row, an exact 1-D distance transform (Felzenszwalb & Huttenlocher) on a half-cell
    lattice whose points are the cell edges and centres: a square of column a covers
    lattice points 2a..2a+2, so the horizontal gap from a centre to it is also exact.
    """
    height, width = blocked.shape
    vertical = np.empty((height, width))  # (2 * vertical gap)^2, in half cells squared
    for c in range(width):
        last = -1  # the row beyond the bottom border
        for r in range(height):
            if blocked[r, c]:
                last = r
            vertical[r, c] = r - last
        last = height  # the row beyond the top border
        for r in range(height - 1, -1, -1):
            if blocked[r, c]:
                last = r
            k = min(vertical[r, c], last - r)
            vertical[r, c] = 0.0 if k == 0 else (2.0 * k - 1.0) ** 2
    n = 2 * width + 1
    f = np.empty(n)
    line = np.empty(n)
    v = np.empty(n, dtype=np.int64)
    z = np.empty(n + 1)
    out = np.empty((height, width))
    for r in range(height):
        f[:] = np.inf
        f[0] = 0.0  # the left border
        f[n - 1] = 0.0  # the right border
        for a in range(width):
            g = vertical[r, a]
            for q in range(2 * a, 2 * a + 3):
                if g < f[q]:
                    f[q] = g
        for q in range(n):  # finite stand-in for "no obstacle": keeps the envelope exact
            if f[q] == np.inf:
                f[q] = 1e20
        edt_1d(f, line, v, z)
        for a in range(width):
            out[r, a] = np.sqrt(line[2 * a + 1]) * 0.5
    return out
