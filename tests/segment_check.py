"""An independent check that a polyline keeps to free cells.

Written apart from planner.route.key_nodes (separating-axis test rather than
Liang–Barsky) so that a bug there cannot hide itself in the tests.
"""

from __future__ import annotations

import itertools

import numpy as np


def segment_meets_square(p, q, centre, half=0.5) -> bool:
    """Separating axis test of segment pq against the closed axis-aligned square."""
    p = np.asarray(p, float) - centre
    q = np.asarray(q, float) - centre
    for axis in range(2):
        if max(p[axis], q[axis]) < -half or min(p[axis], q[axis]) > half:
            return False
    d = q - p
    normal = np.array([-d[1], d[0]])
    radius = half * (abs(normal[0]) + abs(normal[1]))
    return abs(normal @ p) <= radius + 1e-12


def polyline_blocked_cells(blocked: np.ndarray, points) -> list[tuple[int, int]]:
    """Obstacle cells (col, row) that any segment of the polyline touches (cell units)."""
    hits = []
    pts = np.asarray(points, float)
    rows, cols = np.nonzero(blocked)
    for p, q in itertools.pairwise(pts):
        lo = np.minimum(p, q) - 1
        hi = np.maximum(p, q) + 1
        near = (cols >= lo[0]) & (cols <= hi[0]) & (rows >= lo[1]) & (rows <= hi[1])
        for c, r in zip(cols[near], rows[near], strict=True):
            if segment_meets_square(p, q, np.array([c, r], float)):
                hits.append((int(c), int(r)))
    return hits
