"""Seeded traffic cases for ``traffic_bench.py``: many AGVs through narrow places.

Every case is a scenario written as TOML text (``TrafficCase.toml``, so a case
can be written out and watched with ``agv-fleet run case.toml``) and parsed
with ``fleet.scenario.parse_scenario``. Common to all cases:

- maps designed in cells of 0.5 m (``CELL``: corridor-2 is 2 cells = 1.0 m wide)
  and drawn at 0.25 m (``RES``): with 0.5 m cells the planner's costmap has no
  free cell in a 1.0 m passage (each cell centre is 0.25 m from a wall, less
  than the radius), so one AGV alone fails at once with "no path to the goal";
- planner profile ``default``, algorithm ``fusion``, dt 0.1 s, AGV radius 0.3 m,
  safety distance 0.5 m;
- a warehouse vehicle: max_speed 1.0 m/s, max_accel 0.5 m/s², max_omega
  60 deg/s, max_alpha 120 deg/s² (the paper's Table-1 vehicle, 0.2 m/s² and
  20 deg/s, makes every run minutes long);
- every start and goal at least radius + 0.05 m from obstacles and the map's
  edge and 1.5 m from every cell of a door, corridor or crossing arm
  (``MOUTH_CLEAR``: an AGV that arrived in a doorway would close it), starts
  pairwise and goals pairwise at least 1.0 m apart (1.5 m in the
  warehouses), and every goal reachable by the body alone (the AGV's own global
  planner finds a route);
- time limit: 60 s + 4 x (the longest planned route / max_speed + 10 s),
  rounded up to 10 s: about 4 times the longest solo run, plus a minute.

Families (``FAMILIES``), each generated for seeds 0, 1, 2, ...:

- ``corridor-2``, ``corridor-3``, ``corridor-4``: a straight corridor 2, 3 or
  4 cells wide (1.0, 1.5, 2.0 m: single-lane, single-lane, two lanes) and
  10-14 m long between two open rooms of 6 x 8 m; 2-6 AGVs split between both
  rooms, each with its goal in the other room;
- ``door`` and ``door-2m``: two 10 x 10 m rooms sharing a wall with one door
  1.0 m (2 cells) or 2.0 m wide; 6-12 AGVs, half in each room, swapping rooms;
- ``crossing``: a 4-way crossing of 1.5 m corridors (arms 7.5 m long, each
  ending in a 4.5 x 4.5 m room); 4-8 AGVs, each to the room of the opposite arm;
- ``warehouse-10``, ``warehouse-20``, ``warehouse-40``: a shelf warehouse
  (38 x 22 m for 10 AGVs, 62 x 32 m for 20 and 40) with 1 m shelves, 2 m
  aisles, 3 m cross aisles at both ends and a 2 m cross aisle in the middle;
  starts and goals inside aisles and at aisle ends, at most one start and one
  goal per aisle half, each goal at least a third of the map's width away;
- ``corridor-2-mirror``, ``corridor-3-mirror``, ``door-mirror``: the same maps
  (mirror-symmetric about the vertical line through the map's centre), with
  2, 4 or 6 (corridors) or 6-12 (door) AGVs: every AGV of the right room is the
  exact mirror of one in the left room, start, goal and heading.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from functools import cache

import numpy as np

from fleet.scenario import Scenario, parse_scenario
from planner.maps.clearance import Clearance
from planner.maps.costmap import point_clearance
from planner.maps.grid import GridMap
from planner.route.global_planner import plan_global

CELL = 0.5  # m: the cell of the family names (corridor-2 is 2 cells = 1.0 m wide)
RES = 0.25  # m per map cell: CELL / 2, so that the planner finds a way through 1.0 m
FINE = round(CELL / RES)
RADIUS = 0.3
SAFETY_DISTANCE = 0.5
CLEAR = RADIUS + 0.05  # least distance of a start or goal to an obstacle or the map's edge
MIN_SEPARATION = 1.0  # m, starts pairwise and goals pairwise
MOUTH_CLEAR = 1.5
"""m: least distance of a start or goal to a cell of a passage (door, corridor, arm). An
AGV that has arrived stays where it stopped; one parked in a door's mouth closes the door
for good, and two parked in both its mouths make a case no rule can solve (as generated
before: door-mirror n10 s1, 7 AGVs gave up). Stations are not placed in doorways."""
WAREHOUSE_SEPARATION = 1.5
MAX_SPEED = 1.0
VEHICLE = {"max_speed": MAX_SPEED, "max_accel": 0.5, "max_omega": 60, "max_alpha": 120}
DT = 0.1
SENSING_RADIUS = 5.0

FAMILIES = (
    "corridor-2", "corridor-3", "corridor-4", "door", "door-2m", "crossing",
    "warehouse-10", "warehouse-20", "warehouse-40",
    "corridor-2-mirror", "corridor-3-mirror", "door-mirror",
)  # fmt: skip
MIRROR_FAMILIES = ("corridor-2-mirror", "corridor-3-mirror", "door-mirror")


@dataclass(frozen=True)
class Agv:
    name: str
    start: tuple[float, float]
    goal: tuple[float, float]
    heading: float  # deg


@dataclass(frozen=True)
class TrafficCase:
    name: str  # e.g. "corridor-2/n4/s3"
    family: str
    seed: int
    agvs: int
    mirror: bool
    scenario: Scenario

    @property
    def toml(self) -> str:
        """The scenario as TOML text (``agv-fleet run`` reads it)."""
        return self.scenario.source

    @property
    def file_name(self) -> str:
        return self.name.replace("/", "_") + ".toml"


# --- maps ------------------------------------------------------------------------------
def _centre(col: float, row: float) -> tuple[float, float]:
    return ((col + 0.5) * CELL, (row + 0.5) * CELL)


def _spots(grid: GridMap, cols: range, rows: range, keep_off=(), clear: float = CLEAR) -> list:
    """Cell centres in the rectangle ``cols`` x ``rows`` at least ``clear`` from obstacles
    and ``MOUTH_CLEAR`` from every point of ``keep_off`` (the cells of the passages)."""
    off = np.asarray(keep_off, dtype=float).reshape(-1, 2)
    return [
        p
        for r in rows
        for c in cols
        if not grid.blocked[r, c]
        and point_clearance(grid, (p := _centre(c, r)), 2 * clear) >= clear - 1e-9
        and (not len(off) or np.hypot(*(off - p).T).min() >= MOUTH_CLEAR)
    ]


def _outside(grid: GridMap, rooms) -> list:
    """The centres of the free cells outside every room (cols, rows) of ``rooms``: the
    corridors, doors and arms between them."""
    inside = np.zeros(grid.blocked.shape, dtype=bool)
    for cols, rows in rooms:
        inside[rows.start : rows.stop, cols.start : cols.stop] = True
    rows, cols = np.nonzero(~grid.blocked & ~inside)
    return [_centre(c, r) for r, c in zip(rows, cols, strict=True)]


def _pick(rng, candidates: list, n: int, sep: float, taken=()) -> list:
    """``n`` of ``candidates`` (in a seeded random order), each at least ``sep`` from the
    ones picked before and from ``taken``."""
    chosen: list = []
    for i in rng.permutation(len(candidates)):
        p = candidates[int(i)]
        if all(math.dist(p, q) >= sep - 1e-9 for q in [*chosen, *taken]):
            chosen.append(p)
            if len(chosen) == n:
                return chosen
    raise ValueError(f"only {len(chosen)} of {n} places {sep} m apart")


def corridor_map(width_cells: int, length_cells: int) -> np.ndarray:
    """Two 6 x 8 m rooms joined by a straight corridor ``width_cells`` wide."""
    room_cols, rows = 12, 16
    blocked = np.zeros((rows, 2 * room_cols + length_cells), dtype=bool)
    lane = range((rows - width_cells) // 2, (rows - width_cells) // 2 + width_cells)
    for r in range(rows):
        if r not in lane:
            blocked[r, room_cols : room_cols + length_cells] = True
    return blocked


def door_map(door_cells: int) -> np.ndarray:
    """Two 10 x 10 m rooms either side of a one-cell wall with a door ``door_cells`` wide."""
    room, rows = 20, 20
    blocked = np.zeros((rows, 2 * room + 1), dtype=bool)
    blocked[:, room] = True
    low = (rows - door_cells) // 2
    blocked[low : low + door_cells, room] = False
    return blocked


ARM_CELLS, LANE_CELLS, ROOM_CELLS = 15, 3, 9  # crossing: 7.5 m arms, 1.5 m wide, 4.5 m rooms


def crossing_map() -> np.ndarray:
    size = 2 * (ROOM_CELLS + ARM_CELLS) + LANE_CELLS
    blocked = np.ones((size, size), dtype=bool)
    mid = ROOM_CELLS + ARM_CELLS  # first cell of the centre square
    blocked[mid : mid + LANE_CELLS, :] = False  # the east-west corridor
    blocked[:, mid : mid + LANE_CELLS] = False  # the north-south one
    lo = mid + LANE_CELLS // 2 - ROOM_CELLS // 2
    for r0, c0 in ((lo, 0), (lo, size - ROOM_CELLS), (0, lo), (size - ROOM_CELLS, lo)):
        blocked[r0 : r0 + ROOM_CELLS, c0 : c0 + ROOM_CELLS] = False
    return blocked


def _crossing_rooms() -> dict[str, tuple[range, range]]:
    """Each end room's (cols, rows), by compass direction."""
    size = 2 * (ROOM_CELLS + ARM_CELLS) + LANE_CELLS
    lo = ROOM_CELLS + ARM_CELLS + LANE_CELLS // 2 - ROOM_CELLS // 2
    span, far = range(lo, lo + ROOM_CELLS), range(size - ROOM_CELLS, size)
    near = range(ROOM_CELLS)
    return {"W": (near, span), "E": (far, span), "S": (span, near), "N": (span, far)}


