"""Seeded random obstacle maps for benchmarks and scenarios."""

from __future__ import annotations

import numbers
from collections.abc import Iterable

import numpy as np

from planner.core.limits import check_map_cells
from planner.maps.grid import Cell, GridMap


def random_map(
    width: int,
    height: int,
    obstacle_ratio: float,
    seed: int,
    keep_free: Iterable[Cell] = (),
    resolution: float = 1.0,
) -> GridMap:
    """A width x height map with exactly round(obstacle_ratio * width * height) obstacles.

    The obstacle cells are drawn uniformly, without replacement, from the cells not listed
    in ``keep_free`` ((col, row) cells such as starts and goals; cells outside the map are
    ignored, so a bad start is reported by whoever checks it against the map). The same
    arguments always give the same map.
    """
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
            raise ValueError(f"random map {name} must be a positive integer, got {value!r}")
    if not (isinstance(obstacle_ratio, numbers.Real) and 0 <= obstacle_ratio < 1):
        raise ValueError(f"random map obstacle_ratio must be in [0, 1), got {obstacle_ratio!r}")
    width, height = int(width), int(height)
    check_map_cells(width, height, "random map")
    kept = {row * width + col for col, row in keep_free if 0 <= col < width and 0 <= row < height}
    candidates = np.setdiff1d(np.arange(width * height), np.fromiter(kept, int, len(kept)))
    count = round(obstacle_ratio * width * height)
    if count > candidates.size:
        raise ValueError(
            f"cannot place {count} obstacles in a {width}x{height} map "
            f"with {len(kept)} cell(s) kept free"
        )
    blocked = np.zeros(width * height, dtype=bool)
    rng = np.random.default_rng(seed)
    blocked[rng.choice(candidates, size=count, replace=False)] = True
    name = f"random-{width}x{height}-{obstacle_ratio:g}-seed{seed}"
    return GridMap(blocked.reshape(height, width), resolution, name)
