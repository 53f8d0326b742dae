"""The nav_bench episodes are fair: walkers keep off the walls and a crossing walker crosses
the route once, leaving it free, instead of bouncing across it through walls. Written as a
scenario file, an episode is the same scenario."""

from __future__ import annotations

import itertools
import math

import numpy as np

from benchmarks.nav_episodes import CROSSING_CLEAR, WALKER_RADIUS, episodes
from fleet.scenario import parse_scenario
from planner.maps.distance_field import DistanceField

EPISODES = episodes(30)


def _along(waypoints, step=0.05):
    """Points every ``step`` along the walker's polyline."""
    points = []
    for a, b in itertools.pairwise(waypoints):
        n = max(1, math.ceil(math.dist(a, b) / step))
        points += [(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n) for k in range(n)]
    return np.array([*points, waypoints[-1]])


def test_walkers_keep_off_the_walls():
    walkers = 0
    for episode in EPISODES:
        field = DistanceField.from_grid(episode.grid)
        for walker in episode.moving:
            xy = _along(walker.waypoints)
            # the head-on walker follows the body's path, which keeps 0.3 m clear
            least = WALKER_RADIUS if walker.name == "crossing" else 0.3
            assert field.distance_at(xy[:, 0], xy[:, 1]).min() >= least - 1e-6, episode.seed
            walkers += 1
    assert walkers >= 15  # the test is not vacuous


def test_a_crossing_walker_crosses_once_and_ends_clear_of_the_route():
    crossings = [(e, m) for e in EPISODES for m in e.moving if m.name == "crossing"]
    assert len(crossings) >= 8
    for episode, walker in crossings:
        assert walker.mode == "once" and len(walker.waypoints) == 2
        a, b = np.array(walker.waypoints)
        # both ends at least CROSSING_CLEAR from where the line meets the route, on either side
        assert math.dist(a, b) >= 2 * CROSSING_CLEAR - 1e-6, episode.seed


def test_an_episode_written_as_a_scenario_file_reads_back_as_the_same_scenario():
    for episode, (algorithm, profile) in zip(
        EPISODES, itertools.cycle([("fusion", "default"), ("dwa", "paper")]), strict=False
    ):
        read = parse_scenario(episode.toml(algorithm, profile))
        built = episode.scenario(algorithm, profile)
        assert read.agvs == built.agvs, episode.seed  # vehicle limits and planner included
        assert read.moving == built.moving and read.temporary == built.temporary
        assert (read.grid.blocked == built.grid.blocked).all()
        assert read.grid.resolution == built.grid.resolution
        assert (read.dt, read.time_limit, read.sensing_radius) == (
            built.dt, built.time_limit, built.sensing_radius,
        )  # fmt: skip
    assert any(e.moving for e in EPISODES) and any(e.temporary for e in EPISODES)
