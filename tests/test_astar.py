"""A* on the MovingAI benchmarks (known optima) and the improved variant's rules."""

from __future__ import annotations

import numpy as np
import pytest

from planner.core.path_metrics import path_length
from planner.maps.grid import GridMap
from planner.maps.movingai import load_movingai, load_movingai_scenarios
from planner.maps.text_maps import parse_text_grid
from planner.route.astar import search

SCENARIO_FILES = ("random-32-32-20-random-1.scen", "arena.map.scen")


def _scenarios(public_data):
    for scen_name in SCENARIO_FILES:
        scen_path = public_data / "movingai" / scen_name
        for entry in load_movingai_scenarios(scen_path):
            yield scen_path.parent / entry.map_name, entry


def test_traditional_astar_is_optimal_on_every_movingai_scenario(public_data):
    grids = {}
    checked = 0
    for map_path, e in _scenarios(public_data):
        grid = grids.setdefault(map_path, load_movingai(map_path))
        result = search(grid, (e.start_col, e.start_row), (e.goal_col, e.goal_row))
        assert result.found, (map_path.name, e)
        assert path_length(result.cells) == pytest.approx(e.optimal_length, abs=1e-6), (
            map_path.name,
            e,
        )
        checked += 1
    assert checked == 539


def test_search_steps_are_unit_moves_without_corner_cutting(public_data):
    grid = load_movingai(public_data / "movingai" / "random-32-32-20.map")
    rows, cols = np.nonzero(~grid.blocked)  # first and last free cell in row-major order
    result = search(grid, (int(cols[0]), int(rows[0])), (int(cols[-1]), int(rows[-1])))
    assert result.found
    for (c0, r0), (c1, r1) in zip(result.cells, result.cells[1:], strict=False):
        assert max(abs(c1 - c0), abs(r1 - r0)) == 1
        assert not grid.blocked[r1, c1]
        if c1 != c0 and r1 != r0:  # diagonal: both side cells free
            assert not grid.blocked[r0, c1] and not grid.blocked[r1, c0]


def test_corner_cutting_is_only_allowed_when_asked():
    grid = parse_text_grid("#.\n.#")  # the only way through is the blocked corner
    assert not search(grid, (0, 0), (1, 1)).found
    cut = search(grid, (0, 0), (1, 1), corner_cutting=True)
    assert cut.cells == [(0, 0), (1, 1)]


def test_unreachable_goal_is_a_result_not_an_error():
    grid = parse_text_grid("..#..\n..#..\n..#..")
    result = search(grid, (0, 0), (4, 2))
    assert not result.found and result.cells == []
    assert result.expansions == 6  # every reachable cell but the goal side was expanded


def test_blocked_start_is_rejected():
    grid = parse_text_grid("#..")
    with pytest.raises(ValueError, match="start"):
        search(grid, (0, 0), (2, 0))


def test_improved_expands_only_four_neighbours_next_to_an_obstacle():
    # start (1,1) has an obstacle to its right: its first step must be orthogonal
    grid = parse_text_grid(".....\n.....\n.#...\n.S#..\n.....".replace("S", "."))
    result = search(grid, (1, 1), (4, 4), improved=True)
    (c0, r0), (c1, r1) = result.cells[:2]
    assert abs(c1 - c0) + abs(r1 - r0) == 1
    traditional = search(grid, (1, 1), (4, 4))
    assert traditional.found


def test_improved_weight_uses_obstacles_in_node_goal_rectangle():
    rng = np.random.default_rng(5)
    grid = GridMap(rng.random((30, 40)) < 0.3)
    for _ in range(200):
        a = (int(rng.integers(40)), int(rng.integers(30)))
        b = (int(rng.integers(40)), int(rng.integers(30)))
        c0, c1 = sorted((a[0], b[0]))
        r0, r1 = sorted((a[1], b[1]))
        assert grid.obstacles_in_rect(a, b) == int(grid.blocked[r0 : r1 + 1, c0 : c1 + 1].sum())


def test_improved_search_expands_fewer_nodes_on_open_maps():
    rng = np.random.default_rng(1)
    blocked = rng.random((120, 120)) < 0.15
    blocked[0, 0] = blocked[-1, -1] = False
    grid = GridMap(blocked)
    traditional = search(grid, (0, 0), (119, 119))
    improved = search(grid, (0, 0), (119, 119), improved=True)
    assert traditional.found and improved.found
    assert improved.expansions < traditional.expansions
    assert path_length(improved.cells) >= path_length(traditional.cells) - 1e-9
