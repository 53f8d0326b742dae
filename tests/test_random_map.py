"""Seeded random maps: determinism, exact obstacle count, cells kept free, validation."""

from __future__ import annotations

import numpy as np
import pytest

from planner.maps.random_map import random_map


def test_same_seed_same_map_other_seed_other_map():
    a = random_map(30, 20, 0.3, seed=7)
    assert np.array_equal(a.blocked, random_map(30, 20, 0.3, seed=7).blocked)
    assert not np.array_equal(a.blocked, random_map(30, 20, 0.3, seed=8).blocked)
    assert (a.width, a.height) == (30, 20)


@pytest.mark.parametrize(
    ("width", "height", "ratio", "expected"),
    [(10, 10, 0.0, 0), (10, 10, 0.25, 25), (7, 3, 0.5, 10), (50, 50, 0.2, 500), (3, 3, 0.99, 9)],
)
def test_exact_obstacle_count(width, height, ratio, expected):
    # round() as in Python: 0.5 * 21 = 10.5 rounds to 10, 0.99 * 9 = 8.91 to 9.
    assert random_map(width, height, ratio, seed=1).blocked.sum() == expected


def test_keep_free_cells_are_col_row():
    # 14 obstacles in 15 cells: every cell but the kept one is blocked.
    grid = random_map(5, 3, 14 / 15, seed=3, keep_free=[(4, 0)], resolution=0.5)
    expected = np.ones((3, 5), dtype=bool)
    expected[0, 4] = False
    assert np.array_equal(grid.blocked, expected)
    assert grid.resolution == 0.5


def test_keep_free_over_many_seeds():
    keep = [(0, 0), (9, 9), (3, 7)]
    for seed in range(50):
        grid = random_map(10, 10, 0.9, seed, keep_free=keep)
        assert all(grid.is_free(cell) for cell in keep), seed
        assert grid.blocked.sum() == 90


def test_keep_free_outside_the_map_is_ignored():
    inside = random_map(4, 4, 0.5, seed=2)
    assert np.array_equal(inside.blocked, random_map(4, 4, 0.5, 2, keep_free=[(4, 0)]).blocked)


def test_obstacles_spread_over_every_cell():
    counts = sum(random_map(4, 4, 0.5, seed).blocked.astype(int) for seed in range(400))
    # Each cell is blocked with probability 1/2: 200 of 400 expected, far from 0 or 400.
    assert counts.min() > 140 and counts.max() < 260


@pytest.mark.parametrize(
    ("args", "problem"),
    [
        ((0, 5, 0.1), r"width must be a positive integer, got 0"),
        ((5, 2.5, 0.1), r"height must be a positive integer, got 2\.5"),
        ((True, 5, 0.1), r"width must be a positive integer, got True"),
        ((5, 5, 1.0), r"obstacle_ratio must be in \[0, 1\), got 1\.0"),
        ((5, 5, -0.1), r"obstacle_ratio must be in \[0, 1\)"),
        ((5, 5, float("nan")), r"obstacle_ratio must be in \[0, 1\)"),
        ((5, 5, "0.1"), r"obstacle_ratio must be in \[0, 1\)"),
    ],
)
def test_bad_arguments(args, problem):
    with pytest.raises(ValueError, match=problem):
        random_map(*args, seed=0)


def test_too_many_obstacles_for_the_kept_cells():
    problem = r"cannot place 10 obstacles in a 5x2 map with 1 cell\(s\) kept free"
    with pytest.raises(ValueError, match=problem):
        random_map(5, 2, 0.99, seed=0, keep_free=[(0, 0), (0, 0)])