# warehouse: (map width, map height) in cells, per fleet size
WAREHOUSE_SIZES = {10: (76, 44), 20: (124, 64), 40: (124, 64)}
SHELF_CELLS, AISLE_CELLS, END_AISLE_CELLS, MID_AISLE_CELLS, SIDE_CELLS = 2, 4, 6, 4, 6


def warehouse_map(width: int, height: int):
    """Shelves as blocked rectangles; the aisles' centre columns (x in m) and the two shelf
    bands' row ranges."""
    blocked = np.zeros((height, width), dtype=bool)
    band = (height - 2 * END_AISLE_CELLS - MID_AISLE_CELLS) // 2
    bands = (
        range(END_AISLE_CELLS, END_AISLE_CELLS + band),
        range(height - END_AISLE_CELLS - band, height - END_AISLE_CELLS),
    )
    aisles = []
    col = SIDE_CELLS
    while col + SHELF_CELLS + SIDE_CELLS <= width:
        for rows in bands:
            blocked[rows.start : rows.stop, col : col + SHELF_CELLS] = True
        right = col + SHELF_CELLS
        if right + AISLE_CELLS + SHELF_CELLS + SIDE_CELLS <= width:
            aisles.append((right + AISLE_CELLS / 2) * CELL)
        col = right + AISLE_CELLS
    return blocked, aisles, bands


