"""The default profile's global planner: the AGV's body fits on every route.

On Nav2's depot and TurtleBot3 sandbox maps (ROS map frame, 0.05 m cells), on the five
20x20 literature maps and on 50 seeded 50x50 maps: every point of every improved
key-node route keeps at least the AGV radius from every obstacle (and unknown) cell and
the map's border, measured exactly by tests.footprint_check (no planner code); routes
on the Nav2 and 20x20 maps have at most 15 turning points; traditional A* on the costmap
costs what an independent Dijkstra on the same lethal cells and penalties finds.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from fleet.paper.experiments import corner_free_cell
from planner.core.errors import MapError
from planner.maps.clearance import Clearance, ClearanceError, clearance_for
from planner.maps.costmap import COST_WEIGHT, Costmap, centre_distances
from planner.maps.grid import GridMap
from planner.maps.loaders import load_map
from planner.maps.random_map import random_map
from planner.maps.text_maps import load_matrix_text, parse_text_grid
from planner.route.global_planner import plan_global
from tests.footprint_check import MapView, centre_distance, dijkstra, path_cost

CLEARANCE = Clearance(0.3, 0.2)
MAX_TURNS = 15
NAV2 = ("depot.yaml", "tb3_sandbox.yaml")
GRID20 = (
    "map20_IAstar_LOS_unknownrepo.txt",
    "map20_classic_aco_xuedidi.txt",
    "map20_improved_ant_winsleo.txt",
    "map20_jsntjyz_graduation.txt",
    "map20_winsleo_commented.txt",
)
TOL = 1e-9


def _view(grid: GridMap) -> MapView:
    return MapView(grid.blocked, grid.resolution, grid.origin)


def _independent_costs(grid: GridMap):
    """Lethal cells and penalties computed here from the map alone (dilation)."""
    r, m = CLEARANCE.radius, CLEARANCE.margin
    distance = centre_distance(grid.blocked, grid.resolution, r + m)
    lethal = distance < r
    penalty = COST_WEIGHT * np.clip((r + m - distance) / m, 0.0, 1.0)
    return lethal, penalty


def _check_plans(grid, start, goal, lethal, penalty, max_turns=MAX_TURNS):
    """Both A* variants on the costmap: route clearance, turns, traditional optimal."""
    view = _view(grid)
    improved = plan_global(grid, start, goal, "improved", profile="default", clearance=CLEARANCE)
    traditional = plan_global(
        grid, start, goal, "traditional", profile="default", clearance=CLEARANCE
    )
    assert improved.found and traditional.found, (grid.name, start, goal)
    assert improved.key_nodes[0] == start and improved.key_nodes[-1] == goal
    gap = view.route_clearance(improved.key_nodes)
    assert gap >= CLEARANCE.radius - TOL, (grid.name, start, goal, gap)
    assert improved.clearance == pytest.approx(min(gap, 2.0), abs=1e-9)
    assert view.route_clearance(traditional.key_nodes) >= CLEARANCE.radius - TOL
    if max_turns is not None:
        assert improved.turns <= max_turns, (grid.name, start, goal, improved.turns)
    cells = traditional.cells
    assert not any(lethal[r, c] for c, r in cells[1:-1])
    best = dijkstra(lethal, penalty, cells[0], cells[-1])
    assert path_cost(cells, penalty) == pytest.approx(best, rel=1e-9, abs=1e-9)
    return improved, traditional


def _pairs(grid: GridMap, lethal: np.ndarray, penalty: np.ndarray, count: int, seed: int):
    """``count`` seeded start/goal pairs in the map frame where the AGV stands clear (its
    point and its cell's centre keep the radius) and the goal can be reached."""
    rng = np.random.default_rng(seed)
    view = _view(grid)
    need = CLEARANCE.radius + grid.resolution
    # candidate cells, then a uniform point in the cell, kept if it stands clear
    rows, cols = np.nonzero(centre_distance(grid.blocked, grid.resolution, need) >= need)
    pairs = []
    while len(pairs) < count:
        points = []
        while len(points) < 2:
            i = int(rng.integers(len(rows)))
            x, y = grid.centre_of((int(cols[i]), int(rows[i])))
            p = tuple(float(v + rng.uniform(-0.5, 0.5) * grid.resolution) for v in (x, y))
            if view.point_clearance(p) >= need:
                points.append(p)
        cells = [grid.cell_of(p) for p in points]
        if math.isfinite(dijkstra(lethal, penalty, *cells)):
            pairs.append(tuple(points))
    return pairs


# --- Must show: the Nav2 maps --------------------------------------------------------
@pytest.mark.parametrize("name", NAV2)
def test_nav2_routes_keep_the_body_clear(public_data, name):
    grid = load_map(public_data / "nav2" / name)
    lethal, penalty = _independent_costs(grid)
    costmap = Costmap.for_grid(grid, CLEARANCE)
    assert np.array_equal(costmap.lethal, lethal)
    assert np.allclose(np.minimum(costmap.distance, 0.5), np.minimum(centre_distance(
        grid.blocked, grid.resolution, 0.5), 0.5), atol=1e-9)  # fmt: skip
    turns = []
    for start, goal in _pairs(grid, lethal, penalty, 20, seed=10):
        improved, _ = _check_plans(grid, start, goal, lethal, penalty)
        turns.append(improved.turns)
    assert max(turns) <= MAX_TURNS


def test_sandbox_coordinates_are_the_ros_map_frame(public_data):
    grid = load_map(public_data / "nav2" / "tb3_sandbox.yaml")
    assert grid.origin == (-10.0, -10.0)
    assert grid.extent == pytest.approx((-10.0, 9.2, -10.0, 9.2))
    # the sandbox's pillars stand around the map frame's origin, as RViz shows them
    plan = plan_global(grid, (-1.6, -0.6), (1.6, 0.6), "improved", profile="default")
    assert plan.found and plan.key_nodes[0] == (-1.6, -0.6)
    with pytest.raises(MapError, match=r"outside the map \(x in \[-10, 9.2\)"):
        plan_global(grid, (15.0, 0.0), (1.6, 0.6), profile="default")


# --- Must show: the paper's maps, default profile ----------------------------------------
def test_grid20_routes_keep_the_body_clear(public_data):
    for name in GRID20:
        grid = load_matrix_text(public_data / "grid20" / name)
        lethal, penalty = _independent_costs(grid)
        start = grid.centre_of(corner_free_cell(grid, "bottom-left"))
        goal = grid.centre_of(corner_free_cell(grid, "top-right"))
        _check_plans(grid, start, goal, lethal, penalty)


def test_random50_routes_keep_the_body_clear():
    """Random 50x50 maps with 20-30 % obstacles are mazes: their routes turn more than
    15 times with any planner (the paper's improved A* averages 22), so only the
    clearance and the optimality are checked here."""
    checked = seed = 0
    while checked < 50:
        ratio = 0.20 + 0.10 * (seed % 11) / 10
        grid = random_map(50, 50, ratio, seed, keep_free=[(0, 0), (49, 49)])
        seed += 1
        lethal, penalty = _independent_costs(grid)
        if not math.isfinite(dijkstra(lethal, penalty, (0, 0), (49, 49))):
            assert not plan_global(grid, (0.5, 0.5), (49.5, 49.5), profile="default").found
            continue
        _check_plans(grid, (0.5, 0.5), (49.5, 49.5), lethal, penalty, max_turns=None)
        checked += 1


# --- the costmap itself ----------------------------------------------------------------
def test_centre_distances_are_exact_to_squares_and_border():
    rng = np.random.default_rng(3)
    for _ in range(20):
        h, w = (int(v) for v in rng.integers(1, 30, 2))
        blocked = rng.random((h, w)) < rng.random() * 0.3
        got = centre_distances(blocked)
        view = MapView(blocked, 1.0)
        for r, c in zip(*np.nonzero(rng.random((h, w)) < 0.2), strict=True):
            want = 0.0 if blocked[r, c] else view.point_clearance((c + 0.5, r + 0.5), reach=99)
            assert got[r, c] == pytest.approx(want, abs=1e-12)


def test_lethal_is_measured_to_the_square_not_its_centre():
    # one obstacle cell at 0.1 m: a cell whose centre is 0.25 m from the square's edge
    # (0.35 m from its centre) is lethal for a 0.3 m AGV
    blocked = np.zeros((41, 41), dtype=bool)
    blocked[20, 20] = True
    grid = GridMap(blocked, 0.1)
    cm = Costmap.for_grid(grid, Clearance(0.3, 0.2))
    assert cm.distance[20, 23] == pytest.approx(0.25)
    assert cm.lethal[20, 23] and not cm.lethal[20, 24]
    assert cm.penalty[20, 24] == pytest.approx(COST_WEIGHT * (0.5 - 0.35) / 0.2)
    assert cm.penalty[20, 26] == 0.0  # 0.55 m: beyond the margin
    assert cm.lethal[0, :].all() and not cm.lethal[3, 3]  # the border is a wall


def test_costmap_is_cached_per_map_and_clearance_and_updated_with_sensed_cells():
    grid = parse_text_grid("\n".join(["." * 30] * 20), resolution=0.1)
    first = Costmap.for_grid(grid, CLEARANCE)
    assert Costmap.for_grid(grid, CLEARANCE) is first
    assert Costmap.for_grid(grid, Clearance(0.4, 0.2)) is not first
    seen = first.with_blocked([(15, 10)])
    assert seen.grid.blocked[10, 15] and not first.grid.blocked[10, 15]
    assert seen.lethal[10, 12] and not first.lethal[10, 12]
    assert np.array_equal(seen.lethal, Costmap.build(seen.grid, CLEARANCE).lethal)


def test_costmap_of_a_large_map_is_fast():
    blocked = np.random.default_rng(0).random((1000, 1700)) < 0.05
    grid = GridMap(blocked, 0.05)
    Costmap.build(GridMap(blocked[:20, :20], 0.05), CLEARANCE)  # compiled or loaded
    t0 = time.perf_counter()
    Costmap.for_grid(grid, CLEARANCE)
    assert time.perf_counter() - t0 < 1.0


def test_a_gap_narrower_than_the_agv_is_not_taken():
    # a wall with a 0.4 m gap (at 0.1 m cells) between two rooms, and a 1 m door further on
    rows = ["." * 40 for _ in range(30)]
    wall = ["#" * 40 for _ in range(1)]
    grid_rows = rows[:15] + wall + rows[16:]
    text = [list(r) for r in grid_rows]
    for c in range(5, 9):  # the 0.4 m gap
        text[15][c] = "."
    for c in range(30, 40):  # the 1 m door
        text[15][c] = "."
    grid = parse_text_grid("\n".join("".join(r) for r in text), resolution=0.1)
    paper = plan_global(grid, (0.65, 0.5), (0.65, 2.5), "improved", profile="paper")
    default = plan_global(grid, (0.65, 0.5), (0.65, 2.5), "improved", profile="default")
    assert paper.found and default.found
    assert paper.length < 2.5  # straight through the gap the body does not fit
    assert default.length > 5.0  # round by the door
    assert _view(grid).route_clearance(default.key_nodes) >= 0.3 - TOL


def test_a_start_inside_the_lethal_band_escapes_it():
    # DWA may bring an AGV closer to a wall than its radius: it must still be able to plan
    grid = parse_text_grid("\n".join(["." * 40] * 20), resolution=0.1)
    plan = plan_global(grid, (0.15, 1.05), (3.5, 1.05), "improved", profile="default")
    assert plan.found and plan.key_nodes[0] == (0.15, 1.05)
    blocked = parse_text_grid("#.\n..", resolution=1.0)
    with pytest.raises(MapError, match="inside an obstacle"):
        plan_global(blocked, (0.5, 1.5), (1.5, 0.5), profile="default")


# --- the one place for clearance --------------------------------------------------------
def test_a_safety_distance_below_the_radius_is_an_error():
    assert clearance_for(0.3).safety_distance == pytest.approx(0.5)
    assert clearance_for(0.3, safety_distance=0.45).margin == pytest.approx(0.15)
    assert clearance_for(0.4, margin=0.1).safety_distance == pytest.approx(0.5)
    with pytest.raises(ClearanceError, match="below the AGV radius"):
        clearance_for(0.3, safety_distance=0.2)
    with pytest.raises(ClearanceError, match="disagree"):
        clearance_for(0.3, margin=0.1, safety_distance=0.5)
    with pytest.raises(ClearanceError, match="margin must be >= 0"):
        Clearance(0.3, -0.1)
    grid = parse_text_grid("....")
    with pytest.raises(ValueError, match="below the AGV radius"):
        plan_global(grid, (0.5, 0.5), (3.5, 0.5), profile="default", safety_distance=0.1)
