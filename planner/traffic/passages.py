"""Passages: where two AGVs cannot pass each other, found from the costmap.

A *two-lane* place is one where the free space is at least two AGVs plus half a margin
wide (4 r + m/2): two bodies pass each other there with a little room (DWA passes with
less than the margin; the stress suite's 1.5 m corridors, 0.3 m AGVs, need no turns).
It is found from the exact distance to obstacle squares on a lattice of half cells,
plus a quarter cell (by which the lattice can miss a midline on a cell edge): a cell
is two-lane when one of its four half cells is at least 2 r + m/4 from every obstacle
square.

A *passage* cell is a cell the AGV fits in (not lethal in the costmap) from which no
two-lane cell is within r + m/4 (plus half a cell). The cells beside a wall of a room
are nearer than that to the room's two-lane middle; the cells of a corridor, a door in
a thin wall, an aisle end or a dock too narrow for two are not. Connected passage cells
form a passage; two passages closer than about ``WAIT_ROOM`` safety distances (through
free space) are one, so that an AGV never has to wait between two of them where it
would block both. A passage's *mouths* are the clusters of free cells outside it that
touch it: a corridor has two, a dock one.

Nothing is hand-marked: the map, the AGV's radius and margin decide. Built once per
map and clearance and cached with the map, like the costmap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from planner.maps.costmap import Costmap, centre_distances
from planner.maps.distance_field import squared_edt
from planner.maps.grid import GridMap, Point

WAIT_ROOM = 4.0
"""Passages closer than about this many safety distances (through free space, counted in
8-connected cell steps) are one."""

MAX_MOUTHS = 8
"""A corridor has two mouths, a dock one, a crossing of corridors four to eight (its
middle, two-lane or not, adds some); a narrow region with more is a cluttered area (a
TurtleBot3 arena among its pillars), where there is no place to wait outside it: the
rule leaves it to DWA."""
NONE = -1
"""Label of a cell outside every passage / mouth."""
_NEIGHBOURHOOD = ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1))


@dataclass(frozen=True)
class Crossing:
    """Where a route goes through a passage: entered ``enter_at`` m along the route
    through mouth ``entry`` (None: the route starts inside), left ``leave_at`` m along it
    through mouth ``exit`` (None: the route ends inside, at a goal in a dock or a
    corridor)."""

    passage: int
    enter_at: float
    leave_at: float
    exit: int | None
    entry: int | None = None


@dataclass(frozen=True, eq=False)
class RouteCells:
    """A route sampled every half cell (``Passages.route_cells``): each sample's distance
    along the route, cell, whether that cell is on the map, and its passage (or NONE).
    An AGV's route changes only at a key node or a replan, so its guard samples it once
    and not on every tick (the sampling was a tenth of a 50-AGV fleet's planning time)."""

    along: np.ndarray
    cols: np.ndarray
    rows: np.ndarray
    inside: np.ndarray
    labels: np.ndarray


@dataclass(frozen=True, eq=False)
class Passages:
    """The passages of one map for one AGV clearance (see module doc)."""

    grid: GridMap
    label: np.ndarray  # (H, W) int32: passage id, or NONE
    mouth: np.ndarray  # (H, W) int32: mouth id (ids unique over the map), or NONE
    count: int
    join_distance: float  # m: passages closer than this through free space are one
    _centres_of: dict = field(default_factory=dict, repr=False)  # per passage, computed once

    @classmethod
    def for_costmap(cls, costmap: Costmap) -> Passages:
        """The passages of the costmap's map, built on first use and cached with it."""
        return costmap.grid.derived(("passages", costmap.clearance), lambda: cls.build(costmap))

    @classmethod
    def build(cls, costmap: Costmap) -> Passages:
        grid, clearance = costmap.grid, costmap.clearance
        res = grid.resolution
        lane = 2 * clearance.radius + clearance.margin / 4  # m: half of 4 r + m / 2
        fine = np.kron(grid.blocked, np.ones((2, 2), dtype=bool))
        # the half-cell lattice misses a ridge on a cell edge by at most a quarter cell
        half_cell = centre_distances(fine) * (res / 2) + res / 4
        two_lane = half_cell.reshape(grid.height, 2, grid.width, 2).max(axis=(1, 3)) >= lane
        free = ~costmap.lethal
        if two_lane.any():
            to_two_lane = np.sqrt(squared_edt(two_lane)) * res
        else:
            to_two_lane = np.full(two_lane.shape, np.inf)
        # a cell the body fits in next to a wall is within lane - r of the two-lane space
        # beside it (plus half a cell of rounding): farther than that, it is in a passage
        narrow = free & (to_two_lane > lane - clearance.radius + res / 2)
        join = WAIT_ROOM * clearance.safety_distance
        alone = _label_passages(narrow, free, 0)
        alone = _without_nooks(alone, _label_mouths(alone, free), clearance.safety_distance / res)
        label = _label_passages(alone != NONE, free, max(1, math.ceil(join / (2 * res))))
        found = cls(grid, label, _label_mouths(label, free), int(label.max()) + 1, join)
        areas = [p for p in range(found.count) if len(found.mouths(p)) > MAX_MOUTHS]
        if areas:  # cluttered areas, not passages: left to DWA
            label = _renumbered(np.where(np.isin(label, areas), NONE, label).astype(np.int32))
        mouth = _label_mouths(label, free)
        for array in (label, mouth):
            array.setflags(write=False)
        return cls(grid, label, mouth, int(label.max()) + 1, join)

    def at(self, point: Point) -> int:
        """The passage at a world point, or NONE."""
        col, row = self.grid.cell_of(point)
        if not self.grid.contains_cell((col, row)):
            return NONE
        return int(self.label[row, col])

    def mouths(self, passage: int) -> dict[int, Point]:
        """The mouths of a passage and, for each, its cell nearest to its centroid (a
        mouth that bends round a corner has its centroid in the wall)."""
        every = self._centres_of.get("mouths")
        if every is None:
            every = self._centres_of["mouths"] = self._all_mouths()
        return every.get(passage, {})

    def _all_mouths(self) -> dict[int, dict[int, Point]]:
        rows, cols = np.nonzero(self.mouth != NONE)
        ids = self.mouth[rows, cols]
        res, (ox, oy) = self.grid.resolution, self.grid.origin
        xs, ys = ox + (cols + 0.5) * res, oy + (rows + 0.5) * res
        count = np.bincount(ids)
        mx, my = (
            np.bincount(ids, xs) / np.maximum(count, 1),
            np.bincount(ids, ys) / np.maximum(count, 1),
        )
        nearest = {}
        for i in np.argsort(np.hypot(xs - mx[ids], ys - my[ids]), kind="stable"):
            nearest.setdefault(
                int(ids[i]), (float(xs[i]), float(ys[i]), int(rows[i]), int(cols[i]))
            )
        out: dict[int, dict[int, Point]] = {}
        for mouth, (x, y, row, col) in sorted(nearest.items()):
            passage = self._touching(col, row)
            out.setdefault(passage, {})[mouth] = (x, y)
        return out

    def _touching(self, col: int, row: int) -> int:
        """The passage a mouth cell touches."""
        for dc, dr in _NEIGHBOURHOOD[1:]:
            c, r = col + dc, row + dr
            if self.grid.contains_cell((c, r)) and self.label[r, c] != NONE:
                return int(self.label[r, c])
        return NONE

    def nearest_cell_centre(self, point: Point, passage: int) -> Point:
        """The centre of the passage's cell nearest to a world point."""
        centres = self._centres(passage)
        i = int(np.argmin(np.hypot(centres[:, 0] - point[0], centres[:, 1] - point[1])))
        return float(centres[i, 0]), float(centres[i, 1])

    def distance_to(self, point: Point, passage: int) -> float:
        """Distance (m) from a world point to the nearest cell centre of a passage."""
        centres = self._centres(passage)
        return float(np.hypot(centres[:, 0] - point[0], centres[:, 1] - point[1]).min())

    def _centres(self, passage: int) -> np.ndarray:
        centres = self._centres_of.get(passage)
        if centres is None:
            rows, cols = np.nonzero(self.label == passage)
            res, (ox, oy) = self.grid.resolution, self.grid.origin
            centres = np.column_stack((ox + (cols + 0.5) * res, oy + (rows + 0.5) * res))
            self._centres_of[passage] = centres
        return centres

    def route_cells(self, route: list[Point]) -> RouteCells:
        """``route`` sampled every half cell, with the cell and passage of each sample."""
        points, along = _samples(route, self.grid.resolution / 2)
        res = self.grid.resolution
        cols = np.floor((points[:, 0] - self.grid.origin[0]) / res).astype(np.int64)
        rows = np.floor((points[:, 1] - self.grid.origin[1]) / res).astype(np.int64)
        inside = (cols >= 0) & (cols < self.grid.width) & (rows >= 0) & (rows < self.grid.height)
        labels = np.full(len(points), NONE)
        labels[inside] = self.label[rows[inside], cols[inside]]
        return RouteCells(along, cols, rows, inside, labels)

    def first_crossing(
        self, route: list[Point] | RouteCells, lookahead: float, start_at: float = 0.0
    ) -> Crossing | None:
        """The first passage ``route`` (a polyline, world frame, or its ``route_cells``)
        enters between ``start_at`` and ``start_at + lookahead`` metres along it, or None;
        distances in the result are from ``start_at``. Where the route leaves the passage
        (its last sample inside before a stretch longer than a waiting place outside) is
        found on the whole route."""
        cells = route if isinstance(route, RouteCells) else self.route_cells(route)
        behind = start_at - self.grid.resolution / 2
        first, last, ahead, along = _crossing_span(
            cells.along, cells.labels, start_at, behind, lookahead, self.join_distance
        )
        if first < 0:
            return None
        passage = int(cells.labels[ahead[first]])
        exit = entry = None
        if last + 1 < len(ahead) and cells.inside[ahead[last + 1]]:
            after = ahead[last + 1]
            exit = self._mouth_near(int(cells.cols[after]), int(cells.rows[after]), passage)
        if first > 0 and cells.inside[ahead[first - 1]]:
            before = ahead[first - 1]
            entry = self._mouth_near(int(cells.cols[before]), int(cells.rows[before]), passage)
        return Crossing(passage, float(along[first]), float(along[last]), exit, entry)

    def _mouth_near(self, col: int, row: int, passage: int) -> int | None:
        """The mouth of ``passage`` at or next to a cell (routes sample in half cells)."""
        for dc, dr in (
            (0, 0),
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (-1, -1),
            (1, -1),
            (-1, 1),
        ):
            c, r = col + dc, row + dr
            inside = self.grid.contains_cell((c, r))
            if inside and self.mouth[r, c] != NONE and _touches(self.label, c, r, passage):
                return int(self.mouth[r, c])
        return None


@numba.njit(cache=True)
def _crossing_span(along, labels, start_at, behind, lookahead, join):
    """``first_crossing``'s search, compiled (it runs every tick for every AGV): the
    samples from ``behind`` on (``ahead``, indices into the route's samples) and their
    distance from ``start_at`` (``clipped``, >= 0); ``first``, the first of them in a
    passage within ``lookahead``, and ``last``, that passage's last sample before a
    stretch longer than ``join`` outside it, both indices into ``ahead``; -1, -1 if none."""
    ahead = np.flatnonzero(along >= behind)
    clipped = np.maximum(along[ahead] - start_at, 0.0)
    first = -1
    for i in range(ahead.size):
        if labels[ahead[i]] != NONE:
            first = i
            break
    if first < 0 or clipped[first] > lookahead:
        return -1, -1, ahead, clipped
    passage, last = labels[ahead[first]], first
    for i in range(first + 1, ahead.size):
        if labels[ahead[i]] == passage:
            if clipped[i] - clipped[last] > join:
                break
            last = i
    return first, last, ahead, clipped


def _samples(route: list[Point], step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points at most ``step`` m apart along a polyline (its vertices included), and
    their distance along it."""
    vertices = np.asarray(route, dtype=float).reshape(-1, 2)
    if len(vertices) < 2:
        return vertices, np.zeros(len(vertices))
    lengths = np.hypot(*np.diff(vertices, axis=0).T)
    counts = np.maximum(1, np.ceil(lengths / step).astype(np.int64))
    segment = np.repeat(np.arange(len(lengths)), counts)
    t = (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)) / counts[segment]
    a, b = vertices[segment], vertices[segment + 1]
    points = np.vstack((a + (b - a) * t[:, None], vertices[-1:]))
    starts = np.concatenate(([0.0], np.cumsum(lengths)))
    along = np.concatenate((starts[segment] + lengths[segment] * t, starts[-1:]))
    return points, along


def _without_nooks(label: np.ndarray, mouth: np.ndarray, depth: float) -> np.ndarray:
    """``label`` without the nooks: a passage with one mouth whose every cell is within
    ``depth`` cells of it (a room's corner, where no two-lane cell is near, is no
    passage; a dock deeper than that is). Ids renumbered in row-major order."""
    rows, cols = np.nonzero(label != NONE)
    if not len(rows):
        return label
    ids = label[rows, cols]
    order = np.argsort(ids, kind="stable")
    starts = np.flatnonzero(np.diff(ids[order], prepend=-2))
    keep = label.copy()
    for members in np.split(order, starts[1:]):
        r, c = rows[members], cols[members]
        box = (slice(max(r.min() - 1, 0), r.max() + 2), slice(max(c.min() - 1, 0), c.max() + 2))
        mouth_rows, mouth_cols = np.nonzero(mouth[box] != NONE)
        if len(np.unique(mouth[box][mouth_rows, mouth_cols])) != 1:
            continue
        mouth_rows, mouth_cols = mouth_rows + box[0].start, mouth_cols + box[1].start
        step = max(1, len(mouth_rows) // 64)  # a sample of the mouth bounds the memory
        mouth_rows, mouth_cols = mouth_rows[::step], mouth_cols[::step]
        gaps = np.hypot(r[:, None] - mouth_rows, c[:, None] - mouth_cols).min(axis=1)
        if gaps.max() <= depth:
            keep[r, c] = NONE
    return _renumbered(keep)


def _renumbered(label: np.ndarray) -> np.ndarray:
    """Passage ids 0, 1, ... in row-major order of their first cell."""
    present = label[label != NONE]  # row-major
    if not len(present):
        return label
    values, first = np.unique(present, return_index=True)
    renumber = np.full(int(label.max()) + 2, NONE, dtype=np.int32)
    renumber[values[np.argsort(first)]] = np.arange(len(values), dtype=np.int32)
    return np.where(label == NONE, NONE, renumber[label]).astype(np.int32)


def _touches(label: np.ndarray, col: int, row: int, passage: int) -> bool:
    height, width = label.shape
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r, c = row + dr, col + dc
            if 0 <= r < height and 0 <= c < width and label[r, c] == passage:
                return True
    return False


@numba.njit(cache=True)
def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@numba.njit(cache=True)
def _components(key):
    """Ids of the 8-connected regions of cells that share a key >= 0 (-1: no region),
    numbered in row-major order of their first cell."""
    height, width = key.shape
    out = np.full((height, width), -1, dtype=np.int32)
    queue = np.empty(height * width, dtype=np.int64)
    count = 0
    for r0 in range(height):
        for c0 in range(width):
            if key[r0, c0] < 0 or out[r0, c0] >= 0:
                continue
            head, tail = 0, 0
            queue[tail] = r0 * width + c0
            tail += 1
            out[r0, c0] = count
            while head < tail:
                r, c = divmod(queue[head], width)
                head += 1
                for dr in (-1, 0, 1):
                    for dc in (-1, 0, 1):
                        rr, cc = r + dr, c + dc
                        inside = 0 <= rr < height and 0 <= cc < width
                        if inside and out[rr, cc] < 0 and key[rr, cc] == key[r0, c0]:
                            out[rr, cc] = count
                            queue[tail] = rr * width + cc
                            tail += 1
            count += 1
    return out


@numba.njit(cache=True)
def _label_passages(narrow, free, room):
    """Passage ids: 8-connected narrow cells, joined when their components come within
    ``room`` steps of each other through free cells (each grows ``room`` steps, so
    components up to 2 ``room`` steps apart join); ids numbered in row-major order."""
    height, width = narrow.shape
    component = _components(np.where(narrow, 0, -1))
    count = component.max() + 1
    queue = np.empty(height * width * 2, dtype=np.int64)
    parent = np.arange(max(count, 1))
    # grow every component through free cells, at most ``room`` steps; fronts that meet
    # join their components
    owner = component.copy()
    steps = np.full((height, width), -1, dtype=np.int64)
    head, tail = 0, 0
    for r in range(height):
        for c in range(width):
            if owner[r, c] >= 0:
                steps[r, c] = 0
                queue[tail] = r * width + c
                tail += 1
    while head < tail:
        r, c = divmod(queue[head], width)
        head += 1
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if not (0 <= rr < height and 0 <= cc < width) or not free[rr, cc]:
                    continue
                if owner[rr, cc] >= 0:
                    a, b = _find(parent, owner[r, c]), _find(parent, owner[rr, cc])
                    if a != b:
                        parent[max(a, b)] = min(a, b)
                elif steps[r, c] < room:
                    owner[rr, cc] = owner[r, c]
                    steps[rr, cc] = steps[r, c] + 1
                    queue[tail] = rr * width + cc
                    tail += 1
    label = np.full((height, width), -1, dtype=np.int32)
    ids = np.full(max(count, 1), -1, dtype=np.int32)
    next_id = 0
    for r in range(height):
        for c in range(width):
            if component[r, c] >= 0:
                root = _find(parent, component[r, c])
                if ids[root] < 0:
                    ids[root] = next_id
                    next_id += 1
                label[r, c] = ids[root]
    return label


@numba.njit(cache=True)
def _label_mouths(label, free):
    """Mouth ids: 8-connected clusters of free cells outside every passage that touch
    one passage (a cluster never spans two passages: those are at least a waiting
    place apart, or one)."""
    height, width = label.shape
    touching = np.full((height, width), -1, dtype=np.int32)
    for r in range(height):
        for c in range(width):
            if label[r, c] >= 0 or not free[r, c]:
                continue
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    rr, cc = r + dr, c + dc
                    if 0 <= rr < height and 0 <= cc < width and label[rr, cc] >= 0:
                        touching[r, c] = label[rr, cc]
    return _components(touching)
