"""Which walkers make the AGV keep the room to yield (``planner.yielding``)."""

import pytest

from planner.yielding import WALKER_RANGE, walker_coming, walker_near, walkers_standing

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
