"""Self-crossings of a driven path (an AGV's loops) and turn angles
(``planner.core.path_metrics``)."""

from __future__ import annotations

import math

import numpy as np

from planner.core.path_metrics import (
    LOOP_GAP,
    crossing_points,
    heading_changes_deg,
    self_crossings,
    turn_angle,
)


def _curls(turns: float, advance: float = 0.3, radius: float = 0.8) -> np.ndarray:
    """A prolate cycloid: a path that drives on while circling, one curl per full turn
    that advances less than the circle is wide."""
    t = np.linspace(0.0, 2 * math.pi * turns, int(400 * turns))
    return np.column_stack((advance * t - radius * np.sin(t), -radius * np.cos(t)))


def test_each_curl_driven_crosses_the_track_once():
    assert self_crossings(_curls(3)) == 2  # curls at t = 2 pi and 4 pi; the ends are halves
    assert self_crossings(_curls(5)) == 4


def test_straight_driving_and_driving_back_along_the_same_line_are_no_loops():
    assert self_crossings([(0.0, 0.0), (5.0, 0.0)]) == 0
    assert self_crossings([(0.0, 0.0), (5.0, 0.0), (0.0, 0.01), (5.0, 0.02)]) == 0


def test_going_round_the_same_circle_again_is_no_crossing():
    t = np.linspace(0.0, 2 * math.pi * 1.5, 600)
    assert self_crossings(np.column_stack((np.cos(t), np.sin(t)))) == 0


def test_a_wobble_shorter_than_the_gap_is_one_manoeuvre_not_a_loop():
    # a figure-eight 0.2 m across: its track crosses itself within far less than LOOP_GAP
    t = np.linspace(-math.pi / 2, 3 * math.pi / 2, 200)
    eight = np.column_stack((0.1 * np.sin(t), 0.05 * np.sin(2 * t)))
    assert self_crossings(eight, gap=0.01) == 1
    assert self_crossings(eight) == 0 < LOOP_GAP
    assert self_crossings([(0.0, 0.0)] * 5) == 0  # standing still


def test_crossing_points_are_where_the_track_crosses_itself():
    loop = [(0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (2.0, 2.0), (2.0, -2.0)]
    assert crossing_points(loop).tolist() == [[2.0, 0.0]]
    points = crossing_points(_curls(5))
    assert len(points) == self_crossings(_curls(5)) == 4
    assert np.all(np.diff(points[:, 0]) > 0)  # one per curl, in the order driven
    assert crossing_points([(0.0, 0.0), (5.0, 0.0)]).shape == (0, 2)


def test_turn_angle_is_the_heading_change_of_the_three_points_bit_for_bit():
    rng = np.random.default_rng(7)
    for i in range(3000):
        points = rng.normal(size=(3, 2)) * rng.choice([0.01, 1.0, 100.0])
        if i % 5 == 0:
            points = np.round(points, 1)  # on a grid: right angles, straight on, U-turns
        if i % 7 == 0:
            points[1] = points[0 if i % 2 else 2]  # a repeated point: no heading
        before, node, after = (tuple(float(v) for v in p) for p in points)
        change = heading_changes_deg([before, node, after])
        expected = math.radians(abs(float(change[0]))) if len(change) else 0.0
        assert turn_angle(before, node, after) == expected
    assert turn_angle((0.0, 0.0), (1.0, 0.0), (1.0, 1.0)) == math.pi / 2
    assert turn_angle((0.0, 0.0), (1.0, 0.0), (0.0, 0.0)) == math.pi


def _crossings_pair_by_pair(pts: np.ndarray, gap: float) -> list[tuple[float, float]]:
    """``crossing_points`` as its definition reads: every pair of segments, in order."""
    along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    least_sin, found = math.sin(math.radians(30.0)), []
    for i in range(len(pts) - 1):
        (ax, ay), (bx, by) = pts[i], pts[i + 1]
        for j in range(i + 1, len(pts) - 1):
            if along[j] < along[i + 1] + gap:
                continue
            (cx, cy), (dx, dy) = pts[j], pts[j + 1]
            d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
            d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
            d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
            d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
            if d1 * d2 < 0 and d3 * d4 < 0:
                sine = abs(d2 - d1) / (math.hypot(bx - ax, by - ay) * math.hypot(dx - cx, dy - cy))
                if sine >= least_sin:
                    t = d1 / (d1 - d2)
                    found.append((cx + t * (dx - cx), cy + t * (dy - cy)))
    return found


def test_a_long_wandering_path_has_the_crossings_of_every_pair_in_the_same_order():
    """The block skipping of the compiled search changes nothing: a random walk of 700
    points (11 blocks, many crossings) against the pair-by-pair definition."""
    rng = np.random.default_rng(3)
    heading = np.cumsum(rng.normal(0.0, 0.6, 700))
    pts = np.cumsum(np.column_stack((np.cos(heading), np.sin(heading))) * 0.4, axis=0)
    expected = _crossings_pair_by_pair(pts, LOOP_GAP)
    assert len(expected) > 20
    assert crossing_points(pts).tolist() == [list(p) for p in expected]
