"""Routes through passages an even number of cells wide run down their middle."""

from __future__ import annotations

import numpy as np

from benchmarks import traffic_cases as tc
from planner.maps.clearance import Clearance
from planner.maps.grid import GridMap
from planner.maps.random_map import random_map
from planner.maps.segment_clearance import route_clearance
from planner.route.centring import centred
from planner.route.global_planner import plan_global

CLEARANCE = Clearance.from_safety_distance(0.3, 0.5)


def _corridor() -> GridMap:
    """Two rooms joined by a 1.0 m corridor (4 cells of 0.25 m: its middle is a cell edge,
    at y = 4.0 m) from x = 6 m to x = 18 m."""
    return GridMap(tc.fine_map(tc.corridor_map(2, 24)), tc.RES, "corridor-2")


def test_key_nodes_run_down_the_middle_of_a_corridor_an_even_number_of_cells_wide():
    plan = plan_global(_corridor(), (3.0, 1.5), (21.0, 6.5), "improved", clearance=CLEARANCE)
    inside = [p for p in plan.key_nodes if 5.5 <= p[0] <= 18.5]
    assert inside, plan.key_nodes
    # the search's cell centres are at y = 3.875 or 4.125: 0.075 m to spare for the body
    assert all(abs(y - 4.0) < 1e-9 for _, y in inside), inside
    assert plan.clearance >= 0.5 - 1e-9  # 0.2 m to spare on both sides


def test_centring_never_lowers_a_routes_least_clearance():
    for seed in range(8):
        grid = random_map(40, 40, 0.25, seed, [(1, 1), (38, 38)])
        plan = plan_global(grid, (1.5, 1.5), (38.5, 38.5), "improved", clearance=CLEARANCE)
        if not plan.found:
            continue
        points = np.array([grid.to_cell_units(p) for p in plan.key_nodes])
        # undo nothing: centring the centred route again may only keep or raise it
        before = route_clearance(grid.blocked, points, 2.0)
        again = centred(grid.blocked, points, 2.0, grid.resolution)
        assert route_clearance(grid.blocked, again, 2.0) >= before - 1e-9, seed
        assert np.abs(again - points).max() <= 0.5 + 1e-9  # half a cell at most
