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

Work happens in cell units (cell centres at integer coordinates); the segment tests
are ``planner.maps.segment_clearance``'s.
"""

from __future__ import annotations

import itertools

import numpy as np

from planner.maps.clearance import TOLERANCE
from planner.maps.grid import Cell, GridMap
from planner.maps.segment_clearance import segment_clearance, segment_is_clear

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
    """Start, key nodes and goal of a cell path; ``safety_distance`` in metres. A segment
    must keep *more* than it from obstacle centres: one that keeps it only up to the
    rounding of metres into cells (``clearance.TOLERANCE``) does not."""
    nodes = drop_collinear(cells)
    safety_cells = (safety_distance + TOLERANCE) / grid.resolution
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
