"""Independent checks of where an AGV's body fits, for the tests of the costmap planner.

Nothing here imports the planner: distances are computed in world coordinates with
plain numpy from the map's obstacle cells (closed squares) and its border, so that a
bug in planner.maps.costmap, planner.route.key_nodes or planner.route.astar cannot hide itself.

- ``route_clearance``: the exact least distance from a polyline to every obstacle
  square and to the map's border (a segment and a box that do not meet are closest at
  an end of the segment or at a corner of the box; separating axes decide whether they
  meet).
- ``lethal_cells`` / ``centre_distance``: a cell is lethal when its centre lies within
  the radius of an obstacle square or the border, measured by a dilation with the disc
  of offsets, not by a distance transform.
- ``dijkstra``: a plain Dijkstra (numba, compiled here) on 8-neighbour moves that never
  enter a lethal cell nor pass diagonally between two cells one of which is lethal.
"""

from __future__ import annotations

import heapq
import itertools
import math

import numba
import numpy as np


class MapView:
    """The obstacle squares of a map in world coordinates (from its arrays only)."""

    def __init__(self, blocked: np.ndarray, resolution: float, origin=(0.0, 0.0)):
        self.blocked = np.asarray(blocked, dtype=bool)
        self.res = float(resolution)
        self.ox, self.oy = (float(v) for v in origin)
        rows, cols = np.nonzero(self.blocked)
        self.lo = np.column_stack((self.ox + cols * self.res, self.oy + rows * self.res))
        self.hi = self.lo + self.res
        h, w = self.blocked.shape
        self.x1 = self.ox + w * self.res
        self.y1 = self.oy + h * self.res

    def border_distance(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, float).reshape(-1, 2)
        return np.minimum.reduce(
            [p[:, 0] - self.ox, self.x1 - p[:, 0], p[:, 1] - self.oy, self.y1 - p[:, 1]]
        )

    def point_clearance(self, point, reach: float = 2.0) -> float:
        """Least distance from a point to a square or the border (exact up to ``reach``)."""
        return self.segment_clearance(point, point, reach)

    def segment_clearance(self, p, q, reach: float) -> float:
        """Least distance from segment pq to a square or the border: exact when it is at
        most ``reach``, else more than ``reach`` (squares that do not meet the segment's
        bounding box grown by ``reach`` are skipped, as they are farther)."""
        p, q = np.asarray(p, float), np.asarray(q, float)
        box_lo, box_hi = np.minimum(p, q) - reach, np.maximum(p, q) + reach
        near = np.all((self.hi >= box_lo) & (self.lo <= box_hi), axis=1)
        lo, hi = self.lo[near], self.hi[near]
        # the border: the distance to a line is linear along the segment, least at an end
        best = float(self.border_distance(np.array([p, q])).min())
        if not len(lo):
            return best
        if _segments_meet_boxes(p, q, lo, hi).any():
            return 0.0
        gaps = [_point_box(p, lo, hi), _point_box(q, lo, hi)]
        for xs, ys in ((lo, lo), (hi, lo), (lo, hi), (hi, hi)):  # the four corners
            gaps.append(_point_segment(np.column_stack((xs[:, 0], ys[:, 1])), p, q))
        return min(best, float(np.min(gaps)))

    def route_clearance(self, points, reach: float = 2.0) -> float:
        """Least distance from a polyline to a square or the border (exact up to ``reach``)."""
        pts = np.asarray(points, float).reshape(-1, 2)
        if len(pts) == 1:
            return self.point_clearance(pts[0], reach)
        return min(self.segment_clearance(a, b, reach) for a, b in itertools.pairwise(pts))


def _point_box(p, lo, hi) -> np.ndarray:
    gx = np.maximum(np.maximum(lo[:, 0] - p[0], 0.0), p[0] - hi[:, 0])
    gy = np.maximum(np.maximum(lo[:, 1] - p[1], 0.0), p[1] - hi[:, 1])
    return np.hypot(gx, gy)


def _point_segment(points, p, q) -> np.ndarray:
    d = q - p
    length2 = float(d @ d)
    t = np.zeros(len(points)) if length2 == 0 else np.clip((points - p) @ d / length2, 0.0, 1.0)
    foot = p + t[:, None] * d
    return np.hypot(*(points - foot).T)


