"""A key node gone past beside it, beyond its reach, with the next one in plain sight, is
switched from, not turned back to (``planner.nav.passed_node``)."""

from __future__ import annotations

import math

from planner.core.profiles import PAPER
from planner.maps.distance_field import DistanceField
from planner.maps.text_maps import parse_text_grid
from planner.nav.fusion import FusionConfig, FusionController
from planner.nav.passed_node import in_plain_sight, passed_beside

# door n12 s3: R3 came out of the door at (10.5, 5.0), swerved north round an AGV waiting
# beside its route and went by its key node 1.1 m off; its goal lay north-west
BEFORE, NODE, AFTER = (10.5, 5.0), (5.5, 5.38), (0.75, 9.25)
BESIDE = (6.0, 6.4)


def test_a_node_gone_by_beside_is_passed_and_one_ahead_is_not():
    assert passed_beside(BESIDE, BEFORE, NODE, AFTER, reach=1.0)
    assert not passed_beside((7.0, 5.3), BEFORE, NODE, AFTER, reach=1.0)  # 1.5 m short
    # past the node along the leg in, but short of it along a leg out that turns back
    assert not passed_beside((4.0, 5.3), BEFORE, NODE, (9.0, 9.0), reach=1.0)


def test_plain_sight_keeps_the_safety_distance_from_walls():
    room = ["." * 40] * 12 + ["." * 20 + "#" * 4 + "." * 16] * 4 + ["." * 40] * 4
    field = DistanceField.from_grid(parse_text_grid("\n".join(room), resolution=0.25))
    # the wall block spans x 5-6 m, y 1-2 m (rows count from the top)
    assert in_plain_sight(field, (1.0, 4.0), (9.0, 4.0), safety=0.5)
    assert not in_plain_sight(field, (1.0, 2.4), (9.0, 2.4), safety=0.5)  # 0.4 m: body fits
    assert in_plain_sight(field, (1.0, 2.4), (9.0, 2.4), safety=0.3)


def _swerved(profile: str) -> FusionController:
    """A controller on an open 12 x 12 m floor, standing where R3 stood, aiming at the node."""
    floor = parse_text_grid("\n".join(["." * 48] * 48), resolution=0.25)
    controller = FusionController(floor, AFTER, FusionConfig(profile=profile))
    controller.start((*BEFORE, math.atan2(NODE[1] - BEFORE[1], NODE[0] - BEFORE[0])))
    # the route R3 had: its node beside the waiting AGV
    controller.key_nodes.follow([NODE, AFTER], BEFORE, controller.dwa.distance_field)
    controller.step((*BEFORE, 3.07), (0.0, 0.0, 0.0), now=0.0)  # the start's turn ends
    return controller


def test_the_controller_goes_on_to_the_next_node_instead_of_turning_back():
    swerved = _swerved("default")
    swerved.step((*BESIDE, 2.7), (0.5, 0.0, 0.0), now=1.0)
    assert swerved.key_nodes.index == 1
    paper = _swerved(PAPER)
    paper.step((*BESIDE, 2.7), (0.5, 0.0, 0.0), now=1.0)
    assert paper.key_nodes.index == 0  # the paper switches within 1 m only: back to the node
