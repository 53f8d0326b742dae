"""AGVs coming towards each other keep right (``planner.local.keep_right``), so that two mirror
images of each other pass instead of mirroring each other's evasions."""

from __future__ import annotations

import math

import numpy as np

from benchmarks import traffic_cases as tc
from fleet.runtime.inprocess import run_in_process
from planner.local.keep_right import MARGIN, agv_coming, right_offset, shifted_right
from planner.maps.distance_field import DistanceField
from planner.maps.text_maps import parse_text_grid

RADIUS = 0.3


def _corridor(rows: int, resolution: float) -> DistanceField:
    grid = ["#" * 40, *(["." * 40] * rows), "#" * 40]
    return DistanceField.from_grid(parse_text_grid("\n".join(grid), resolution))


def test_the_offset_is_a_body_width_in_the_open_and_what_the_walls_leave_in_a_corridor():
    open_room = DistanceField.from_grid(parse_text_grid("\n".join(["." * 30] * 30)))
    assert math.isclose(right_offset(open_room, RADIUS, ((5.0, 15.0), (25.0, 15.0))), 0.35)
    # 1.0 m wide (2 cells of 0.5 m): 0.5 m from the centre line to each wall
    narrow = _corridor(2, 0.5)
    offset = right_offset(narrow, RADIUS, ((2.0, 1.0), (18.0, 1.0)))
    assert math.isclose(offset, 0.5 - RADIUS - MARGIN, abs_tol=1e-6)


def test_right_is_to_the_right_of_the_travel():
    east = shifted_right(((0.0, 0.0), (10.0, 0.0)), 0.3)
    assert east == ((0.0, -0.3), (10.0, -0.3))
    west = shifted_right(((10.0, 0.0), (0.0, 0.0)), 0.3)
    assert west == ((10.0, 0.3), (0.0, 0.3))


def test_only_an_agv_ahead_coming_the_other_way_counts():
    position, segment = (0.0, 0.0), ((-2.0, 0.0), (20.0, 0.0))  # driving east
    head_on = np.array([[5.0, 0.2, -0.5, 0.0, 0.3]])
    assert agv_coming(position, segment, RADIUS, head_on)
    ahead_same_way = np.array([[5.0, 0.0, 0.3, 0.0, 0.3]])
    assert not agv_coming(position, segment, RADIUS, ahead_same_way)
    behind = np.array([[-5.0, 0.0, 0.5, 0.0, 0.3]])
    assert not agv_coming(position, segment, RADIUS, behind)
    far = np.array([[20.0, 0.0, -0.5, 0.0, 0.3]])
    assert not agv_coming(position, segment, RADIUS, far)
    crossing = np.array([[4.0, 2.0, -0.2, -0.5, 0.3]])  # from the left, across the way ahead
    assert not agv_coming(position, segment, RADIUS, crossing)
    other_lane = np.array([[5.0, 0.9, -0.5, 0.0, 0.3]])  # head-on in a lane of its own
    assert not agv_coming(position, segment, RADIUS, other_lane)
    alongside = np.array([[-0.5, 0.3, -0.5, 0.0, 0.3]])  # passing: the shift holds
    assert agv_coming(position, segment, RADIUS, alongside)


def test_mirror_image_agvs_pass_each_other_in_a_corridor_one_and_a_half_metres_wide():
    # traffic suite corridor-3-mirror n2 s0: without keeping right the two mirrored each
    # other's evasions for 40 s in the corridor's middle (94.6 s, 35 m driven for 22 m)
    summary = run_in_process(tc.make_case("corridor-3-mirror", 0).scenario)
    assert summary.end_reason == "every AGV arrived" and summary.collisions == 0
    for agv in summary.agvs:
        assert agv.distance < 1.1 * agv.route_length
    assert summary.sim_time < 50.0