# --- scenario text ---------------------------------------------------------------------
def _fmt(v: float) -> str:
    return f"{v:.3f}".rstrip("0").rstrip(".")


def _time_limit(grid: GridMap, agvs: list[Agv]) -> float:
    longest = max(_route_length(grid, a.start, a.goal) for a in agvs)
    return float(math.ceil((60 + 4 * (longest / MAX_SPEED + 10)) / 10) * 10)


def _route_length(grid: GridMap, start, goal) -> float:
    plan = plan_global(
        grid,
        start,
        goal,
        "improved",
        clearance=Clearance.from_safety_distance(RADIUS, SAFETY_DISTANCE),
    )
    if not plan.found:
        raise ValueError(f"no route from {start} to {goal}")
    return plan.length


def fine_map(blocked: np.ndarray) -> np.ndarray:
    """A map of ``CELL`` cells as the same obstacles in cells of ``RES``."""
    return blocked.repeat(FINE, axis=0).repeat(FINE, axis=1)


def scenario_text(name: str, description: str, blocked: np.ndarray, agvs: list[Agv]) -> str:
    """The scenario of ``agvs`` on ``blocked`` (cells of ``CELL``, drawn at ``RES``)."""
    blocked = fine_map(blocked)
    grid = GridMap(blocked, RES, name)
    lines = [
        f'name = "{name}"',
        f'description = "{description}"',
        f"dt = {DT}",
        f"time_limit = {_time_limit(grid, agvs):g}",
        f"sensing_radius = {SENSING_RADIUS}",
        'profile = "default"',
        "",
        "[map]",
        f"resolution = {RES}",
        f'grid = """\n{grid.to_text()}\n"""',
        "",
        "[planner]",
        'algorithm = "fusion"',
        f"safety_distance = {SAFETY_DISTANCE}",
        "",
        "[agv_defaults]",
        f"radius = {RADIUS}",
        *(f"{k} = {v:g}" for k, v in VEHICLE.items()),
    ]
    for a in agvs:
        lines += [
            "",
            "[[agvs]]",
            f'name = "{a.name}"',
            f"start = [{_fmt(a.start[0])}, {_fmt(a.start[1])}]",
            f"goal = [{_fmt(a.goal[0])}, {_fmt(a.goal[1])}]",
            f"heading = {a.heading:g}",
        ]
    return "\n".join(lines) + "\n"


