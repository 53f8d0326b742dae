"""The roadmap the reservations are made on: a 4-connected lattice derived from the costmap.

Nodes are the cells of a lattice whose centre the AGV's body fits (not lethal in the
costmap of the fleet's widest clearance). The lattice spacing is the fewest cells that
hold two bodies side by side with ``GAP`` between them (2 r + GAP), so that two AGVs on
adjacent nodes never touch: on a MovingAI map of 1 m cells with 0.3 m AGVs every free
cell is a node, and a one-cell aisle is a chain of nodes. Two lattice neighbours are
joined when every cell between them fits the body too. Nothing is drawn by hand.

An AGV *reaches* a node when its centre is within ``reach`` of the node's centre:
then it is at least ``spacing - reach`` from every neighbour's centre, so an AGV
stopped on a neighbour keeps ``GAP`` from it (``planner.traffic.precedence`` lets the
next AGV in only then).

Distances to a goal (BFS over the nodes, avoiding blocked ones: AGVs stopped for good)
are computed once per goal and set of blocked nodes and cached on the roadmap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.grid import GridMap, Point

GAP = 0.1
"""m, the least room between two AGVs on adjacent nodes."""
UNREACHABLE = np.iinfo(np.int32).max
"""The distance of a node from which the goal cannot be reached."""
# the four lattice directions, in a fixed order (east, north, west, south)
DIRECTIONS = ((1, 0), (0, 1), (-1, 0), (0, -1))


@dataclass(eq=False)
class Roadmap:
    """Nodes (lattice cells), their centres and 4-neighbours; see the module docstring."""

    costmap: Costmap
    spacing: int  # lattice step in cells
    cells: np.ndarray  # (n, 2) int: (col, row) of each node
    centres: np.ndarray  # (n, 2) float: world point of each node
    neighbours: np.ndarray  # (n, 4) int32: node ids in DIRECTIONS, -1 none
    index: np.ndarray  # (H, W) int32: the node of a lattice cell, -1 none
    reach: float  # m, how near a node's centre an AGV has reached it
    _distances: dict = field(default_factory=dict, repr=False)

    @classmethod
    def for_costmap(cls, costmap: Costmap) -> Roadmap:
        """The roadmap of a costmap, built once and cached with its map."""
        return costmap.grid.derived(("roadmap", costmap.clearance), lambda: cls.build(costmap))

    @classmethod
    def for_fleet(cls, grid: GridMap, clearances: list[Clearance]) -> Roadmap:
        """The one roadmap of a fleet: on the costmap of its widest clearance."""
        widest = Clearance(max(c.radius for c in clearances), max(c.margin for c in clearances))
        return cls.for_costmap(Costmap.for_grid(grid, widest))

    @staticmethod
    def spacing_for(grid: GridMap, radius: float) -> int:
        """The lattice step (cells) for bodies of ``radius``: see the module docstring."""
        return max(1, math.ceil((2 * radius + GAP) / grid.resolution - 1e-9))

    @classmethod
    def build(cls, costmap: Costmap) -> Roadmap:
        grid, radius = costmap.grid, costmap.clearance.radius
        spacing = cls.spacing_for(grid, radius)
        fits = ~costmap.lethal
        index = np.full(fits.shape, -1, dtype=np.int32)
        rows, cols = np.nonzero(fits[::spacing, ::spacing])
        rows, cols = rows * spacing, cols * spacing
        order = np.lexsort((cols, rows))  # row by row from the bottom, then by column
        rows, cols = rows[order], cols[order]
        index[rows, cols] = np.arange(len(rows), dtype=np.int32)
        neighbours = _neighbours(index, fits, cols.astype(np.int64), rows.astype(np.int64), spacing)
        centres = np.array([grid.centre_of((int(c), int(r))) for c, r in zip(cols, rows)])
        reach = max(0.05, spacing * grid.resolution - 2 * radius - GAP)
        cells = np.stack([cols, rows], axis=1) if len(cols) else np.zeros((0, 2), dtype=int)
        return cls(costmap, spacing, cells, centres.reshape(-1, 2), neighbours, index, reach)

    def __len__(self) -> int:
        return len(self.cells)

    def node_at(self, point: Point) -> int | None:
        """The node nearest ``point`` among those of its lattice neighbourhood (None: no
        node within a lattice step)."""
        grid = self.costmap.grid
        col, row = grid.cell_of(point)
        s = self.spacing
        best, best_d = None, math.inf
        for c in range((col // s - 1) * s, (col // s + 2) * s + 1, s):
            for r in range((row // s - 1) * s, (row // s + 2) * s + 1, s):
                if 0 <= c < grid.width and 0 <= r < grid.height and self.index[r, c] >= 0:
                    node = int(self.index[r, c])
                    d = math.dist(point, self.centres[node])
                    if d < best_d:
                        best, best_d = node, d
        return best

    def centre(self, node: int) -> Point:
        x, y = self.centres[node]
        return (float(x), float(y))

    def distances(self, goal: int, blocked: frozenset[int] = frozenset()) -> np.ndarray:
        """Steps from every node to ``goal`` avoiding ``blocked`` nodes (UNREACHABLE: no
        way), cached per goal and blocked set."""
        key = (goal, blocked)
        table = self._distances.get(key)
        if table is None:
            mask = np.zeros(len(self), dtype=np.bool_)
            if blocked:
                mask[list(blocked)] = True
            table = _bfs(self.neighbours, mask, goal)
            table.setflags(write=False)
            if len(self._distances) > 4096:  # blocked sets change as AGVs park: bounded
                self._distances.clear()
            self._distances[key] = table
        return table


@numba.njit(cache=True)
def _neighbours(index, fits, cols, rows, spacing):
    height, width = index.shape
    out = np.full((len(cols), 4), -1, dtype=np.int32)
    steps = ((1, 0), (0, 1), (-1, 0), (0, -1))
    for n in range(len(cols)):
        for d in range(4):
            dc, dr = steps[d]
            c, r = cols[n] + dc * spacing, rows[n] + dr * spacing
            if not (0 <= c < width and 0 <= r < height) or index[r, c] < 0:
                continue
            clear = True
            for k in range(1, spacing):
                if not fits[rows[n] + dr * k, cols[n] + dc * k]:
                    clear = False
            if clear:
                out[n, d] = index[r, c]
    return out


@numba.njit(cache=True)
def _bfs(neighbours, blocked, goal):
    n = len(neighbours)
    dist = np.full(n, np.iinfo(np.int32).max, dtype=np.int32)
    if blocked[goal]:
        return dist
    queue = np.empty(n, dtype=np.int32)
    dist[goal], queue[0] = 0, goal
    head, tail = 0, 1
    while head < tail:
        node = queue[head]
        head += 1
        for d in range(4):
            nb = neighbours[node, d]
            if nb >= 0 and not blocked[nb] and dist[nb] == np.iinfo(np.int32).max:
                dist[nb] = dist[node] + 1
                queue[tail] = nb
                tail += 1
    return dist
