"""Metrics of a polyline path, usable on any path (planned or driven).

Turning times count the vertices where the heading changes; the total turning
angle sums the absolute heading changes (the paper's Tables 2 and 3). Self-crossings
count an AGV's loops: a driven path that circles crosses its own track.
"""

from __future__ import annotations

import itertools
import math

import numba
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
    (0 where two of the points coincide: no heading to turn from); ``heading_changes_deg``
    of the three points, bit for bit, in scalars (the planner asks this every cycle, and
    numpy's call overhead on three points was 3 % of a fleet's planning time)."""
    (x0, y0), (x1, y1), (x2, y2) = before, node, after
    if (x0 == x1 and y0 == y1) or (x1 == x2 and y1 == y2):
        return 0.0
    change = math.atan2(y2 - y1, x2 - x1) - math.atan2(y1 - y0, x1 - x0)
    change = (change + math.pi) % math.tau - math.pi
    return math.radians(abs(math.degrees(change)))


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


LOOP_GAP = 1.0
"""m along the path: two stretches at least this far apart that cross make a loop; nearer
ones are one manoeuvre (a turn on the spot, a wobble), not a loop."""

LOOP_ANGLE = math.radians(30.0)
"""rad: stretches crossing at less than this (or more than 180 degrees less this) retrace
the track, forwards or back: their sampled segments cross by chance, many times."""


def self_crossings(path, gap: float = LOOP_GAP) -> int:
    """How often ``path`` crosses itself, between stretches at least ``gap`` apart along it
    and at an angle of at least ``LOOP_ANGLE`` (a curl driven once crosses its own track
    once; driving back along the same line, or round the same circle again, does not)."""
    return len(crossing_points(path, gap))


def crossing_points(path, gap: float = LOOP_GAP) -> np.ndarray:
    """(K, 2) the points where ``path`` crosses itself, as ``self_crossings`` counts them
    (in the order of the earlier stretch): where an AGV looped."""
    pts = _points(path)
    if len(pts) < 4:
        return np.zeros((0, 2))
    along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    return _crossings(np.ascontiguousarray(pts), along, float(gap), math.sin(LOOP_ANGLE))


_BLOCK = 64
"""Segments per block of ``_crossings``: a block whose bounding box misses a segment's is
skipped whole, so a long path (20 000 points for 2000 s of driving) is not compared pair by
pair (0.5 s per AGV before)."""


@numba.njit(cache=True)
def _crossings(pts, along, gap, least_sin):
    """Where segments i and j > i of the polyline ``pts`` properly cross, j starting at
    least ``gap`` beyond the end of i along it (``along``: arc length at each point), at
    an angle whose sine is at least ``least_sin``. Each pair is tested as if all were, in
    the same order: a block of segments is skipped only when each of them would be."""
    n = len(pts) - 1
    blocks = (n + _BLOCK - 1) // _BLOCK
    box = np.empty((blocks, 4))  # x low, x high, y low, y high of each block's segments
    for b in range(blocks):
        block = pts[b * _BLOCK : min(n, (b + 1) * _BLOCK) + 1]
        box[b, 0], box[b, 1] = block[:, 0].min(), block[:, 0].max()
        box[b, 2], box[b, 3] = block[:, 1].min(), block[:, 1].max()
    out = np.empty((8, 2))
    count = 0
    for i in range(n):
        ax, ay = pts[i, 0], pts[i, 1]
        bx, by = pts[i + 1, 0], pts[i + 1, 1]
        lo_x, hi_x = min(ax, bx), max(ax, bx)
        lo_y, hi_y = min(ay, by), max(ay, by)
        for b in range((i + 1) // _BLOCK, blocks):
            if box[b, 1] < lo_x or box[b, 0] > hi_x or box[b, 3] < lo_y or box[b, 2] > hi_y:
                continue
            for j in range(max(i + 1, b * _BLOCK), min(n, (b + 1) * _BLOCK)):
                if along[j] < along[i + 1] + gap:
                    continue
                cx, cy = pts[j, 0], pts[j, 1]
                dx, dy = pts[j + 1, 0], pts[j + 1, 1]
                if (
                    max(cx, dx) < lo_x
                    or min(cx, dx) > hi_x
                    or max(cy, dy) < lo_y
                    or min(cy, dy) > hi_y
                ):
                    continue
                d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
                d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
                d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
                d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
                if d1 * d2 < 0 and d3 * d4 < 0:
                    sine = abs(d2 - d1) / (
                        math.hypot(bx - ax, by - ay) * math.hypot(dx - cx, dy - cy)
                    )
                    if sine >= least_sin:
                        if count == len(out):
                            out = np.concatenate((out, np.empty_like(out)))
                        t = d1 / (d1 - d2)  # where c -> d meets the line of a -> b
                        out[count, 0] = cx + t * (dx - cx)
                        out[count, 1] = cy + t * (dy - cy)
                        count += 1
    return out[:count].copy()
