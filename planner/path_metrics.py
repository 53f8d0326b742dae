"""Metrics of a polyline path, usable on any path (planned or driven).

Turning times count the vertices where the heading changes; the total turning
angle sums the absolute heading changes (the paper's Tables 2 and 3).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

# heading changes below this are numerical noise on a straight line, not turns
TURN_TOLERANCE_DEG = 1e-6


def _points(path) -> np.ndarray:
    pts = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(pts) > 1:  # repeated points have no heading: drop them
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.any(np.diff(pts, axis=0) != 0.0, axis=1)
        pts = pts[keep]
    return pts


def path_length(path) -> float:
    """Sum of segment lengths."""
    pts = _points(path)
    return float(np.hypot(*np.diff(pts, axis=0).T).sum()) if len(pts) > 1 else 0.0


def heading_changes_deg(path) -> np.ndarray:
    """Signed heading change (deg, in (-180, 180]) at each interior vertex."""
    pts = _points(path)
    if len(pts) < 3:
        return np.zeros(0)
    d = np.diff(pts, axis=0)
    headings = np.arctan2(d[:, 1], d[:, 0])
    change = np.diff(headings)
    change = (change + np.pi) % (2 * np.pi) - np.pi
    return np.degrees(change)


def turn_angle(before, node, after) -> float:
    """The angle (rad, 0..pi) by which the route ``before`` → ``node`` → ``after`` turns
    (0 where two of the points coincide: no heading to turn from)."""
    change = heading_changes_deg([before, node, after])
    return math.radians(abs(float(change[0]))) if len(change) else 0.0


def turning_times(path) -> int:
    """Number of vertices where the heading changes."""
    return int(np.count_nonzero(np.abs(heading_changes_deg(path)) > TURN_TOLERANCE_DEG))


def total_turning_angle_deg(path) -> float:
    """Sum of absolute heading changes, degrees."""
    changes = np.abs(heading_changes_deg(path))
    return float(changes[changes > TURN_TOLERANCE_DEG].sum())


def distance_to_path(path, point) -> float:
    """Least distance from a point to a polyline (inf for an empty one)."""
    best = math.inf
    px, py = point
    for (ax, ay), (bx, by) in itertools.pairwise(path):
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        t = 0.0 if length2 == 0 else min(max(((px - ax) * dx + (py - ay) * dy) / length2, 0), 1)
        best = min(best, math.hypot(ax + t * dx - px, ay + t * dy - py))
    if len(path) == 1:
        best = math.dist(path[0], point)
    return best
