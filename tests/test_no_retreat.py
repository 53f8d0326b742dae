"""Another AGV in reach: brake or step aside, never drive away from the target
(``planner.local.no_retreat``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from benchmarks import traffic_cases as tc
from fleet.runtime.inprocess import run_in_process
from planner.local.behaviour import local_behaviour
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.local.filters import NoRetreat
from planner.local.no_retreat import ahead_on_route, retreating
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap

CONFIG = DwaConfig(
    max_speed=1.0, max_accel=0.5, max_omega=math.radians(60), max_alpha=math.radians(120)
)
DEFAULT = local_behaviour("default")
WITHOUT = dataclasses.replace(
    DEFAULT, filters=tuple(f for f in DEFAULT.filters if not isinstance(f, NoRetreat))
)


def _retreats(pose, end, target) -> bool:
    return bool(retreating(pose, np.array([end[0]]), np.array([end[1]]), target)[0])


def test_a_step_straight_aside_or_standing_is_no_retreat_driving_back_is():
    pose, target = (0.0, 0.0, 0.0), (5.0, 0.0)
    assert not _retreats(pose, (1.0, 0.0), target)
    assert not _retreats(pose, (0.0, 1.0), target)  # straight aside: 90 degrees
    assert not _retreats(pose, (-0.05, 0.0), target)  # braking: hardly moved
    assert _retreats(pose, (-0.5, 0.5), target)  # 135 degrees off the target
    assert _retreats(pose, (-1.0, 0.0), target)


def test_away_counts_from_where_the_route_goes_on_not_from_the_target_beyond_a_shelf():
    """warehouse-40 n40 s4's agv22: pushed 1.7 m down a side aisle below the cross aisle
    its route follows west, its target 20 m west beyond a shelf."""
    pose, target = (25.5, 13.8, 0.0), (5.875, 15.625)
    ahead = ahead_on_route(pose, target, ((25.25, 15.5), target))
    down_the_aisle, back_up = (25.5, 12.8), (25.5, 14.8)
    assert not _retreats(pose, down_the_aisle, target)  # aside from the target as the crow flies
    assert _retreats(pose, down_the_aisle, ahead)
    assert not _retreats(pose, back_up, ahead)


def test_on_the_route_a_step_straight_aside_is_still_no_retreat():
    target = (0.0, 0.0)
    segment = ((20.0, 0.0), target)
    for offset in (0.0, 0.5):  # on the route, and already half an aisle aside
        pose = (10.0, offset, 0.0)
        assert not _retreats(pose, (10.0, offset + 1.0), ahead_on_route(pose, target, segment))
    pose = (1.0, 0.0, 0.0)  # near the end the target itself is ahead
    assert ahead_on_route(pose, target, segment) == target


def _head_on(behaviour, walkers=None):
    """An AGV already swerving away (heading -60 deg at 0.5 m/s, its target 8 m west) with
    another disc 1.5 m west coming east at 0.5 m/s: where its chosen trajectory ends."""
    field = DistanceField.from_grid(GridMap(np.zeros((20, 30), dtype=bool)))
    planner = DwaPlanner(CONFIG, field, behaviour=behaviour)
    pose, target = (10.0, 10.0, math.radians(-60)), (2.0, 10.0)
    disc = np.array([[8.5, 10.0, 0.5, 0.0, 0.3]])
    result = planner.plan(
        pose, (0.5, 0.0, 0.0), target, disc, segment=((10.0, 10.0), target), walkers=walkers
    )
    return _retreats(pose, result.trajectory[-1], target)


def test_dwa_turns_back_towards_the_target_instead_of_running_ahead_of_an_agv():
    assert _head_on(WITHOUT)  # the most clearance lies ahead of the oncoming disc
    assert not _head_on(DEFAULT)


def test_from_a_walker_the_agv_may_still_back_off():
    walker = np.array([[8.5, 10.0, 0.5, 0.0, 0.3]])
    assert _head_on(DEFAULT, walkers=walker)  # walkers do not plan: get out of their way


def test_an_agv_meeting_a_pair_head_on_in_a_corridor_does_not_back_out_ahead_of_them():
    # traffic suite corridor-3 n4 s3: L2 met two AGVs head-on in the 1.5 m corridor and
    # backed 7 m out ahead of them (1.98 x its route, the run 95 s)
    summary = run_in_process(tc.make_case("corridor-3", 3).scenario)
    assert summary.end_reason == "every AGV arrived" and summary.collisions == 0
    for agv in summary.agvs:
        assert agv.distance < 1.2 * agv.route_length, agv.name
    assert summary.sim_time < 70.0
