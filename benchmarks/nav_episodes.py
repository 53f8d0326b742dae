"""Seeded single-AGV navigation episodes for ``nav_bench.py``.

Episode ``seed`` is a 20 x 20 m map (1 m cells, 15-30 % random obstacles),
a start and a goal at least 10 m apart, and from the seed:

- the goal in a dock (a 1-cell-wide recess 2 cells deep), a 1-cell pocket
  (3 sides walled) or in the open;
- a walker crossing the route once at a random place, speed and time (on a
  straight line clear of the walls, from one side to the other), and/or one
  coming head-on along the route;
- a temporary wall across the route, there from the start (sensed once
  within the sensing radius: early) or appearing just before the AGV gets
  there (late), only where the body still fits round it;
- the paper's vehicle (Table 1) or a realistic one (1 m/s², 60 deg/s).

``body_path`` is the shortest path the AGV's disc fits through (the
reference for driven / shortest), on the distance-field lattice.
``way_at_rest`` says whether one is left once every walker has stopped where
its walk ends: a crossing walker stops clear of the route drawn before the
temporary wall, which is not always clear of the detour round it (seed 55
stops in the detour's only gap). Such an episode has no way to the goal and
is reported apart, as the issue's "success where a path exists" asks.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass

import numpy as np

from fleet.moving_obstacle import MovingObstacle
from fleet.scenario import VEHICLE_KEYS, AgvSpec, Scenario, TemporaryObstacle
from planner.local.config import DwaConfig
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap
from planner.maps.random_map import random_map
from planner.nav.fusion import FusionConfig

SIZE = 20
RADIUS = 0.3
SENSING_RADIUS = 5.0
TABLE1 = {
    "max_speed": 2.0, "max_accel": 0.2, "max_omega": math.radians(20),
    "max_alpha": math.radians(50),
}  # fmt: skip
REALISTIC = {
    "max_speed": 1.5, "max_accel": 1.0, "max_omega": math.radians(60),
    "max_alpha": math.radians(120),
}  # fmt: skip
VEHICLES = {"table1": TABLE1, "realistic": REALISTIC}
NOMINAL_SPEED = {"table1": 0.8, "realistic": 1.2}  # m/s, to time walkers and late walls
_STEPS = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)]


@dataclass(frozen=True)
class Episode:
    seed: int
    vehicle: str
    goal_kind: str  # open, dock, pocket
    events: str  # what happens, e.g. "crossing+wall-late"
    grid: GridMap  # static map (docks and pockets included)
    start: tuple[float, float]
    goal: tuple[float, float]
    temporary: tuple[TemporaryObstacle, ...]
    moving: tuple[MovingObstacle, ...]
    shortest: float  # m, the body's shortest path with every temporary wall present
    way_at_rest: bool = True  # a way is left once every walker has stopped where it ends

    def scenario(self, algorithm: str, profile: str) -> Scenario:
        dwa = DwaConfig(radius=RADIUS, **VEHICLES[self.vehicle])
        config = FusionConfig(algorithm=algorithm, profile=profile, dwa=dwa)
        return Scenario(
            name=f"nav-{self.seed}",
            description=self.events,
            dt=0.1,
            time_limit=round(60 + 6 * self.shortest),
            sensing_radius=SENSING_RADIUS,
            grid=self.grid,
            agvs=(AgvSpec("agv", self.start, self.goal, 0.0, config),),
            temporary=self.temporary,
            moving=self.moving,
            source="",
            path="",
        )

    def toml(self, algorithm: str = "fusion", profile: str = "default") -> str:
        """The episode as a scenario file that ``agv-fleet run`` reads as ``scenario``
        reads it (a test checks they are equal): to watch an episode in Rerun or plot it
        with ``analyze``. The vehicle's limits are written in the format's units."""
        vehicle = {k: v / VEHICLE_KEYS[k][1] for k, v in VEHICLES[self.vehicle].items()}
        lines = [
            f'name = "nav-{self.seed}"',
            f'description = "nav_bench episode {self.seed}: {self.vehicle} vehicle, '
            f'goal {self.goal_kind}, {self.events}"',
            "dt = 0.1",
            f"time_limit = {round(60 + 6 * self.shortest)}",
            f"sensing_radius = {SENSING_RADIUS}",
            f'profile = "{profile}"',
            "",
            "[map]",
            f"resolution = {self.grid.resolution!r}",
            f'grid = """\n{self.grid.to_text()}\n"""',
            "",
            "[planner]",
            f'algorithm = "{algorithm}"',
            "",
            "[agv_defaults]",
            f"radius = {RADIUS}",
            *(f"{k} = {round(v, 9)!r}" for k, v in vehicle.items()),
            "",
            "[[agvs]]",
            'name = "agv"',
            f"start = [{self.start[0]!r}, {self.start[1]!r}]",
            f"goal = [{self.goal[0]!r}, {self.goal[1]!r}]",
            "heading = 0.0",
        ]
        for wall in self.temporary:
            cells = ", ".join(f"[{c}, {r}]" for c, r in wall.cells)
            lines += ["", "[[obstacles]]", 'type = "temporary"', f'name = "{wall.name}"',
                      f"cells = [{cells}]", f"appear_at = {wall.appear_at!r}"]  # fmt: skip
        for walker in self.moving:
            points = ", ".join(f"[{x!r}, {y!r}]" for x, y in walker.waypoints)
            lines += [
                "", "[[obstacles]]", 'type = "moving"', f'name = "{walker.name}"',
                f"radius = {walker.radius!r}", f"waypoints = [{points}]",
                f"speed = {walker.speed!r}", f'mode = "{walker.mode}"',
                f"start_at = {walker.start_at!r}",
            ]  # fmt: skip
        return "\n".join(lines) + "\n"


def body_path(
    grid: GridMap, start, goal, radius: float = RADIUS, discs=()
) -> list[tuple[float, float]]:
    """Shortest 8-connected lattice path from ``start`` to ``goal`` keeping ``radius`` clear
    of the walls and of the standing ``discs`` (x, y, r) (lattice of the map's
    DistanceField); [] when the body cannot get there."""
    field = DistanceField.from_grid(grid)
    free = field.samples >= radius
    h = field.spacing
    rows, cols = free.shape
    if len(discs):
        lattice_y, lattice_x = np.mgrid[0:rows, 0:cols] * h
        for x, y, r in discs:
            free &= np.hypot(lattice_x - x, lattice_y - y) >= r + radius

    def node(p):
        return (round(p[1] / h), round(p[0] / h))

    s, g = node(start), node(goal)
    if not (free[s] and free[g]):
        return []
    dist = {s: 0.0}
    came: dict = {}
    queue = [(0.0, s)]
    while queue:
        d, u = heapq.heappop(queue)
        if u == g:
            break
        if d > dist[u]:
            continue
        for dj, di in _STEPS:
            v = (u[0] + dj, u[1] + di)
            if not (0 <= v[0] < rows and 0 <= v[1] < cols and free[v]):
                continue
            nd = d + math.hypot(dj, di) * h
            if nd < dist.get(v, math.inf):
                dist[v], came[v] = nd, u
                heapq.heappush(queue, (nd, v))
    if g not in dist:
        return []
    path = [g]
    while path[-1] != s:
        path.append(came[path[-1]])
    return [(c * h, r * h) for r, c in reversed(path)]


def path_length(path) -> float:
    return float(sum(math.dist(a, b) for a, b in itertools.pairwise(path)))


def _aside(grid: GridMap, route, point) -> tuple[float, float] | None:
    """The free cell centre nearest ``point`` that is at least 1.5 m from every route point
    and that a walker's disc reaches from ``point`` in a straight line clear of the walls."""
    field = DistanceField.from_grid(grid)
    route_xy = np.asarray(route)
    best, best_d = None, math.inf
    for row in range(grid.height):
        for col in range(grid.width):
            centre = grid.centre_of((col, row))
            d = math.dist(centre, point)
            if grid.blocked[row, col] or d >= best_d:
                continue
            if np.hypot(*(route_xy - centre).T).min() < 1.5:
                continue
            direction = ((centre[0] - point[0]) / d, (centre[1] - point[1]) / d)
            if _free_extent(field, point, direction, d) >= d - 0.05:
                best, best_d = centre, d
    return best


