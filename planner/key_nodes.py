"""Key-node extraction (Guo et al. 2023, section 2.3.3): the paper's, and footprint-safe.

Profile ``paper`` (``extract_key_nodes``): first collinear nodes are dropped. Then,
from each kept node P_i, the segment to P_{i+2} is tried: if every obstacle cell
centre lies farther than the safety distance from it, P_{i+1} is redundant and
dropped (and the next node is tried from P_i again); otherwise P_{i+1} is a key
node and becomes the new P_i. Beyond the paper, a shortcut must also keep to free
cells: it may not touch an obstacle cell's square (so it crosses no blocked corner)
whatever the safety distance, which makes every returned segment drivable on the grid.

Profile ``default`` (``extract_key_nodes_costmap``): the same greedy walk, but the
test is measured against obstacle *squares* (and the map border) with the AGV's
radius r and margin m. With c_path the least clearance of the path that a shortcut
P_i -> P_{i+2} would replace (the original search path between them, so that
clearance cannot erode shortcut after shortcut), the shortcut is taken only if its
least clearance c keeps

- c >= min(r, c_path): the body never touches an obstacle (and a path that starts
  inside the lethal band, where the AGV already is, is never made worse), and
- c >= min(r + m, c_path) - MARGIN_SLACK * m: the margin where the space allows, less
  a slack that lets a shortcut cut the corner of the margin zone round an obstacle
  corner (without it a fine map's route would keep every step of the arc there).

Work happens in cell units (cell centres at integer coordinates); the segment
tests only visit the band of cells near the segment, so they cost
O(length x safety distance), not O(map).
"""

from __future__ import annotations

import itertools
import math

import numba
import numpy as np

from planner.grid_map import Cell, GridMap

# a segment closer than this to an obstacle square counts as touching it
_TOUCH_EPS = 1e-9
MARGIN_SLACK = 0.5
"""Fraction of the margin a default-profile shortcut may cut into (see module doc)."""
_EPS = 1e-9


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


@numba.njit(cache=True)
def _band_rows(c, x0, y0, x1, y1, reach, height):
    """The rows (first, last; first > last: none) of column ``c`` that lie within
    ``reach`` cells of segment (x0, y0)-(x1, y1), the rows beyond the border included."""
    if x0 == x1:
        ya = min(y0, y1)
        yb = max(y0, y1)
    else:
        ta = (c - reach - x0) / (x1 - x0)
        tb = (c + reach - x0) / (x1 - x0)
        t_lo = max(0.0, min(ta, tb))
        t_hi = min(1.0, max(ta, tb))
        if t_lo > t_hi:
            return 0, -1
        ya = min(y0 + t_lo * (y1 - y0), y0 + t_hi * (y1 - y0))
        yb = max(y0 + t_lo * (y1 - y0), y0 + t_hi * (y1 - y0))
    return max(-1, math.floor(ya - reach)), min(height, math.ceil(yb + reach))


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
        r_lo, r_hi = _band_rows(c, x0, y0, x1, y1, reach, height)
        for r in range(r_lo, r_hi + 1):
            outside = c < 0 or c >= width or r < 0 or r >= height
            if not outside and not blocked[r, c]:
                continue
            if _point_segment_distance(c, r, x0, y0, x1, y1) <= safety:
                return False
            if _segment_touches_box(x0, y0, x1, y1, c - h, r - h, c + h, r + h):
                return False
    return True


# --- the default profile: clearance to obstacle squares -------------------------------
def drop_collinear_points(points: np.ndarray) -> list[int]:
    """Indices of the first point, the last and every point where the direction changes
    (points in cell units; repeated points are dropped)."""
    pts = np.asarray(points, dtype=float)
    if len(pts) < 3:
        return list(range(len(pts)))
    kept = [0]
    for j in range(1, len(pts) - 1):
        prev = pts[kept[-1]]
        d1 = pts[j] - prev
        d2 = pts[j + 1] - pts[j]
        if not d1.any():
            continue
        cross = d1[0] * d2[1] - d1[1] * d2[0]
        dot = d1[0] * d2[0] + d1[1] * d2[1]
        if abs(cross) > _EPS * (1.0 + abs(dot)) or dot <= 0.0:
            kept.append(j)
    if pts[-1].tolist() != pts[kept[-1]].tolist() or len(kept) == 1:
        kept.append(len(pts) - 1)
    return kept


