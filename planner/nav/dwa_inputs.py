"""What the controller hands DWA beyond its target, and the straight approach that takes
DWA's place over the last metres to a node.

- The route's current segment, for DWA's on-route term, shifted to the right while
  another AGV comes the other way (``planner.local.keep_right``).
- The braking room the route ahead grants DWA's samples that follow it
  (``planner.local.lane_speed``).
- The straight approach to a tight corner, the goal or a waiting place
  (``planner.nav.tight_turns``): DWA's arcs cannot end at rest on a point.
"""

from __future__ import annotations

import math

import numpy as np

from planner.core.motion import Command, Pose
from planner.local.behaviour import LocalBehaviour
from planner.local.dwa import DwaPlanner
from planner.local.keep_right import agv_coming, right_offset, shifted_right
from planner.local.lane_speed import oncoming, route_room
from planner.local.yielding import (
    agvs_of,
    contact_later,
    walker_near,
    walker_standing_near,
    walkers_standing,
)
from planner.maps.grid import Point
from planner.nav.config import FusionConfig
from planner.nav.tight_turns import Corner, approach_command, approach_path


def route_segment(
    behaviour: LocalBehaviour, config: FusionConfig, dwa: DwaPlanner,
    segment: tuple[Point, Point], pose: Pose, moving, walkers,
) -> tuple[Point, Point]:  # fmt: skip
    """``segment`` (from its start to DWA's target), shifted to the right while another AGV
    comes the other way along it."""
    if not behaviour.keep_right:
        return segment
    field, radius = dwa.distance_field, config.dwa.radius
    if not agv_coming(pose[:2], segment, radius, agvs_of(moving, walkers)):
        return segment
    return shifted_right(segment, right_offset(field, radius, segment))


def lane_room(
    behaviour: LocalBehaviour, config: FusionConfig, dwa: DwaPlanner, pose: Pose,
    command: Command, moving, walkers, nodes: list[Point], corners: list[Corner],
) -> float | None:  # fmt: skip
    """The braking room the route along ``nodes`` (``corners``: how each but the last is
    passed) grants DWA's samples that follow it. With a walker near or a disc coming
    (``oncoming``), none: DWA still grants the hardest braking from the current speed, so
    the AGV slows to Eq. (7)'s speed, keeping the room to yield or pass, instead of
    finding nothing admissible at once."""
    if not behaviour.lane_speed:
        return None
    cfg = config.dwa
    if walker_near(pose, walkers) or oncoming(pose, command, moving, cfg.max_accel, cfg.horizon_s):
        return 0.0
    # a tight corner's bound applies from where its straight approach begins
    corners = corners if len(nodes) > 1 else []
    reaches = [config.approach_distance if c.stop else c.reach for c in corners]
    horizon = cfg.max_speed**2 / (2.0 * cfg.max_accel)
    return route_room(dwa.distance_field, cfg.radius, (pose[0], pose[1]), nodes, reaches, horizon)


def straight_approach(
    config: FusionConfig, dwa: DwaPlanner, pose: Pose, command: Command, node: Point,
    moving, walkers, stalled_before: Point | None, route: list[Point], came_by: list[Point],
) -> tuple[Command, np.ndarray] | None:  # fmt: skip
    """The command and predicted path of the straight approach to ``node``, when within
    ``approach_distance``; no walker stands still within ``WALKER_RANGE`` (unless the AGV
    stalled before this node and every walker in range stands: ``stalled_before``); driven
    no faster than it can brake within its clearance (Eq. 7, as DWA's samples), it keeps
    clear of the map and the moving discs over the horizon; and no walker walking on
    reaches its end before the AGV could yield (``contact_later``: early yield's test of
    DWA's samples; a walker against the ``route`` is taken along it and on along
    ``came_by``). None: DWA drives (and avoids).

    The approach stops and turns at the corner, slow to get out of a walker's way, so it
    must leave the room to yield that DWA's samples must leave. A walker standing still
    may start at any time, and keeps it off within range. With any walker within 12 m
    instead, DWA's arcs took paper-dynamic's tight corners while its walker was 10 m off:
    ω bounced in the 1 m passage past (5.5, 3.5) (15 sign changes in 5 s) and the AGV
    stalled past (11.5, 14.5) in 14 of 21 runs of the walker sweep. But a walker that
    stopped where its walk ended may stand there for good, and a 1-cell gap that DWA's
    arcs cannot thread then failed the run (a walker standing still near the mouth of a
    narrow gap)."""
    if math.dist(pose[:2], node) > config.approach_distance:
        return None
    if walker_standing_near(pose, walkers) and not _stuck_past_standing(
        config, stalled_before, node, pose, walkers
    ):
        return None
    cfg = config.dwa
    room = dwa.clearance_along(approach_path(cfg, pose, command, node, cfg.max_speed), moving)
    if room <= 0.0:
        return None
    cap = math.sqrt(2.0 * room * cfg.max_accel)  # the approach keeps below Eq. (7)'s limit
    path = approach_path(cfg, pose, command, node, cap)
    if dwa.clearance_along(path, moving) <= 0.0:
        return None
    if walkers is not None and len(walkers):
        walkers = np.asarray(walkers, dtype=float).reshape(-1, 5)
        speed = math.hypot(command[0], command[1])
        end_x, end_y = path[-1:, 0], path[-1:, 1]
        if contact_later(cfg, end_x, end_y, walkers, speed, route, came_by)[0] < math.inf:
            return None
    return approach_command(cfg, pose, command, node, cap), path


def _stuck_past_standing(config: FusionConfig, before: Point | None, node: Point, pose, walkers):
    """Whether the AGV stalled before on its way to ``node`` and every walker in range
    stands still."""
    stuck = before is not None and math.dist(before, node) < config.goal_tolerance
    return stuck and walkers_standing(pose, walkers)