def _segments_meet_boxes(p, q, lo, hi) -> np.ndarray:
    """Separating axis test of segment pq against each closed box (x axis, y axis, and
    the segment's normal)."""
    meet = (np.maximum(p[0], q[0]) >= lo[:, 0]) & (np.minimum(p[0], q[0]) <= hi[:, 0])
    meet &= (np.maximum(p[1], q[1]) >= lo[:, 1]) & (np.minimum(p[1], q[1]) <= hi[:, 1])
    n = np.array([-(q - p)[1], (q - p)[0]])
    centre = (lo + hi) / 2
    half = (hi - lo) / 2
    reach = half[:, 0] * abs(n[0]) + half[:, 1] * abs(n[1])
    meet &= np.abs((centre - p) @ n) <= reach + 1e-12
    return meet


# --- lethal cells by dilation ------------------------------------------------------------
def centre_distance(blocked: np.ndarray, resolution: float, cap: float) -> np.ndarray:
    """min(cap, distance from each cell centre to the nearest obstacle square or the
    border), metres, by trying every offset within ``cap``."""
    h, w = blocked.shape
    out = np.full((h, w), float(cap))
    n = math.ceil(cap / resolution) + 1
    padded = np.zeros((h + 2 * n, w + 2 * n), dtype=bool)
    padded[n : n + h, n : n + w] = blocked
    padded[:n, :] = padded[-n:, :] = True  # outside the map is obstacle
    padded[:, :n] = padded[:, -n:] = True
    for dr in range(-n, n + 1):
        for dc in range(-n, n + 1):
            gap = math.hypot(max(abs(dc) - 0.5, 0.0), max(abs(dr) - 0.5, 0.0)) * resolution
            if gap >= cap:
                continue
            shifted = padded[n + dr : n + dr + h, n + dc : n + dc + w]
            out[shifted] = np.minimum(out[shifted], gap)
    return out


def lethal_cells(blocked: np.ndarray, resolution: float, radius: float) -> np.ndarray:
    return centre_distance(blocked, resolution, radius) < radius


# --- Dijkstra ----------------------------------------------------------------------------
@numba.njit(cache=True)
def _dijkstra(lethal, penalty, sc, sr, gc, gr):
    h, w = lethal.shape
    dist = np.full((h, w), np.inf)
    done = np.zeros((h, w), dtype=np.bool_)
    dist[sr, sc] = 0.0
    heap = [(0.0, sc, sr)]
    while heap:
        d, c, r = heapq.heappop(heap)
        if done[r, c]:
            continue
        done[r, c] = True
        if c == gc and r == gr:
            return d
        for dc in (-1, 0, 1):
            for dr in (-1, 0, 1):
                if dc == 0 and dr == 0:
                    continue
                cc, rr = c + dc, r + dr
                if cc < 0 or rr < 0 or cc >= w or rr >= h or lethal[rr, cc] or done[rr, cc]:
                    continue
                if dc != 0 and dr != 0:
                    if lethal[r, cc] or lethal[rr, c]:
                        continue
                    step = math.sqrt(2.0)
                else:
                    step = 1.0
                nd = d + step * (1.0 + penalty[rr, cc])
                if nd < dist[rr, cc]:
                    dist[rr, cc] = nd
                    heapq.heappush(heap, (nd, cc, rr))
    return np.inf


def dijkstra(lethal: np.ndarray, penalty: np.ndarray, start, goal) -> float:
    """Least cost (cells) from cell start to cell goal (col, row): a step costs its length
    times (1 + penalty of the cell entered); inf when the goal cannot be reached."""
    return float(
        _dijkstra(
            np.ascontiguousarray(lethal, dtype=np.bool_),
            np.ascontiguousarray(penalty, dtype=np.float64),
            int(start[0]),
            int(start[1]),
            int(goal[0]),
            int(goal[1]),
        )
    )


def path_cost(cells, penalty: np.ndarray) -> float:
    """The same cost, of a given cell path."""
    total = 0.0
    for (c0, r0), (c1, r1) in itertools.pairwise(cells):
        total += math.hypot(c1 - c0, r1 - r0) * (1.0 + penalty[r1, c1])
    return total