def _case(family, seed, blocked, agvs, description, mirror=False) -> TrafficCase:
    name = f"{family}/n{len(agvs)}/s{seed}"
    text = scenario_text(name.replace("/", "_"), description, blocked, agvs)
    return TrafficCase(name, family, seed, len(agvs), mirror, parse_scenario(text))


def _rng(family: str, seed: int) -> np.random.Generator:
    return np.random.default_rng([zlib.crc32(family.encode()), seed])


def _mirror_x(width_m: float, p: tuple[float, float]) -> tuple[float, float]:
    return (round(width_m - p[0], 6), p[1])


def _two_rooms(family, seed, blocked, left_cols, right_cols, rows, n, mirror, what) -> TrafficCase:
    """AGVs in both rooms, each with its goal in the other; ``mirror``: the right room's
    AGVs are the left room's reflected about the map's vertical centre line."""
    rng = _rng(family, seed)
    grid = GridMap(blocked, CELL, family)
    width_m = blocked.shape[1] * CELL
    passages = _outside(grid, [(left_cols, rows), (right_cols, rows)])
    left_spots = _spots(grid, left_cols, rows, passages)
    right_spots = _spots(grid, right_cols, rows, passages)
    if mirror:
        half = n // 2
        starts = _pick(rng, left_spots, half, MIN_SEPARATION)
        goals = _pick(rng, right_spots, half, MIN_SEPARATION)
        agvs = [Agv(f"L{i + 1}", s, g, 0.0) for i, (s, g) in enumerate(zip(starts, goals))]
        agvs += [
            Agv(f"R{i + 1}", _mirror_x(width_m, a.start), _mirror_x(width_m, a.goal), 180.0)
            for i, a in enumerate(agvs)
        ]
        return _case(family, seed, blocked, agvs, f"{what}, mirror-symmetric", mirror=True)
    left = n // 2 + (int(rng.integers(0, 2)) if n % 2 else 0)
    right = n - left
    starts_l = _pick(rng, left_spots, left, MIN_SEPARATION)
    goals_r = _pick(rng, right_spots, left, MIN_SEPARATION)
    starts_r = _pick(rng, right_spots, right, MIN_SEPARATION)
    goals_l = _pick(rng, left_spots, right, MIN_SEPARATION)
    agvs = [Agv(f"L{i + 1}", s, g, 0.0) for i, (s, g) in enumerate(zip(starts_l, goals_r))]
    agvs += [Agv(f"R{i + 1}", s, g, 180.0) for i, (s, g) in enumerate(zip(starts_r, goals_l))]
    return _case(family, seed, blocked, agvs, what)


def corridor_case(width_cells: int, seed: int, mirror: bool = False) -> TrafficCase:
    family = f"corridor-{width_cells}" + ("-mirror" if mirror else "")
    rng = _rng(family, seed)
    length = int(rng.integers(20, 29))  # 10-14 m
    n = int(rng.choice([2, 4, 6])) if mirror else int(rng.integers(2, 7))
    if seed == 0:  # seed 0: the smallest case of each family (the fast subset)
        n = 2
    blocked = corridor_map(width_cells, length)
    what = f"corridor {width_cells * CELL:g} m wide, {length * CELL:g} m long, {n} AGVs"
    cols = blocked.shape[1]
    return _two_rooms(
        family, seed, blocked, range(0, 12), range(cols - 12, cols), range(16), n, mirror, what
    )


def door_case(seed: int, door_cells: int = 2, mirror: bool = False) -> TrafficCase:
    family = "door-mirror" if mirror else "door" if door_cells == 2 else "door-2m"
    rng = _rng(family, seed)
    n = 6 if seed == 0 else 2 * int(rng.integers(3, 7))  # 6-12, half in each room
    blocked = door_map(door_cells)
    what = f"two 10 x 10 m rooms, a door {door_cells * CELL:g} m wide, {n} AGVs swapping rooms"
    return _two_rooms(
        family, seed, blocked, range(0, 20), range(21, 41), range(20), n, mirror, what
    )


OPPOSITE = {"W": "E", "E": "W", "S": "N", "N": "S"}
HEADING = {"W": 0.0, "E": 180.0, "S": 90.0, "N": 270.0}


