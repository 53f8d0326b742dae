"""Along its route the default bounds the speed by the room to brake ahead, not by the
clearance beside it (``planner.local.lane_speed``); off the route and near walkers, Eq. 7."""

from __future__ import annotations

import itertools
import math

import numpy as np

from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario, with_profile, with_traffic
from planner.core.motion import step_pose
from planner.local.behaviour import local_behaviour
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.local.lane_speed import node_room, route_room
from planner.maps.distance_field import DistanceField
from planner.maps.text_maps import parse_text_grid

CFG = DwaConfig()  # Table 1: 0.2 m/s², so Eq. 7 at 0.2 m of clearance allows 0.28 m/s
EQ7_AT_LANE = math.sqrt(2.0 * 0.2 * CFG.max_accel)


def _lane_field() -> DistanceField:
    """A 40 m corridor two cells (2 m) wide: y from 1 to 3."""
    return DistanceField.from_grid(
        parse_text_grid("\n".join(["#" * 40, "." * 40, "." * 40, "#" * 40]))
    )


def _drive(lane_room, seconds: float, disc=None) -> tuple[list[float], list]:
    """Speeds and positions of an AGV driving DWA along the lane at y = 1.5 (0.2 m of clearance)."""
    planner = DwaPlanner(CFG, _lane_field(), local_behaviour("default"))
    pose, command, previous = (1.0, 1.5, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    speeds, xs = [], []
    goal = (39.0, 1.5)
    for _ in range(round(seconds / CFG.dt)):
        moving = None
        if disc is not None:  # a disc standing across the corridor ahead
            moving = np.array([[*disc, 0.0, 0.0, 1.0]])
        room = None if lane_room is None else math.dist(pose[:2], goal)
        result = planner.plan(
            pose, command, goal, moving, previous=previous, segment=((1.0, 1.5), goal),
            lane_room=room,
        )  # fmt: skip
        previous, command = command, result.command
        pose = step_pose(pose, command, CFG.dt)
        speeds.append(math.hypot(command[0], command[1]))
        xs.append(pose[:2])
    return speeds, xs


def test_a_lane_along_a_wall_is_driven_faster_than_eq7_allows_beside_it():
    paper_bound = max(_drive(None, 20.0)[0])
    lane = max(_drive(True, 20.0)[0])
    assert paper_bound <= EQ7_AT_LANE + 0.011
    # 20 s at 0.2 m/s² from rest: the lane bound lets it reach 2 a T = 1.2 m/s
    assert lane > 3 * EQ7_AT_LANE


def test_a_standing_disc_ahead_still_bounds_the_lane_speed():
    speeds, positions = _drive(True, 40.0, disc=(12.0, 2.0))
    assert max(speeds) > 3 * EQ7_AT_LANE  # fast while the way is long
    gaps = [math.dist(p, (12.0, 2.0)) - 1.3 for p in positions]  # body 0.3 m, disc 1 m
    assert min(gaps) > 0.0
    assert speeds[-1] < 0.05 and gaps[-1] < 0.5  # stopped, short of it
    # braking within the limits all the way
    assert max(abs(a - b) for a, b in itertools.pairwise(speeds)) <= CFG.max_accel * CFG.dt * 1.5


def test_the_route_room_brakes_for_the_next_turn_and_ignores_straight_nodes():
    field = _lane_field()
    # straight on through (10, 1.5), turning at (20, 1.5) with a 1 m reach
    nodes = [(10.0, 1.5), (20.0, 1.5), (20.0, 2.5)]
    room = route_room(field, 0.3, (2.0, 1.5), nodes, [1.0, 1.0], horizon=10.0)
    assert math.isclose(room, 18.0 - 1.0 + node_room(field, 0.3, (20.0, 1.5)))
    # the last node is a stop: the whole way there
    assert math.isclose(route_room(field, 0.3, (2.0, 1.5), [(12.0, 1.5)], [], 10.0), 10.0)
    # nothing to brake for within the horizon
    far = [(10.0, 1.5), (30.0, 1.5), (38.0, 1.5)]
    assert route_room(field, 0.3, (2.0, 1.5), far, [1.0, 1.0], horizon=5.0) == math.inf


def test_the_builtin_corridor_is_faster_than_the_paper_and_passes_in_its_lanes():
    scenario = with_traffic(load_scenario("corridor"), "zones")  # DWA's lanes, not the lattice
    lanes = {agv.name: agv.start[1] for agv in scenario.agvs}
    towards = {"left": 1.0, "right": -1.0}  # left's lane is below right's
    drift = dict.fromkeys(lanes, 0.0)

    def sink(key, message):
        if key == "world/tick" and abs(message.agvs[0].x - message.agvs[1].x) < 5.0:  # passing
            for agv in message.agvs:
                moved = towards[agv.name] * (agv.y - lanes[agv.name])
                drift[agv.name] = max(drift[agv.name], moved)

    default = run_in_process(scenario, sink).to_json()
    paper = run_in_process(with_profile(scenario, "paper")).to_json()
    assert default["end_reason"] == "every AGV arrived" and default["collisions"] == 0
    # Eq. 7 beside the wall held the default to 77 s; the paper slides to the middle: 52 s
    assert default["sim_time"] < paper["sim_time"]
    # seen too late at lane speed, the two wove towards each other by 0.19 m as they passed
    assert max(drift.values()) < 0.1
