"""The paper's claims for the improved planner, and the plan result's contract."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fleet.paper.experiments import corner_free_cell
from planner.core.errors import MapError
from planner.core.path_metrics import path_length
from planner.maps.random_map import random_map
from planner.maps.text_maps import load_matrix_text, parse_text_grid
from planner.route.global_planner import plan_global
from planner.route.key_nodes import drop_collinear, extract_key_nodes
from tests.segment_check import polyline_blocked_cells

GRID20 = (
    "map20_IAstar_LOS_unknownrepo.txt",
    "map20_classic_aco_xuedidi.txt",
    "map20_improved_ant_winsleo.txt",
    "map20_jsntjyz_graduation.txt",
    "map20_winsleo_commented.txt",
)


def paper_maps(public_data):
    """The five 20x20 literature maps and 50 seeded 50x50 maps with 20-30 % obstacles."""
    for name in GRID20:
        grid = load_matrix_text(public_data / "grid20" / name)
        yield name, grid, corner_free_cell(grid, "bottom-left"), corner_free_cell(grid, "top-right")
    seed = made = 0
    while made < 50:
        ratio = 0.20 + 0.10 * (seed % 11) / 10
        grid = random_map(50, 50, ratio, seed, keep_free=[(0, 0), (49, 49)])
        seed += 1
        if plan_global(grid, (0.5, 0.5), (49.5, 49.5), "traditional", profile="paper").found:
            made += 1
            yield f"random-50x50 seed {seed - 1}", grid, (0, 0), (49, 49)


def test_improved_never_turns_more_and_keeps_to_free_cells(public_data):
    compared = 0
    for name, grid, start_cell, goal_cell in paper_maps(public_data):
        start, goal = grid.centre_of(start_cell), grid.centre_of(goal_cell)
        traditional = plan_global(grid, start, goal, "traditional", profile="paper")
        improved = plan_global(grid, start, goal, "improved", profile="paper")
        assert traditional.found and improved.found, name
        assert improved.turns <= traditional.turns, name
        assert improved.turning_angle_deg <= traditional.turning_angle_deg + 1e-9, name
        for plan in (traditional, improved):
            cells = np.array(plan.key_nodes) / grid.resolution - 0.5
            assert polyline_blocked_cells(grid.blocked, cells) == [], (name, plan.algorithm)
            assert plan.key_nodes[0] == start and plan.key_nodes[-1] == goal
        compared += 1
    assert compared == 55


def _distance_to_segment(point, a, b) -> float:
    p, a, b = (np.asarray(v, float) for v in (point, a, b))
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
    return float(np.linalg.norm(a + t * (b - a) - p))


def test_key_nodes_keep_the_safety_distance():
    # a pillar at cell (2, 2) inside a 6x6 room; the path goes up, then right
    grid = parse_text_grid("......\n......\n......\n..#...\n......\n......")
    path = [(0, 0), (0, 1), (0, 2), (0, 3), (1, 4), (2, 5), (3, 5), (4, 5), (5, 5)]
    tight = extract_key_nodes(grid, path, safety_distance=0.0)
    safe = extract_key_nodes(grid, path, safety_distance=1.2)
    assert tight != safe
    gaps_tight = [_distance_to_segment((2, 2), a, b) for a, b in itertools.pairwise(tight)]
    gaps_safe = [_distance_to_segment((2, 2), a, b) for a, b in itertools.pairwise(safe)]
    assert min(gaps_tight) <= 1.2  # without a safety distance it cuts close to the pillar
    assert min(gaps_safe) > 1.2
    assert tight[0] == safe[0] == (0, 0) and tight[-1] == safe[-1] == (5, 5)


def test_key_nodes_treat_outside_the_map_as_obstacle():
    grid = parse_text_grid("....\n....\n....")
    path = [(0, 0), (1, 1), (2, 1), (3, 0)]
    # every obstacle-cell centre beyond the border is >= 1 cell away from these segments
    assert extract_key_nodes(grid, path, safety_distance=0.9) == [(0, 0), (3, 0)]
    assert extract_key_nodes(grid, path, safety_distance=1.0) == [(0, 0), (1, 1), (2, 1), (3, 0)]


def test_drop_collinear_keeps_only_turning_points():
    path = [(0, 0), (1, 0), (2, 0), (3, 1), (4, 2), (4, 3), (4, 4)]
    assert drop_collinear(path) == [(0, 0), (2, 0), (4, 2), (4, 4)]


def test_plan_reports_world_coordinates_and_metrics():
    grid = parse_text_grid("....\n.##.\n....", resolution=0.5)
    plan = plan_global(grid, (0.25, 0.25), (1.75, 1.25), "traditional", profile="paper")
    assert plan.found
    assert plan.path[0] == (0.25, 0.25) and plan.path[-1] == (1.75, 1.25)
    assert plan.length == pytest.approx(path_length(plan.path))
    assert plan.expansions > 0 and plan.time_s > 0


@pytest.mark.parametrize(
    ("start", "goal", "message"),
    [
        ((-1.0, 0.5), (3.5, 0.5), r"start \(-1, 0.5\) is outside the map"),
        ((0.5, 0.5), (3.5, 9.0), r"goal \(3.5, 9\) is outside the map"),
        ((1.5, 1.5), (3.5, 0.5), r"start \(1.5, 1.5\) is inside an obstacle"),
    ],
)
def test_bad_points_name_the_point(start, goal, message):
    grid = parse_text_grid("....\n.##.\n....")
    with pytest.raises(MapError, match=message):
        plan_global(grid, start, goal, profile="paper")


def test_no_path_is_a_distinct_outcome():
    grid = parse_text_grid("..#..\n..#..")
    plan = plan_global(grid, (0.5, 0.5), (4.5, 1.5), "improved", profile="paper")
    assert not plan.found
    assert plan.path == [] and plan.key_nodes == []


def test_unknown_algorithm_is_rejected():
    grid = parse_text_grid("..")
    with pytest.raises(ValueError, match="unknown algorithm"):
        plan_global(grid, (0.5, 0.5), (1.5, 0.5), "dijkstra", profile="paper")
