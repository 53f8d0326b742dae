"""Which walkers make the AGV keep the room to yield, and where a head-on walker is
taken to walk on (``planner.local.yielding``, ``planner.nav.trail``)."""

import math

import numpy as np
import pytest

from planner.core.path_metrics import distance_to_path
from planner.local.yielding import (
    WALKER_RANGE,
    sweep,
    walker_coming,
    walker_near,
    walker_standing_near,
    walkers_standing,
)
from planner.nav.trail import TRAIL_LENGTH, TRAIL_STEP, Trail

POSE = (5.0, 5.0, 0.0)


def _walker(x, y, vx, vy):
    return [[x, y, vx, vy, 0.35]]


@pytest.mark.parametrize(
    ("walker", "coming"),
    [
        (_walker(8.0, 5.0, -0.5, 0.0), True),  # straight at the AGV
        (_walker(8.0, 5.0, 0.0, 0.5), True),  # across, at its closest now: not yet away
        (_walker(8.0, 5.0, 0.0, 0.0), True),  # standing: may start at any time
        (_walker(8.0, 5.0, 0.5, 0.0), False),  # walking away
        (_walker(4.0, 4.0, -0.3, -0.1), False),  # passed, behind on the left
        (_walker(5.0 + WALKER_RANGE + 1.0, 5.0, -1.0, 0.0), False),  # coming, out of range
    ],
)
def test_a_walker_is_coming_unless_it_walks_away_or_is_out_of_range(walker, coming):
    assert walker_coming(POSE, walker) is coming


def test_one_coming_walker_among_receding_ones_is_enough():
    walkers = _walker(8.0, 5.0, 0.5, 0.0) + _walker(2.0, 5.0, 0.5, 0.0)
    assert walker_coming(POSE, walkers)
    assert not walker_coming(POSE, walkers[:1])


def test_near_counts_every_walker_in_range_and_none_without_walkers():
    assert walker_near(POSE, _walker(8.0, 5.0, 0.5, 0.0))
    assert not walker_near(POSE, _walker(5.0 + WALKER_RANGE + 1.0, 5.0, 0.0, 0.0))
    assert not walker_near(POSE, None) and not walker_coming(POSE, [])


def test_standing_means_every_walker_in_range_stands_still():
    standing, walking = _walker(8.0, 5.0, 0.0, 0.0), _walker(3.0, 5.0, 0.0, 0.4)
    far_walking = _walker(5.0 + WALKER_RANGE + 1.0, 5.0, -1.0, 0.0)
    assert walkers_standing(POSE, standing)
    assert walkers_standing(POSE, standing + far_walking)  # out of range: does not count
    assert not walkers_standing(POSE, standing + walking)


def test_standing_near_means_one_walker_in_range_stands_still():
    standing, walking = _walker(8.0, 5.0, 0.0, 0.0), _walker(3.0, 5.0, 0.0, 0.4)
    far_standing = _walker(5.0 + WALKER_RANGE + 1.0, 5.0, 0.0, 0.0)
    assert walker_standing_near(POSE, standing + walking)
    assert not walker_standing_near(POSE, walking + far_standing)
    assert not walker_standing_near(POSE, None)


def test_a_head_on_walker_walks_on_past_the_agv_along_the_way_the_agv_came():
    # the AGV at (5, 0) drives east; it came down an aisle from the north
    route = [(5.0, 0.0), (10.0, 0.0)]
    came_by = [(5.0, 0.0), (5.0, 4.0)]
    walker = np.array([8.0, 0.0, -1.0, 0.0, 0.35])  # 3 m ahead, coming west at 1 m/s
    alone = sweep(route, walker, 1.0, 6.0)
    on = sweep(route, walker, 1.0, 6.0, came_by)
    # without the way it came, the walker stops at the AGV: backing off looks clear
    assert np.allclose(alone[0], (7.0, 0.0)) and np.allclose(alone[-1], (5.0, 0.0))
    # with it, it walks the 5 m on: 2 m to the AGV, then 3 m up the aisle
    assert np.allclose(on[0], (7.0, 0.0)) and np.allclose(on[-1], (5.0, 3.0))
    way = [(10.0, 0.0), (5.0, 0.0), (5.0, 4.0)]
    assert max(distance_to_path(way, p) for p in on) < 1e-9
    # where the way ends, so does the walk; a walker not walking against the route keeps
    # its velocity, the way behind or not
    assert np.allclose(sweep(route, walker, 1.0, 12.0, came_by)[-1], (5.0, 4.0))
    across = np.array([8.0, -2.0, 0.0, 1.0, 0.35])
    assert np.allclose(sweep(route, across, 0.0, 3.0, came_by)[-1], (8.0, 1.0))


def test_the_trail_keeps_positions_a_step_apart_and_only_the_last_stretch():
    trail = Trail()
    for x in np.arange(0.0, 1.0, 0.1):  # 0.0 ... 0.9 m: kept every 0.25 m or more
        trail.note((float(x), 0.0))
    back = trail.back_from((1.0, 0.0))
    assert back[0] == (1.0, 0.0)
    assert [round(p[0], 6) for p in back[1:]] == [0.9, 0.6, 0.3, 0.0]
    for x in np.arange(0.0, 3 * TRAIL_LENGTH, TRAIL_STEP):
        trail.note((1.0 + float(x), 5.0))
    kept = trail.back_from((0.0, 0.0))[1:]
    assert math.dist(kept[0], kept[-1]) == pytest.approx(TRAIL_LENGTH - TRAIL_STEP)