WALKER_RADIUS = 0.35
CROSSING_HALF = 3.0  # m: a crossing walker starts and ends at most this far from the route
CROSSING_CLEAR = 1.0  # m: ... and at least this far, so that it leaves the route free


def _free_extent(field: DistanceField, point, direction, longest: float) -> float:
    """How far a walker's disc moves from ``point`` along ``direction`` before touching a wall
    (or the map's edge), up to ``longest``."""
    step, reach = 0.05, 0.0
    while reach + step <= longest:
        x = point[0] + (reach + step) * direction[0]
        y = point[1] + (reach + step) * direction[1]
        inside = (
            WALKER_RADIUS <= x <= SIZE - WALKER_RADIUS
            and WALKER_RADIUS <= y <= SIZE - WALKER_RADIUS
        )
        if not inside or float(field.distance_at(x, y)) < WALKER_RADIUS:
            break
        reach += step
    return reach


def _crossing(grid: GridMap, route, rng, speed: float) -> MovingObstacle | None:
    """A walker crossing the route once at a random place, speed and time, on a straight line
    that keeps its disc off the walls, from one side to the other (None: no such place found).

    It is timed to reach the route within 5 s of the AGV's nominal arrival there, and stops
    at least ``CROSSING_CLEAR`` from the route, so it never parks in the AGV's way.
    """
    field = DistanceField.from_grid(grid)
    walk = float(rng.uniform(0.3, 0.8))
    offset = float(rng.uniform(-5, 5))
    side = 1 if rng.random() < 0.5 else -1
    for _ in range(20):
        k = int(rng.integers(len(route) // 5, 4 * len(route) // 5))
        (x0, y0), (x1, y1) = route[k], route[min(k + 5, len(route) - 1)]
        heading = math.atan2(y1 - y0, x1 - x0) + math.pi / 2
        unit = (side * math.cos(heading), side * math.sin(heading))
        back = _free_extent(field, (x0, y0), (-unit[0], -unit[1]), CROSSING_HALF)
        ahead = _free_extent(field, (x0, y0), unit, CROSSING_HALF)
        if min(back, ahead) < CROSSING_CLEAR:
            continue
        ends = (
            (x0 - back * unit[0], y0 - back * unit[1]),
            (x0 + ahead * unit[0], y0 + ahead * unit[1]),
        )
        meet = path_length(route[: k + 1]) / speed + offset
        start_at = max(0.0, meet - back / walk)
        return MovingObstacle("crossing", WALKER_RADIUS, ends, walk, "once", start_at)
    return None


def _recess(blocked: np.ndarray, rng, depth: int, keep) -> tuple[int, int] | None:
    """Carve a 1-cell-wide recess ``depth`` cells deep; its innermost cell, or None."""
    for _ in range(200):
        col, row = (int(v) for v in rng.integers(2, SIZE - 2, size=2))
        dx, dy = _STEPS[int(rng.integers(0, 4))]  # the opening's direction
        cells = [(col + dx * k, row + dy * k) for k in range(depth)]
        mouth = (col + dx * depth, row + dy * depth)
        if not all(2 <= c < SIZE - 2 and 2 <= r < SIZE - 2 for c, r in [*cells, mouth]):
            continue
        if any(c in keep for c in [*cells, mouth]):
            continue
        walls = [(col - dx, row - dy)]
        for c, r in cells:
            walls += [(c + dy, r + dx), (c - dy, r - dx)]
        for c, r in cells:
            blocked[r, c] = False
        blocked[mouth[1], mouth[0]] = False
        for c, r in walls:
            blocked[r, c] = True
        return (col, row)
    return None


def make_episode(seed: int) -> Episode | None:
    """Episode ``seed``, or None when its map leaves the body no way to the goal."""
    rng = np.random.default_rng(seed)
    vehicle = ("table1", "realistic")[seed % 2]
    goal_kind = ("open", "dock", "pocket")[(seed // 2) % 3]
    ratio = float(rng.uniform(0.15, 0.30))
    while True:
        start_cell = tuple(int(v) for v in rng.integers(0, SIZE, size=2))
        goal_cell = tuple(int(v) for v in rng.integers(0, SIZE, size=2))
        if math.dist(start_cell, goal_cell) >= 10:
            break
    grid = random_map(SIZE, SIZE, ratio, seed, [start_cell, goal_cell])
    blocked = np.array(grid.blocked)
    if goal_kind != "open":
        keep = {start_cell, *((start_cell[0] + a, start_cell[1] + b) for a, b in _STEPS)}
        inner = _recess(blocked, rng, 2 if goal_kind == "dock" else 1, keep)
        if inner is None:
            return None
        goal_cell = inner
    grid = GridMap(blocked, 1.0, f"nav-{seed}")
    start = (start_cell[0] + 0.5, start_cell[1] + 0.5)
    goal = (goal_cell[0] + 0.5, goal_cell[1] + 0.5)
    route = body_path(grid, start, goal)
    if not route:
        return None
    length = path_length(route)
    speed = NOMINAL_SPEED[vehicle]
    events, moving, temporary = [], [], []
    if rng.random() < 0.6:  # a walker crossing the route once, from a random side
        walker = _crossing(grid, route, rng, speed)
        if walker is not None:
            moving.append(walker)
            events.append("crossing")
    if rng.random() < 0.4:  # a walker coming head-on along the route, then stepping aside
        k = int(rng.integers(len(route) // 2, len(route) - 1))
        j = max(30, k - 80)  # it turns off at least 3 m before the start
        aside = _aside(grid, route, route[j])
        if k - j >= 10 and aside is not None:
            walk = float(rng.uniform(0.3, 0.8))
            points = (*route[j : k + 1][::-1], aside)
            start_at = float(rng.uniform(0, 20))
            moving.append(MovingObstacle("head-on", WALKER_RADIUS, points, walk, "once", start_at))
            events.append("head-on")
    if rng.random() < 0.6:  # a wall across the route
        late = rng.random() < 0.5
        k = int(rng.integers(len(route) // 4, 3 * len(route) // 4))
        cell = grid.cell_of(route[k])
        candidates = [[cell, (cell[0] + 1, cell[1]), (cell[0] - 1, cell[1])],
                      [cell, (cell[0], cell[1] + 1), (cell[0], cell[1] - 1)], [cell]]  # fmt: skip
        for cells in candidates:
            cells = [c for c in cells if grid.contains_cell(c) and c not in (start_cell, goal_cell)]
            if not cells or grid.cell_of(start) in cells:
                continue
            walled = grid.with_blocked(cells)
            detour = body_path(walled, start, goal)
            if detour and math.dist(start, grid.centre_of(cells[0])) > 1.5:
                appear = max(0.0, path_length(route[: k + 1]) / speed - 3.0) if late else 0.0
                temporary.append(TemporaryObstacle("wall", tuple(cells), round(appear, 1)))
                events.append("wall-late" if late else "wall-early")
                length = path_length(detour)
                break
    walled = grid.with_blocked([c for t in temporary for c in t.cells])
    at_rest = [(*m.waypoints[-1], m.radius) for m in moving]
    way_at_rest = bool(body_path(walled, start, goal, discs=at_rest))
    return Episode(
        seed, vehicle, goal_kind, "+".join(events) or "static", grid, start, goal,
        tuple(temporary), tuple(moving), length, way_at_rest,
    )  # fmt: skip


def episodes(count: int, first_seed: int = 0) -> list[Episode]:
    """The first ``count`` episodes that have a way for the body, from ``first_seed`` on."""
    out, seed = [], first_seed
    while len(out) < count:
        episode = make_episode(seed)
        if episode is not None:
            out.append(episode)
        seed += 1
    return out