def crossing_case(seed: int) -> TrafficCase:
    family = "crossing"
    rng = _rng(family, seed)
    n = 4 if seed == 0 else int(rng.integers(4, 9))
    blocked = crossing_map()
    grid = GridMap(blocked, CELL, family)
    rooms = _crossing_rooms()
    order = list("WESN")
    arms = order + [order[int(i)] for i in rng.choice(4, n - 4, replace=False)]
    passages = _outside(grid, rooms.values())
    spots = {k: _spots(grid, *rooms[k], passages) for k in order}
    starts = {k: _pick(rng, spots[k], arms.count(k), MIN_SEPARATION) for k in order}
    goals = {k: _pick(rng, spots[OPPOSITE[k]], arms.count(k), MIN_SEPARATION) for k in order}
    agvs = []
    for k in order:
        for i, (s, g) in enumerate(zip(starts[k], goals[k])):
            agvs.append(Agv(f"{k}{i + 1}", s, g, HEADING[k]))
    what = f"4-way crossing of 1.5 m corridors, {n} AGVs to the opposite arm"
    return _case(family, seed, blocked, agvs, what)


def warehouse_case(agvs: int, seed: int) -> TrafficCase:
    family = f"warehouse-{agvs}"
    rng = _rng(family, seed)
    width, height = WAREHOUSE_SIZES[agvs]
    blocked, aisles, bands = warehouse_map(width, height)
    grid = GridMap(blocked, CELL, family)
    # places: inside the aisles (grouped by aisle half) and at the aisle ends
    places: list[tuple[tuple[float, float], object]] = []
    for i, x in enumerate(aisles):
        for b, rows in enumerate(bands):
            for r in range(rows.start + 1, rows.stop - 1, 2):
                places.append(((x, (r + 0.5) * CELL), (i, b)))
        for r in (END_AISLE_CELLS // 2, height - END_AISLE_CELLS // 2):
            places.append(((x, r * CELL), None))
    places = [(p, g) for p, g in places if point_clearance(grid, p, 1.0) >= CLEAR]
    min_trip = width * CELL / 3

    def pick(taken_groups: set, chosen: list, far_from=None):
        for i in rng.permutation(len(places)):
            p, g = places[int(i)]
            if g is not None and g in taken_groups:
                continue
            if any(math.dist(p, q) < WAREHOUSE_SEPARATION - 1e-9 for q in chosen):
                continue
            if far_from is not None and math.dist(p, far_from) < min_trip:
                continue
            if g is not None:
                taken_groups.add(g)
            return p
        raise ValueError(f"{family} seed {seed}: no place left")

    start_groups: set = set()
    goal_groups: set = set()
    starts: list = []
    goals: list = []
    for _ in range(agvs):
        starts.append(pick(start_groups, starts))
        goals.append(pick(goal_groups, goals, far_from=starts[-1]))
    out = [
        Agv(f"agv{i + 1}", s, g, 90.0 if s[1] < height * CELL / 2 else 270.0)
        for i, (s, g) in enumerate(zip(starts, goals))
    ]
    what = f"shelf warehouse {width * CELL:g} x {height * CELL:g} m, 2 m aisles, {agvs} AGVs"
    return _case(family, seed, blocked, out, what)


@cache
def make_case(family: str, seed: int) -> TrafficCase:
    """Case ``seed`` of ``family`` (deterministic: the same case for the same arguments)."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}: choose from {', '.join(FAMILIES)}")
    if family.startswith("corridor-"):
        return corridor_case(int(family.split("-")[1]), seed, mirror=family.endswith("mirror"))
    if family == "door":
        return door_case(seed)
    if family == "door-2m":
        return door_case(seed, door_cells=4)
    if family == "door-mirror":
        return door_case(seed, mirror=True)
    if family == "crossing":
        return crossing_case(seed)
    return warehouse_case(int(family.split("-")[1]), seed)


def cases(families=FAMILIES, seeds: int = 5) -> list[TrafficCase]:
    """Seeds 0 .. seeds-1 of every family in ``families``, family by family."""
    return [make_case(f, s) for f in families for s in range(seeds)]


def fast_subset() -> list[TrafficCase]:
    """Six small cases for outcome tests: corridor-2 with 2 mirror-symmetric AGVs,
    corridor-3 with 2, corridor-4 with 4, the 1 m door with 6, the crossing with 4 and a
    10-AGV warehouse."""
    out = [make_case("corridor-2-mirror", 0), make_case("corridor-3", 0)]
    out.append(next(c for s in range(50) if (c := make_case("corridor-4", s)).agvs == 4))
    out += [make_case("door", 0), make_case("crossing", 0), make_case("warehouse-10", 0)]
    return out
