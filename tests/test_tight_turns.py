"""Where the route turns into a 1.0 m corridor, the AGV does not cut the corner: it
switches late, or stops at the node and turns on the spot (``planner.nav.tight_turns``)."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np

from benchmarks import traffic_cases as tc
from bridge import keys
from fleet.runtime.inprocess import run_in_process
from planner.core.motion import step_pose
from planner.core.path_metrics import turn_angle
from planner.local.behaviour import local_behaviour
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.local.yielding import WALKER_RANGE
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap
from planner.maps.text_maps import parse_text_grid
from planner.nav.dwa_inputs import straight_approach
from planner.nav.fusion import FusionConfig, FusionController
from planner.nav.tight_turns import (
    MIN_REACH,
    TURN_ON_SPOT,
    approach_command,
    approach_path,
    corner,
    room_ahead,
)
from recordings.analysis import sign_changes

RADIUS = 0.3


def _corridor_field() -> DistanceField:
    """Two rooms joined by a 1.0 m corridor along y = 4.0 m from x = 6 m to x = 18 m."""
    return DistanceField.from_grid(GridMap(tc.fine_map(tc.corridor_map(2, 24)), tc.RES, "c2"))


def test_a_sharp_turn_into_a_one_metre_corridor_is_a_stop_and_a_turn():
    field = _corridor_field()
    mouth = corner(field, RADIUS, (5.25, 6.25), (5.5, 4.0), (16.8, 4.0), 1.0)
    assert mouth.stop
    assert MIN_REACH <= mouth.reach <= 0.21  # 0.2 m to spare beside the body, / sin(84°)


def test_a_straight_run_into_a_corridor_and_a_turn_in_the_open_keep_the_paper_switch():
    field = _corridor_field()
    straight = corner(field, RADIUS, (2.0, 4.0), (5.5, 4.0), (16.8, 4.0), 1.0)
    assert straight.reach == 1.0 and not straight.stop
    open_room = DistanceField.from_grid(parse_text_grid("\n".join(["." * 20] * 20)))
    assert corner(open_room, RADIUS, (5.0, 5.0), (10.0, 5.0), (10.0, 15.0), 1.0).reach == 1.0


def test_a_slight_bend_into_a_corridor_is_passed_without_stopping():
    field = _corridor_field()
    bend = corner(field, RADIUS, (2.0, 4.4), (5.5, 4.0), (16.8, 4.0), 1.0)
    assert turn_angle((2.0, 4.4), (5.5, 4.0), (16.8, 4.0)) < TURN_ON_SPOT
    assert not bend.stop
    # switching 1 m early cuts this bend by ~0.11 m: within the body's 0.2 m of room
    assert bend.reach == 1.0


def test_the_switch_reach_bounds_the_corner_cut_by_the_room():
    field = _corridor_field()
    for before in [(2.0, 5.5), (3.0, 6.0), (5.0, 7.0), (5.5, 8.0)]:
        c = corner(field, RADIUS, before, (5.5, 4.0), (16.8, 4.0), 1.0)
        phi = turn_angle(before, (5.5, 4.0), (16.8, 4.0))
        room = room_ahead(field, RADIUS, (5.5, 4.0), (16.8, 4.0))
        assert c.reach * math.sin(min(phi, math.pi / 2)) <= room + 1e-9, before
        assert c.stop == (phi > TURN_ON_SPOT), before


def test_the_straight_approach_ends_at_rest_on_the_node_within_the_limits():
    config = DwaConfig(max_speed=1.0, max_accel=0.5)
    pose, command, node = (0.0, 0.0, 0.3), (0.2, -0.1, 0.1), (2.0, 0.5)
    for _ in range(200):
        new = approach_command(config, pose, command, node, config.max_speed)
        for axis in range(2):
            assert abs(new[axis] - command[axis]) <= config.max_accel * config.dt + 1e-9
        assert math.hypot(new[0], new[1]) <= config.max_speed + 1e-9
        command, pose = new, step_pose(pose, new, config.dt)
    assert math.dist(pose[:2], node) < 0.05
    assert math.hypot(command[0], command[1]) < 1e-6
    assert approach_path(config, pose, command, node, config.max_speed).shape == (config.steps, 3)


def test_the_straight_approach_holds_its_heading_without_chatter():
    # at 60 deg/s and 0.5 s to reach it, the turn curve sqrt(2 alpha |error|) overshot a
    # heading error of a few tenths of a degree each period: omega flipped sign every tick
    config = DwaConfig(max_speed=1.2, max_accel=1.0, max_omega=math.radians(60), max_alpha=2.1)
    pose, command, node = (0.0, 0.0, math.radians(3.0)), (0.4, 0.0, 0.0), (4.0, 0.0)
    omegas = []
    while math.dist(pose[:2], node) > 0.6:  # nearer than FACE_FROM the turn rate brakes
        command = approach_command(config, pose, command, node, config.max_speed)
        pose = step_pose(pose, command, config.dt)
        omegas.append(command[2])
    flips = sum(1 for a, b in itertools.pairwise(omegas) if a * b < 0)
    assert flips <= 1
    assert abs(math.remainder(pose[2], math.tau)) < math.radians(0.5)  # faces the node


def test_the_faced_approach_does_not_chase_rounding():
    # off the axes a period's turn closes the heading error only to rounding (~1e-16 rad):
    # chasing it drove omega of +-1e-15 rad/s, whose sign flipped every tick or two
    config = DwaConfig(max_speed=1.0, max_accel=0.5)
    node = (6.0, 4.0)
    pose, command = (0.0, 0.0, math.atan2(4.0, 6.0) + 0.02), (0.3, 0.0, 0.0)
    omegas = []
    while math.dist(pose[:2], node) > 0.6:  # nearer than FACE_FROM the turn rate brakes
        command = approach_command(config, pose, command, node, config.max_speed)
        pose = step_pose(pose, command, config.dt)
        omegas.append(command[2])
    rounding = [w for w in omegas if 0 < abs(w) < 1e-9]
    assert not rounding and omegas[-20:] == [0.0] * 20  # turned, then exactly straight
    assert sign_changes(np.array(omegas)) <= 1  # the turn's own end may overshoot once


def test_an_agv_alone_turns_into_a_one_metre_corridor_and_arrives():
    # traffic suite corridor-2 seed 3, AGV L3 alone: it used to cut the corner at the mouth,
    # end up beside it and slide along the wall until it failed after its recoveries
    case = tc.make_case("corridor-2", 3).scenario
    scenario = replace(case, agvs=(case.agv("L3"),))
    headings = []

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            headings.extend(a.theta for a in msg.agvs if 7.0 <= a.x <= 16.0)

    summary = run_in_process(scenario, sink)
    agv = summary.agvs[0]
    assert agv.status == "arrived" and agv.collisions == 0, agv.failure
    assert agv.arrival_time < 60.0  # 13 m of corridor at 0.42 m/s, and the rooms
    # inside the corridor the body faces along it
    assert max(abs(math.remainder(h, math.tau)) for h in headings) < math.radians(10)


def test_only_the_default_profile_stops_at_tight_corners():
    grid = GridMap(tc.fine_map(tc.corridor_map(2, 24)), tc.RES, "c2")
    stops = {}
    for profile in ("default", "paper"):
        config = FusionConfig(profile=profile, dwa=DwaConfig(radius=RADIUS), safety_distance=0.5)
        controller = FusionController(grid, (18.25, 6.75), config)
        controller.start((5.25, 6.25, 0.0))
        stops[profile] = [c.stop for c in controller.corners]
        if profile == "paper":
            assert all(c.reach == config.switch_distance for c in controller.corners)
    assert any(stops["default"]) and not any(stops["paper"])


def _approach(walkers, stalled_before=None):
    """The straight approach from (2, 6) to the node (4.5, 6) in an open room, the route
    turning north there, with ``walkers`` (rows [x, y, vx, vy, r]) about."""
    field = DistanceField.from_grid(parse_text_grid("\n".join(["." * 20] * 12)))
    config = FusionConfig()
    dwa = DwaPlanner(config.dwa, field, local_behaviour(config.profile))
    pose, command, node = (2.0, 6.0, 0.0), (0.3, 0.0, 0.0), (4.5, 6.0)
    moving = None if walkers is None else np.array(walkers, dtype=float)
    route = [pose[:2], node, (4.5, 10.0)]
    return straight_approach(
        config, dwa, pose, command, node, moving, moving, stalled_before, route, [pose[:2]]
    )


def test_a_walker_that_cannot_reach_the_approach_leaves_it_on_one_that_can_keeps_it_off():
    assert _approach(None) is not None
    # 5.5 m beyond the node, within 12 m: walking away, or across far behind the node
    assert _approach([[10.0, 6.0, 0.5, 0.0, 0.35]]) is not None
    assert _approach([[10.0, 6.0, 0.0, 0.5, 0.35]]) is not None
    # the same walker walking at the node reaches it before the AGV could yield there
    assert _approach([[10.0, 6.0, -0.5, 0.0, 0.35]]) is None
    # one standing may start at any time: off, unless the AGV already stalled before
    # this node and every walker in range stands
    standing = [[10.0, 6.0, 0.0, 0.0, 0.35]]
    assert _approach(standing) is None
    assert _approach(standing, stalled_before=(4.5, 6.0)) is not None
    # a walker out of range standing does not count
    assert _approach([[2.0 + WALKER_RANGE + 1.0, 6.0, 0.0, 0.0, 0.35]]) is not None
