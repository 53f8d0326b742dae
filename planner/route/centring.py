"""Key nodes moved off the cell centres towards the middle of the free space (default).

The search puts key nodes on cell centres. In a passage an even number of
cells wide the middle is a cell edge, so the route runs half a cell off it:
a 1.0 m corridor drawn at 0.25 m leaves the body 0.075 m on one side
instead of 0.2 m on both, and DWA, whose arcs must keep clear for their
whole horizon, then finds almost no admissible way in (an AGV slid 50 s up
and down in front of such a corridor and gave up). So each inner key node
is moved by at most half a cell (and ``MAX_SHIFT_M``), in steps of half that, to where its
two segments have the largest least clearance, then the largest mean
clearance; a move is taken only if it improves that, so the route's least
clearance never drops. A few passes let neighbouring nodes follow each other.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.maps.segment_clearance import segment_clearance

SHIFT = 0.5  # cells: the farthest a key node moves from where the search put it ...
MAX_SHIFT_M = 0.15  # m: ... and no farther than this (a coarse map's cell is 1 m)
PASSES = 3
_EPS = 1e-9


@numba.njit(cache=True)
def segment_profile(blocked, x0, y0, x1, y1, cap):
    """(least, mean) clearance in cells along the segment, each capped at ``cap``: the
    mean over pieces at most one cell long (cell units, as ``segment_clearance``)."""
    pieces = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0)))
    least, total = cap, 0.0
    for k in range(pieces):
        a, b = k / pieces, (k + 1) / pieces
        c = segment_clearance(
            blocked, x0 + a * (x1 - x0), y0 + a * (y1 - y0), x0 + b * (x1 - x0),
            y0 + b * (y1 - y0), cap,
        )  # fmt: skip
        least = min(least, c)
        total += c
    return least, total / pieces


@numba.njit(cache=True)
def _score(blocked, p, q, r, cap):
    """Least and mean clearance of the two segments p-q and q-r (mean weighted by length)."""
    l1, m1 = segment_profile(blocked, p[0], p[1], q[0], q[1], cap)
    l2, m2 = segment_profile(blocked, q[0], q[1], r[0], r[1], cap)
    w1 = math.hypot(q[0] - p[0], q[1] - p[1])
    w2 = math.hypot(r[0] - q[0], r[1] - q[1])
    mean = (m1 * w1 + m2 * w2) / max(w1 + w2, _EPS)
    return min(l1, l2), mean


@numba.njit(cache=True)
def _centre(blocked, points, cap, shift, step, passes):
    pts = points.copy()
    n = round(shift / step)
    for _ in range(passes):
        moved = False
        for i in range(1, len(pts) - 1):
            best_least, best_mean = _score(blocked, pts[i - 1], pts[i], pts[i + 1], cap)
            best = pts[i].copy()
            for dx in range(-n, n + 1):
                for dy in range(-n, n + 1):
                    q = np.array([points[i, 0] + dx * step, points[i, 1] + dy * step])
                    least, mean = _score(blocked, pts[i - 1], q, pts[i + 1], cap)
                    if least > best_least + _EPS or (
                        least >= best_least - _EPS and mean > best_mean + _EPS
                    ):
                        best_least, best_mean, best = least, mean, q
            if best[0] != pts[i, 0] or best[1] != pts[i, 1]:
                pts[i] = best
                moved = True
        if not moved:
            break
    return pts


def centred(blocked: np.ndarray, points: np.ndarray, cap: float, resolution: float) -> np.ndarray:
    """``points`` (K, 2, cell units: the route's start, key nodes, goal) with the inner
    ones moved towards the middle of the free space (module doc); ``cap`` in cells,
    ``resolution`` in m per cell."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    shift = min(SHIFT, MAX_SHIFT_M / resolution)
    if len(pts) < 3:
        return pts.copy()
    return _centre(blocked.view(np.uint8), pts, float(cap), shift, shift / 2, PASSES)
