"""Exact distances from segments and polylines (cell units) to obstacle squares.

Cell centres sit at integer coordinates; an obstacle cell is the closed unit square round
its centre, and the ring of cells just beyond the map's border stands for outside the map.
The tests only visit the band of cells near a segment, so they cost
O(length x reach), not O(map). Key nodes (``planner.route.key_nodes``), the costmap and
the global planner's clearance checks all measure with these.
"""

from __future__ import annotations

import itertools
import math

import numba
import numpy as np

# a segment closer than this to an obstacle square counts as touching it
_TOUCH_EPS = 1e-9


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
def point_segment_distance(px, py, x0, y0, x1, y1):
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
def segment_touches_box(x0, y0, x1, y1, bx0, by0, bx1, by1):
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
            if point_segment_distance(c, r, x0, y0, x1, y1) <= safety:
                return False
            if segment_touches_box(x0, y0, x1, y1, c - h, r - h, c + h, r + h):
                return False
    return True


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
    if segment_touches_box(x0, y0, x1, y1, bx0, by0, bx1, by1):
        return 0.0
    best = np.inf
    for px, py in ((x0, y0), (x1, y1)):
        gx = max(bx0 - px, 0.0, px - bx1)
        gy = max(by0 - py, 0.0, py - by1)
        best = min(best, math.sqrt(gx * gx + gy * gy))
    for cx, cy in ((bx0, by0), (bx1, by0), (bx0, by1), (bx1, by1)):
        best = min(best, point_segment_distance(cx, cy, x0, y0, x1, y1))
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
