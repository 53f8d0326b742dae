"""Key-node extraction (Guo et al. 2023, section 2.3.3).

First collinear nodes are dropped. Then, from each kept node P_i, the segment
to P_{i+2} is tried: if every obstacle cell centre lies farther than the
safety distance from it, P_{i+1} is redundant and dropped (and the next node
is tried from P_i again); otherwise P_{i+1} is a key node and becomes the new
P_i. Beyond the paper, a shortcut must also keep to free cells: it may not
touch an obstacle cell's square (so it crosses no blocked corner) whatever the
safety distance, which makes every returned segment drivable on the grid.

Work happens in cell units (cell centres at integer coordinates); the segment
test only visits the band of cells near the segment, so it costs
O(length x safety distance), not O(map).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.grid_map import Cell, GridMap

# a segment closer than this to an obstacle square counts as touching it
_TOUCH_EPS = 1e-9


def drop_collinear(cells: list[Cell]) -> list[Cell]:
    """Keep the start, the goal and every node where the direction changes."""
    if len(cells) < 3:
        return list(cells)
    kept = [cells[0]]
    for prev, node, nxt in zip(cells, cells[1:], cells[2:], strict=False):
        d1 = (node[0] - prev[0], node[1] - prev[1])
        d2 = (nxt[0] - node[0], nxt[1] - node[1])
        if d1[0] * d2[1] - d1[1] * d2[0] != 0 or d1[0] * d2[0] + d1[1] * d2[1] <= 0:
            kept.append(node)
    kept.append(cells[-1])
    return kept


def extract_key_nodes(grid: GridMap, cells: list[Cell], safety_distance: float) -> list[Cell]:
    """Start, key nodes and goal of a cell path; ``safety_distance`` in metres."""
    nodes = drop_collinear(cells)
    safety_cells = safety_distance / grid.resolution
    blocked = grid.blocked.view(np.uint8)
    i = 0
    while i + 2 < len(nodes):
        a, c = nodes[i], nodes[i + 2]
        if segment_is_clear(
            blocked, float(a[0]), float(a[1]), float(c[0]), float(c[1]), safety_cells
        ):
            del nodes[i + 1]
        else:
            i += 1
    return nodes


def segment_clear(grid: GridMap, a: Cell, b: Cell, safety_distance: float) -> bool:
    """Whether the segment between two cell centres is a safe shortcut (see module doc)."""
    return bool(
        segment_is_clear(
            grid.blocked.view(np.uint8),
            float(a[0]),
            float(a[1]),
            float(b[0]),
            float(b[1]),
            safety_distance / grid.resolution,
        )
    )


@numba.njit(cache=True)
def _point_segment_distance(px, py, x0, y0, x1, y1):
    dx = x1 - x0
    dy = y1 - y0
    len2 = dx * dx + dy * dy
    t = 0.0
    if len2 > 0.0:
        t = ((px - x0) * dx + (py - y0) * dy) / len2
        t = min(1.0, max(0.0, t))
    ex = x0 + t * dx - px
    ey = y0 + t * dy - py
    return math.sqrt(ex * ex + ey * ey)


@numba.njit(cache=True)
def _segment_touches_box(x0, y0, x1, y1, bx0, by0, bx1, by1):
    """Liang–Barsky: does the segment meet the closed box?"""
    t0 = 0.0
    t1 = 1.0
    dx = x1 - x0
    dy = y1 - y0
    for p, q in ((-dx, x0 - bx0), (dx, bx1 - x0), (-dy, y0 - by0), (dy, by1 - y0)):
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            r = q / p
            if p < 0.0:
                t0 = max(t0, r)
            else:
                t1 = min(t1, r)
            if t0 > t1:
                return False
    return True


@numba.njit(cache=True)
def segment_is_clear(blocked, x0, y0, x1, y1, safety):
    """Segment between cell centres (x=col, y=row) keeps > safety from every obstacle
    centre and touches no obstacle square.

    Outside the map counts as obstacle: the ring of cells just beyond the border
    is checked like obstacle cells (cells farther out are farther from any
    segment inside the map).
    """
    height, width = blocked.shape
    reach = max(safety, 0.5 * math.sqrt(2.0)) + 1.0  # band half-width in cells
    c_lo = max(-1, math.floor(min(x0, x1) - reach))
    c_hi = min(width, math.ceil(max(x0, x1) + reach))
    h = 0.5 + _TOUCH_EPS
    for c in range(c_lo, c_hi + 1):
        # rows the band can reach in this column
        if x0 == x1:
            ya = min(y0, y1)
            yb = max(y0, y1)
        else:
            ta = (c - reach - x0) / (x1 - x0)
            tb = (c + reach - x0) / (x1 - x0)
            t_lo = max(0.0, min(ta, tb))
            t_hi = min(1.0, max(ta, tb))
            if t_lo > t_hi:
                continue
            ya = min(y0 + t_lo * (y1 - y0), y0 + t_hi * (y1 - y0))
            yb = max(y0 + t_lo * (y1 - y0), y0 + t_hi * (y1 - y0))
        r_lo = max(-1, math.floor(ya - reach))
        r_hi = min(height, math.ceil(yb + reach))
        for r in range(r_lo, r_hi + 1):
            outside = c < 0 or c >= width or r < 0 or r >= height
            if not outside and not blocked[r, c]:
                continue
            if _point_segment_distance(c, r, x0, y0, x1, y1) <= safety:
                return False
            if _segment_touches_box(x0, y0, x1, y1, c - h, r - h, c + h, r + h):
                return False
    return True
