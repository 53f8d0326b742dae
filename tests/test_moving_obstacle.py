"""Moving obstacles follow their waypoints as a pure function of time."""

from __future__ import annotations

import pytest

from fleet.moving_obstacle import MovingObstacle

ROUTE = ((0.0, 0.0), (4.0, 0.0), (4.0, 2.0))  # 6 m long


@pytest.mark.parametrize(
    ("mode", "t", "expected"),
    [
        ("bounce", 1.0, (2.0, 0.0, 2.0, 0.0)),
        ("bounce", 2.5, (4.0, 1.0, 0.0, 2.0)),
        ("bounce", 4.5, (3.0, 0.0, -2.0, 0.0)),  # on the way back: 9 m travelled
        ("bounce", 6.5, (1.0, 0.0, 2.0, 0.0)),  # 13 m: back at the start, going out again
        ("once", 2.5, (4.0, 1.0, 0.0, 2.0)),
        ("once", 10.0, (4.0, 2.0, 0.0, 0.0)),  # stays at the last waypoint
        # 7 m: 1 m along the closing leg from (4, 2) back to the start, direction (-2, -1)/sqrt(5)
        ("loop", 3.5, (4.0 - 2 / 5**0.5, 2.0 - 1 / 5**0.5, -4 / 5**0.5, -2 / 5**0.5)),
    ],
)
def test_positions_and_velocities(mode, t, expected):
    ob = MovingObstacle("o", 0.4, ROUTE, speed=2.0, mode=mode)
    assert ob.state_at(t) == pytest.approx(expected)


def test_waits_at_the_first_waypoint_until_it_starts():
    ob = MovingObstacle("o", 0.4, ROUTE, speed=2.0, start_at=5.0)
    assert ob.state_at(4.0) == (0.0, 0.0, 0.0, 0.0)
    assert ob.state_at(6.0) == pytest.approx((2.0, 0.0, 2.0, 0.0))


def test_a_single_waypoint_stands_still():
    assert MovingObstacle("o", 0.4, ((1.0, 2.0),), speed=1.0).state_at(3.0) == (1.0, 2.0, 0, 0)
