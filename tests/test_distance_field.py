"""DistanceField: exact distances to obstacle squares and the map border, vectorised lookup."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.maps.distance_field import DistanceField, choose_subdivision
from planner.maps.grid import GridMap

TOLERANCE = 0.05


def one_obstacle(size: int = 11, cell: tuple[int, int] = (5, 5), resolution: float = 1.0):
    blocked = np.zeros((size, size), dtype=bool)
    blocked[cell[1], cell[0]] = True
    return GridMap(blocked, resolution)


def brute_force(grid: GridMap, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest obstacle square or the map border."""
    res = grid.resolution
    rows, cols = np.nonzero(grid.blocked)
    dx = np.maximum.reduce([cols * res - x, np.zeros(len(cols)), x - (cols + 1) * res])
    dy = np.maximum.reduce([rows * res - y, np.zeros(len(rows)), y - (rows + 1) * res])
    to_cells = np.hypot(dx, dy).min(initial=math.inf)
    width, height = grid.size_m
    return min(to_cells, x, y, width - x, height - y)


def test_distance_to_a_face_of_one_obstacle_cell():
    field = DistanceField.from_grid(one_obstacle())  # the obstacle is the square [5, 6] x [5, 6]
    assert field.distance_at(7.5, 5.5) == pytest.approx(1.5, abs=TOLERANCE)
    assert field.distance_at(5.5, 3.5) == pytest.approx(1.5, abs=TOLERANCE)
    assert field.distance_at(7.43, 5.57) == pytest.approx(1.43, abs=TOLERANCE)


def test_distance_to_a_corner_is_pythagorean():
    field = DistanceField.from_grid(one_obstacle())
    assert field.distance_at(7.0, 7.5) == pytest.approx(math.hypot(1.0, 1.5), abs=TOLERANCE)
    assert field.distance_at(4.2, 3.9) == pytest.approx(math.hypot(0.8, 1.1), abs=TOLERANCE)


def test_the_map_border_is_a_wall_and_outside_is_not_free():
    field = DistanceField.from_grid(GridMap(np.zeros((4, 6), dtype=bool)))
    assert field.distance_at(0.7, 2.0) == pytest.approx(0.7, abs=TOLERANCE)
    assert field.distance_at(5.8, 2.0) == pytest.approx(0.2, abs=TOLERANCE)
    assert field.distance_at(3.0, 2.0) == pytest.approx(2.0, abs=TOLERANCE)
    outside = field.distance_at([-1.0, 3.0, 7.0, 3.0, np.nan], [2.0, -0.5, 2.0, 9.0, 1.0])
    assert np.all(outside <= 0)


def test_inside_an_obstacle_is_zero():
    field = DistanceField.from_grid(one_obstacle())
    assert field.distance_at(5.5, 5.5) == 0.0


def test_matches_brute_force_on_a_random_map_at_several_resolutions():
    rng = np.random.default_rng(7)
    for resolution in (1.0, 0.5, 0.25):
        grid = GridMap(rng.random((20, 30)) < 0.2, resolution)
        field = DistanceField.from_grid(grid)
        width, height = grid.size_m
        xs, ys = rng.random(3000) * width, rng.random(3000) * height
        expected = np.array([brute_force(grid, x, y) for x, y in zip(xs, ys, strict=True)])
        error = field.distance_at(xs, ys) - expected
        assert np.abs(error).max() <= TOLERANCE, resolution
        assert error.max() <= 0.02, resolution  # overestimates (the unsafe side) are tiny


def test_keeps_the_shape_of_the_query():
    field = DistanceField.from_grid(one_obstacle())
    assert field.distance_at(np.full((2, 3), 7.5), np.full((2, 3), 5.5)).shape == (2, 3)
    assert field.distance_at(7.5, np.array([5.5, 8.0])).shape == (2,)
    assert np.ndim(field.distance_at(7.5, 5.5)) == 0


def test_distances_are_in_metres_with_fine_cells():
    field = DistanceField.from_grid(one_obstacle(resolution=0.5))  # obstacle [2.5, 3] x [2.5, 3]
    assert field.distance_at(4.0, 2.75) == pytest.approx(1.0, abs=TOLERANCE)


def test_with_blocked_adds_obstacles_and_leaves_the_original_alone():
    field = DistanceField.from_grid(one_obstacle())
    nearer = field.with_blocked([(7, 5)])  # the square [7, 8] x [5, 6]
    assert nearer.distance_at(7.5, 5.5) == 0.0
    assert nearer.distance_at(7.5, 3.5) == pytest.approx(1.5, abs=TOLERANCE)
    assert field.distance_at(7.5, 5.5) == pytest.approx(1.5, abs=TOLERANCE)
    assert nearer.subdivision == field.subdivision


def test_subdivision_keeps_the_lattice_fine_for_metre_cells():
    assert one_obstacle().resolution / choose_subdivision(one_obstacle()) <= 0.1
    assert choose_subdivision(one_obstacle(resolution=0.05)) == 1
    with pytest.raises(ValueError, match="subdivision"):
        DistanceField.from_grid(one_obstacle(), subdivision=0)


def test_a_runs_agvs_and_its_world_share_one_field_of_the_map():
    """The field is built once per map, not once per AGV: at 100 AGVs on a 128 x 80 m map
    one field each was 20 MiB of memory per AGV process and 3 s of start-up (issue 42)."""
    from fleet.builtin import builtin_scenarios
    from fleet.runtime.agv_node import AgvNode
    from fleet.runtime.world import World
    from fleet.scenario import load_scenario

    scenario = load_scenario(builtin_scenarios()["warehouse"])
    a, b = (AgvNode(scenario, s.name) for s in scenario.agvs[:2])
    shared = DistanceField.for_grid(scenario.grid)
    assert a.controller.plans.static_field is shared
    assert b.controller.plans.static_field is shared
    assert World(scenario)._static is shared
    assert np.array_equal(shared.samples, DistanceField.from_grid(scenario.grid).samples)
