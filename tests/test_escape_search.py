"""benchmarks/escape_search.py: the search finds the way out a walker leaves, and none
when the AGV cannot move."""

from __future__ import annotations

from types import SimpleNamespace

from benchmarks.escape_search import search
from fleet.moving_obstacle import MovingObstacle
from planner.maps.text_maps import parse_text_grid


def test_a_walker_coming_straight_at_a_standing_agv_is_escaped_only_with_acceleration():
    room = SimpleNamespace(
        grid=parse_text_grid("\n".join(["." * 12] * 12)),
        moving=[MovingObstacle("w", 0.35, ((6.0, 11.0), (6.0, 1.0)), 1.0, "once", 0.0)],
    )
    start = (6.0, 6.0, 0.0, 0.0, 0.3)  # x, y, vx, vy, radius: 4.35 m below the walker
    contact, _ = search(room, start, 0.0, 0.0, 0.0, 6.0, 500)
    assert contact is not None and 4.0 < contact < 4.5  # it cannot move: hit at 4.35 s
    contact, kept = search(room, start, 0.0, 0.2, 0.0, 6.0, 500)
    assert contact is None and kept > 0.3  # 0.2 m/s² sideways for 4 s is 1.6 m
