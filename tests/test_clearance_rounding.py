"""Clearance compared with a radius holds for every radius and resolution: metres turned
into cells and back round (0.11 / 0.05 * 0.05 = 0.10999999999999999), and a TurtleBot3-
sized AGV (0.105 or 0.11 m) could not be placed anywhere on a 5 cm map. Radii 0.1-0.5 m
in 1 mm steps on 2, 3, 5 and 10 cm maps, against exact rational arithmetic."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from PIL import Image

from fleet.runtime.inprocess import run_in_process
from fleet.scenario import ScenarioError, load_scenario
from planner.maps.clearance import Clearance, keeps
from planner.maps.costmap import Costmap, point_clearance
from planner.maps.grid import GridMap
from planner.maps.ros_map import load_ros_map
from planner.route.key_nodes import extract_key_nodes
from tests.test_map_images import DATA, pgm_pixels, twin

RESOLUTIONS_MM = (20, 30, 50, 100)
RADII_MM = range(100, 501)


def one_obstacle(res_mm: int) -> tuple[GridMap, int]:
    """A map 3.2 m wide with one obstacle cell in the middle, and that cell's index."""
    middle = -(-1600 // res_mm)
    blocked = np.zeros((2 * middle + 1, 2 * middle + 1), dtype=bool)
    blocked[middle, middle] = True
    return GridMap(blocked, res_mm / 1000, "one", (-1.3, 2.7)), middle


@pytest.mark.parametrize("res_mm", RESOLUTIONS_MM)
def test_point_clearance_meets_the_radius_exactly_where_it_should(res_mm):
    grid, middle = one_obstacle(res_mm)
    res = grid.resolution
    edge = grid.origin[0] + (middle + 1) * res  # the obstacle square's right edge
    y = grid.origin[1] + (middle + 0.5) * res
    for r_mm in RADII_MM:
        r = r_mm / 1000
        far = point_clearance(grid, (edge + 2 * r, y), r)
        assert far == r and keeps(far, r), (res_mm, r_mm)
        assert keeps(point_clearance(grid, (edge + r, y), r), r), (res_mm, r_mm)
        assert not keeps(point_clearance(grid, (edge + r - 0.001, y), r), r), (res_mm, r_mm)


@pytest.mark.parametrize("res_mm", RESOLUTIONS_MM)
def test_costmap_lethal_cells_are_those_exactly_closer_than_the_radius(res_mm):
    grid, middle = one_obstacle(res_mm)
    res = Fraction(res_mm, 1000)
    reach = -(-600 // res_mm)  # cells within 0.6 m of the obstacle: the border is > 1 m away
    window = slice(middle - reach, middle + reach + 1)
    size = 2 * reach + 1
    offsets = np.abs(np.arange(size) - reach)
    gaps = [Fraction(2 * int(k) - 1, 2) * res if k else Fraction(0) for k in range(size)]
    squared = {(a, b): gaps[a] ** 2 + gaps[b] ** 2 for a in range(size) for b in range(size)}
    ties = 0
    for r_mm in RADII_MM:
        r = Fraction(r_mm, 1000)
        lethal = Costmap.build(grid, Clearance(r_mm / 1000, 0.0)).lethal[window, window]
        exact = np.array(
            [
                [squared[offsets[row], offsets[col]] < r * r for col in range(size)]
                for row in range(size)
            ]
        )
        assert np.array_equal(lethal, exact), (res_mm, r_mm)
        ties += sum(
            squared[offsets[row], offsets[col]] == r * r
            for row in range(size)
            for col in range(size)
        )
    if res_mm in (20, 50, 100):  # e.g. 0.125 m = 2.5 cells of 5 cm: a cell exactly r away
        assert ties


def test_paper_key_nodes_need_more_than_the_safety_distance_after_rounding():
    # from cell (6, 5) to (8, 5) past an obstacle centre 3 cells of 5 cm above (6, 5):
    # exactly 0.15 m, which is not *farther* than a 0.15 m safety distance
    blocked = np.zeros((14, 13), dtype=bool)
    blocked[8, 6] = True
    grid = GridMap(blocked, 0.05, "t")
    path = [(4, 5), (5, 5), (6, 5), (7, 6), (8, 5)]
    assert 0.15 / 0.05 < 3  # the rounding that made it look farther
    assert (7, 6) in extract_key_nodes(grid, path, 0.15)
    assert (7, 6) not in extract_key_nodes(grid, path, 0.149)


SCENARIO = """
name = "tb3"
[map]
file = "{map}"
[[agvs]]
name = "a"
radius = {radius}
start = [{x}, {y}]
goal = [1.8, 0.0]
"""


@pytest.mark.parametrize("radius", [0.105, 0.11])
def test_a_turtlebot_sized_agv_can_be_placed_where_it_fits(tmp_path, radius):
    grid = load_ros_map(DATA / "tb3_sandbox.yaml")
    assert point_clearance(grid, (-1.53, 0.78), radius) == radius
    path = tmp_path / "tb3.toml"
    path.write_text(SCENARIO.format(map=DATA / "tb3_sandbox.yaml", radius=radius, x=-1.53, y=0.78))
    assert load_scenario(path).agvs[0].start == (-1.53, 0.78)
    # a free cell whose centre is closer to a wall than the radius is refused, and says so
    distance = Costmap.for_grid(grid, Clearance(radius, 0.0)).distance
    row, col = np.argwhere((distance > radius / 2) & (distance < radius - 0.001))[0]
    x, y = grid.centre_of((int(col), int(row)))
    path.write_text(SCENARIO.format(map=DATA / "tb3_sandbox.yaml", radius=radius, x=x, y=y))
    with pytest.raises(ScenarioError, match=r"start .* m from an obstacle or the map's edge"):
        load_scenario(path)


TB3_SANDBOX_RUN = """
name = "tb3-sandbox-3"
description = "Three TurtleBot3-sized AGVs (radius 0.105 m) between the sandbox pillars"
dt = 0.1
time_limit = 200

[map]
file = "MAP"

[planner]
algorithm = "fusion"
margin = 0.1

[agv_defaults]
radius = 0.105
max_speed = 0.5

[[agvs]]
name = "tb1"
start = [-1.8, 0.0]
goal = [1.8, 0.0]

[[agvs]]
name = "tb2"
start = [0.0, 1.8]
goal = [0.0, -1.8]
heading = -90

[[agvs]]
name = "tb3"
start = [1.6, -1.0]
goal = [-1.6, 1.0]
heading = 180
"""


def test_three_turtlebot_sized_agvs_cross_the_tb3_sandbox_png_and_all_arrive(tmp_path):
    """The TurtleBot3 sandbox (5 cm cells, read from a PNG twin of Nav2's PGM): three
    0.105 m AGVs between its pillars, every one arrives with no collision."""
    png = twin(tmp_path, "tb3_sandbox", Image.fromarray(pgm_pixels("tb3_sandbox"), "L"), ".png")
    path = tmp_path / "tb3.toml"
    path.write_text(TB3_SANDBOX_RUN.replace("MAP", str(png)))
    summary = run_in_process(load_scenario(path))
    assert summary.success, summary.table()
    assert [a.status for a in summary.agvs] == ["arrived"] * 3
