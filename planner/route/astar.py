"""Grid A* search: the traditional algorithm and the paper's improved variant.

One compiled search loop serves both (numba, cached on disk), because the
1000x1000 maps of the benchmarks need ~10^5–10^6 expansions and a Python heap
loop costs ~1 µs per push. The variants differ only in three switches:

- traditional: 8 neighbours, f = g + h.
- improved (Guo et al. 2023, section 2.3): f = g + exp(p/k)·h, where
  k = cells in the rectangle spanned by start and goal and p = obstacle cells
  in the rectangle spanned by the node and the goal (O(1) from 2-D prefix
  sums); hybrid neighbourhood: a node with an obstacle among its 4 orthogonal
  neighbours expands only those 4, otherwise all 8.

Step costs are 1 and sqrt(2) cells, the heuristic is Euclidean. A diagonal
step needs both orthogonal side cells free (no corner cutting) unless
``corner_cutting`` is set, which exists only to compare with peers that allow
it. Outside the map counts as obstacle, as it does for DWA and the world's
collision check: a node on the map border expands 4 neighbours.
With the inflated heuristic of the improved variant a closed node is never
reopened (weighted-A* practice); the path is then not necessarily optimal.
Ties on f are broken towards the smaller h (deeper nodes first).

``search`` is the paper's search on the map's obstacle cells (profile ``paper``).
``search_costmap`` is the same search on a costmap (profile ``default``, see
planner.maps.costmap): the lethal cells take the obstacles' place for moving (no entry,
no diagonal past one, the hybrid rule's "obstacle among the 4 neighbours"), and a
step into a cell costs its length times (1 + the cell's penalty). Eq. (3)'s p still
counts the map's obstacle cells and k the cells of the start-goal rectangle. The
heuristic stays the Euclidean distance in cells, admissible since penalties are >= 0,
so the traditional search is optimal on the costmap.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numba
import numpy as np

from planner.maps.costmap import Costmap
from planner.maps.grid import Cell, GridMap

SQRT2 = math.sqrt(2.0)

# neighbour offsets: the 4 orthogonal first, then the 4 diagonals
_DCOL = np.array([1, 0, -1, 0, 1, -1, -1, 1], dtype=np.int64)
_DROW = np.array([0, 1, 0, -1, 1, 1, -1, -1], dtype=np.int64)


@dataclass(frozen=True)
class SearchResult:
    """Outcome of one grid search. ``cells`` is empty when no path exists."""

    cells: list[Cell]
    expansions: int
    time_s: float

    @property
    def found(self) -> bool:
        return bool(self.cells)


_NO_PENALTY = np.zeros((1, 1))  # the plain map's steps cost their length


def _result(path, expansions, width: int, t0: float) -> SearchResult:
    """The kernel's path of flat indices as (col, row) cells, timed from ``t0``."""
    elapsed = time.perf_counter() - t0
    cells = [(int(i % width), int(i // width)) for i in path]
    return SearchResult(cells, int(expansions), elapsed)


def search(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    *,
    improved: bool = False,
    corner_cutting: bool = False,
) -> SearchResult:
    """A* from start to goal cell (col, row); both must be free cells of the map."""
    for what, cell in (("start", start), ("goal", goal)):
        if not grid.is_free(cell):
            raise ValueError(f"{what} cell {cell} is not a free cell of the map")
    blocked = grid.blocked.view(np.uint8)
    t0 = time.perf_counter()
    path, expansions = _astar(
        blocked,
        _NO_PENALTY,
        grid.prefix_sums,
        int(start[0]),
        int(start[1]),
        int(goal[0]),
        int(goal[1]),
        improved,
        corner_cutting,
        False,
    )
    return _result(path, expansions, grid.width, t0)


def search_costmap(
    costmap: Costmap, start: Cell, goal: Cell, *, improved: bool = False
) -> SearchResult:
    """A* on a costmap from start to goal cell (col, row). A start or goal inside the
    lethal band gets an escape out of it (``Costmap.passable``); one in an obstacle cell
    is a MapError."""
    grid = costmap.grid
    for what, cell in (("start", start), ("goal", goal)):
        if not grid.contains_cell(cell):
            raise ValueError(f"{what} cell {cell} is outside the map")
    t0 = time.perf_counter()
    closed = costmap.passable(start, goal)
    path, expansions = _astar(
        closed,
        costmap.penalty,
        grid.prefix_sums,
        int(start[0]),
        int(start[1]),
        int(goal[0]),
        int(goal[1]),
        improved,
        False,
        True,
    )
    return _result(path, expansions, grid.width, t0)


# The open list is a binary heap of rows (f, h, node) in one (capacity, 3) array:
# one cache line per entry makes it ~2x faster than three parallel arrays.
@numba.njit(cache=True)
def _heap_push(heap, size, f, h, node):
    if size == heap.shape[0]:
        grown = np.empty((2 * heap.shape[0], 3), np.float64)
        grown[:size] = heap[:size]
        heap = grown
    i = size
    while i > 0:
        up = (i - 1) >> 1
        uf = heap[up, 0]
        if not (f < uf or (f == uf and h < heap[up, 1])):
            break
        heap[i, 0] = uf
        heap[i, 1] = heap[up, 1]
        heap[i, 2] = heap[up, 2]
        i = up
    heap[i, 0] = f
    heap[i, 1] = h
    heap[i, 2] = node
    return heap, size + 1


@numba.njit(cache=True)
def _heap_pop(heap, size):
    top = int(heap[0, 2])
    size -= 1
    f = heap[size, 0]
    h = heap[size, 1]
    node = heap[size, 2]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        right = child + 1
        if right < size and (
            heap[right, 0] < heap[child, 0]
            or (heap[right, 0] == heap[child, 0] and heap[right, 1] < heap[child, 1])
        ):
            child = right
        cf = heap[child, 0]
        if not (cf < f or (cf == f and heap[child, 1] < h)):
            break
        heap[i, 0] = cf
        heap[i, 1] = heap[child, 1]
        heap[i, 2] = heap[child, 2]
        i = child
    heap[i, 0] = f
    heap[i, 1] = h
    heap[i, 2] = node
    return top, size


@numba.njit(cache=True)
def _astar(blocked, penalty, prefix, sc, sr, gc, gr, improved, corner_cutting, weighted):
    """The one A* kernel. ``blocked`` (uint8) is 1 where no step may enter: the map's
    obstacles, or a costmap's lethal cells, which then also stand for obstacles in the
    hybrid rule and the diagonal rule. ``weighted``: a step into cell n costs its length
    times (1 + penalty[n]) (a costmap); otherwise its length (``penalty`` unused)."""
    height, width = blocked.shape
    n = height * width
    g = np.full(n, np.inf)
    parent = np.full(n, -1, np.int32)
    # one byte per cell: 0 open or unseen, 1 obstacle, 2 closed (one load per neighbour)
    state = blocked.ravel().copy()
    heap = np.empty((4096, 3), np.float64)
    size = 0
    # k of Eq. (3): cells of the rectangle spanned by start and goal
    k = float((abs(gc - sc) + 1) * (abs(gr - sr) + 1))

    start = sr * width + sc
    goal = gr * width + gc
    g[start] = 0.0
    h0 = math.sqrt(float((gc - sc) ** 2 + (gr - sr) ** 2))
    heap, size = _heap_push(heap, size, h0, h0, start)
    expansions = 0
    while size > 0:
        node, size = _heap_pop(heap, size)
        if state[node] == 2:
            continue
        state[node] = 2
        if node == goal:
            break
        expansions += 1
        r = node // width
        c = node - r * width
        g_node = g[node]
        n_dirs = 8
        if improved:
            for d in range(4):
                cc = c + _DCOL[d]
                rr = r + _DROW[d]
                if cc < 0 or cc >= width or rr < 0 or rr >= height or blocked[rr, cc]:
                    n_dirs = 4
                    break
        for d in range(n_dirs):
            cc = c + _DCOL[d]
            rr = r + _DROW[d]
            if cc < 0 or cc >= width or rr < 0 or rr >= height:
                continue
            nb = rr * width + cc
            if state[nb]:
                continue
            if d >= 4:
                if not corner_cutting and (blocked[r, cc] or blocked[rr, c]):
                    continue
                step = SQRT2
            else:
                step = 1.0
            ng = g_node + (step * (1.0 + penalty[rr, cc]) if weighted else step)
            if ng >= g[nb]:
                continue
            g[nb] = ng
            parent[nb] = node
            h = math.sqrt(float((gc - cc) ** 2 + (gr - rr) ** 2))
            if improved:
                c0 = min(cc, gc)
                c1 = max(cc, gc)
                r0 = min(rr, gr)
                r1 = max(rr, gr)
                p = (
                    prefix[r1 + 1, c1 + 1]
                    - prefix[r0, c1 + 1]
                    - prefix[r1 + 1, c0]
                    + prefix[r0, c0]
                )
                h = math.exp(p / k) * h
            heap, size = _heap_push(heap, size, ng + h, h, nb)

    if state[goal] != 2:
        return np.empty(0, np.int64), expansions
    length = 1
    node = goal
    while node != start:
        node = parent[node]
        length += 1
    path = np.empty(length, np.int64)
    node = goal
    for i in range(length - 1, -1, -1):
        path[i] = node
        node = parent[node]
    return path, expansions