def extract_key_nodes_costmap(
    blocked: np.ndarray, points: np.ndarray, radius: float, margin: float
) -> list[int]:
    """Indices into ``points`` (a search path in cell units, start and goal exact) of the
    start, the key nodes and the goal; ``radius`` and ``margin`` in cells (module doc)."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    kept = drop_collinear_points(pts)
    if len(kept) < 3:
        return kept
    blocked = blocked.view(np.uint8)
    cap = radius + margin
    along = np.array(
        [segment_clearance(blocked, *pts[a], *pts[b], cap) for a, b in itertools.pairwise(kept)]
    )
    # c_path of a shortcut: the least clearance of the original path between its ends
    position = {index: n for n, index in enumerate(kept)}
    nodes = list(kept)
    slack = MARGIN_SLACK * margin
    i = 0
    while i + 2 < len(nodes):
        a, c = nodes[i], nodes[i + 2]
        path_clearance = float(along[position[a] : position[c]].min())
        needed = max(min(radius, path_clearance), min(cap, path_clearance) - slack)
        if segment_clearance(blocked, *pts[a], *pts[c], needed + 1e-6) >= needed - _EPS:
            del nodes[i + 1]
        else:
            i += 1
    return nodes


def route_clearance(blocked: np.ndarray, points, cap: float) -> float:
    """Least distance (cells) from a polyline (cell units) to an obstacle square or the
    map border, capped at ``cap``."""
    pts = np.asarray(points, dtype=np.float64)
    blocked = blocked.view(np.uint8)
    if len(pts) == 1:
        return float(segment_clearance(blocked, *pts[0], *pts[0], cap))
    return min(float(segment_clearance(blocked, *p, *q, cap)) for p, q in itertools.pairwise(pts))


@numba.njit(cache=True)
def _segment_box_distance(x0, y0, x1, y1, bx0, by0, bx1, by1):
    """Least distance between a segment and a closed axis-aligned box (0 if they meet):
    apart, it is reached at an end of the segment or at a corner of the box."""
    if _segment_touches_box(x0, y0, x1, y1, bx0, by0, bx1, by1):
        return 0.0
    best = np.inf
    for px, py in ((x0, y0), (x1, y1)):
        gx = max(bx0 - px, 0.0, px - bx1)
        gy = max(by0 - py, 0.0, py - by1)
        best = min(best, math.sqrt(gx * gx + gy * gy))
    for cx, cy in ((bx0, by0), (bx1, by0), (bx0, by1), (bx1, by1)):
        best = min(best, _point_segment_distance(cx, cy, x0, y0, x1, y1))
    return best


@numba.njit(cache=True)
def segment_clearance(blocked, x0, y0, x1, y1, cap):
    """Least distance (cells) from the segment (cell units: centres at integers) to an
    obstacle square or to outside the map, or ``cap`` if it is farther than that.

    Only the band of cells within cap + 1 of the segment is visited (a square whose
    centre is farther away is more than cap from it); the ring of cells just beyond the
    border stands for outside the map.
    """
    height, width = blocked.shape
    reach = cap + 1.0
    best = cap
    c_lo = max(-1, math.floor(min(x0, x1) - reach))
    c_hi = min(width, math.ceil(max(x0, x1) + reach))
    for c in range(c_lo, c_hi + 1):
        r_lo, r_hi = _band_rows(c, x0, y0, x1, y1, reach, height)
        for r in range(r_lo, r_hi + 1):
            outside = c < 0 or c >= width or r < 0 or r >= height
            if not outside and not blocked[r, c]:
                continue
            d = _segment_box_distance(x0, y0, x1, y1, c - 0.5, r - 0.5, c + 0.5, r + 0.5)
            if d < best:
                best = d
                if best <= 0.0:
                    return 0.0
    return best
