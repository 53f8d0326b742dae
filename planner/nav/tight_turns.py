"""Key nodes where the route turns into a passage with little room to spare.

The fusion controller switches its local target to the next key node as soon
as the AGV is within ``switch_distance`` (1 m) of the current one. DWA then
aims at the next node and cuts the corner. In open space that is what makes
the motion smooth; where the next stretch is a 1.0 m corridor or door and the
body has 0.2 m to spare, cutting the corner by more than that puts the AGV
beside the mouth instead of in it, and it slides along the wall (the traffic
suite's solo failures at 1.0 m openings).

Switching within ``r`` of a node that turns by ``phi`` cuts the corner by
about ``r sin(phi)`` across the next stretch, so the switch reach is capped at
``room / sin(phi)``, ``room`` being the body's least free space along the
start of the next stretch. Where the turn is sharp as well (``TURN_ON_SPOT``),
the AGV brakes to the node, stops and turns on the spot to face the next
stretch before it drives on, as industrial AGVs do at aisle ends. The last
metres to such a node are driven straight, braking along sqrt(2 a d)
(``approach_command``): DWA's constant-velocity arcs cannot end at rest on a
point, and near one its near-best samples spiral round it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from planner.core.cpython_math import hypot, remainder
from planner.core.motion import Command, Pose, step_pose
from planner.core.path_metrics import turn_angle
from planner.local.config import DwaConfig
from planner.local.turning import stopping_rate
from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point
from planner.nav.recovery import step_towards
from planner.route.route_check import route_samples

TURN_ON_SPOT = math.radians(10.0)
"""A tight node turning the route by more than this is a stop and a turn on the spot; a
smaller turn is driven through (its capped reach keeps the cut within the room)."""

LOOK_AHEAD = 2.0
"""m: how much of the next stretch counts for the room the body has where it enters (where
a cut corner puts it)."""

FACE_FROM = 0.5
"""m: the straight approach turns the body towards the node until this near it (nearer,
the bearing swings fast with every centimetre off the line)."""

FACE_FIRST = math.radians(15.0)
"""rad: a node this far off the heading is faced first, turning on the spot (turning while
driving bends the way: the body-frame velocity turns with the body)."""

FACED = 1e-9
"""rad: a heading error this small is rounding left by the last period's turn (closing the
error exactly): chasing it drove ω of ±1e-15 rad/s, flipping sign every tick or two."""

MIN_REACH = 0.1
"""m: the least switch reach (the AGV must be able to get this near a node)."""


@dataclass(frozen=True)
class Corner:
    """How the controller passes one key node."""

    reach: float  # switch to the next node within this distance
    stop: bool  # brake to the node, stop and turn on the spot towards the next


def room_ahead(field: DistanceField, radius: float, node: Point, after: Point) -> float:
    """The body's least free space (m, >= 0) along the first ``LOOK_AHEAD`` of node → after."""
    length = math.dist(node, after)
    if length > LOOK_AHEAD:
        t = LOOK_AHEAD / length
        after = (node[0] + t * (after[0] - node[0]), node[1] + t * (after[1] - node[1]))
    points = route_samples([node, after], field.spacing / 2)
    return max(0.0, float(field.distance_at(points[:, 0], points[:, 1]).min()) - radius)


def corner(
    field: DistanceField,
    radius: float,
    before: Point,
    node: Point,
    after: Point,
    switch_distance: float,
) -> Corner:
    """How to pass ``node`` (between ``before`` and ``after``) without cutting into a wall."""
    phi = turn_angle(before, node, after)
    sine = math.sin(min(phi, math.pi / 2))  # past 90 degrees the cut is the whole reach
    if sine * switch_distance <= room_ahead(field, radius, node, after):
        return Corner(switch_distance, False)
    reach = max(MIN_REACH, room_ahead(field, radius, node, after) / sine)
    return Corner(min(reach, switch_distance), phi > TURN_ON_SPOT)


def corners(
    field: DistanceField, radius: float, start: Point, targets: list[Point], switch_distance: float
) -> list[Corner]:
    """One ``Corner`` per target but the last (the goal, which is never switched from)."""
    route = [start, *targets]
    return [
        corner(field, radius, route[i - 1], route[i], route[i + 1], switch_distance)
        for i in range(1, len(route) - 1)
    ]


def stopped_enough(config: DwaConfig, command: Command) -> bool:
    """True when one period of braking stops the AGV (at a node it then turns on the spot:
    the turn brakes the rest)."""
    return math.hypot(command[0], command[1]) <= config.max_accel * config.dt + 1e-9


def approach_path(
    config: DwaConfig, pose: Pose, command: Command, node: Point, cap: float
) -> np.ndarray:
    """(K, 3) the poses after each of the horizon's steps of ``approach_command``, as
    DWA's rollouts are (closed loop: the commands bend from the current velocity)."""
    return _approach_path(
        _limits(config), config.steps, _floats(pose), _floats(command), _floats(node), float(cap)
    )


def approach_command(
    config: DwaConfig, pose: Pose, command: Command, node: Point, cap: float
) -> Command:
    """The next command driving straight to ``node`` and stopping there: the speed follows
    the braking curve sqrt(2 a d), at most ``cap`` and d / dt; the velocity changes by at
    most a period of acceleration per axis, scaled as a whole so that its direction holds
    (an omnidirectional body slides sideways for what is off its heading; vx stays within
    ``min_vx``). Farther than ``FACE_FROM`` the body turns to face
    the node (on the curve sqrt(2 alpha |error|), as ``turn_command``), on the spot first
    when it is more than ``FACE_FIRST`` off; nearer, the turn rate brakes to zero (the
    turn on the spot at the node follows)."""
    return _approach(_limits(config), _floats(pose), _floats(command), _floats(node), float(cap))


def _limits(config: DwaConfig) -> tuple[float, ...]:
    """What the compiled approach needs of ``config``."""
    return (
        config.max_speed, config.max_accel, config.max_alpha, config.max_omega, config.min_vx,
        config.dt,
    )  # fmt: skip


def _floats(values) -> tuple[float, ...]:
    return tuple(map(float, values))


@numba.njit(cache=True)
def _approach_path(limits, steps, pose, command, node, cap):
    """``approach_path``, compiled: 30 steps of the pure-Python approach were a tenth of an
    AGV's step near a tight corner."""
    path = np.empty((steps, 3))
    for k in range(steps):
        command = _approach(limits, pose, command, node, cap)
        pose = step_pose(pose, command, limits[5])
        path[k, 0], path[k, 1], path[k, 2] = pose
    return path


@numba.njit(cache=True)
def _approach(limits, pose, command, node, cap):
    """``approach_command``, compiled (with CPython's hypot and remainder: bit for bit the
    Python it replaced)."""
    max_speed, max_accel, max_alpha, max_omega, min_vx, dt = limits
    dv, dw = max_accel * dt, max_alpha * dt
    dx, dy = node[0] - pose[0], node[1] - pose[1]
    distance = hypot(dx, dy)
    if distance < 1e-9:  # there: every component towards zero
        return step_towards(command, (0.0, 0.0, 0.0), dv, dw)
    # the braking curve, and no faster than reaches the node in one period (no overshoot
    # and no chatter round it)
    speed = min(cap, max_speed, math.sqrt(2.0 * max_accel * distance), distance / dt)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    vx = speed * (dx * c + dy * s) / distance
    vy = speed * (-dx * s + dy * c) / distance
    omega = 0.0
    error = remainder(math.atan2(dy, dx) - pose[2], math.tau)
    if distance > FACE_FROM and abs(error) > FACED:
        if abs(error) > FACE_FIRST:  # face the node first: brake and turn on the spot
            vx = vy = 0.0
        # turning the body turns a body-frame velocity with it: no faster than half a period
        # of acceleration can make up for, so that the way stays straight
        moving = hypot(command[0], command[1])
        fastest = min(max_omega, max_accel / (2.0 * moving) if moving else math.inf)
        # on the braking curve of whole periods, and no faster than closes the error in
        # one period: the continuous curve alone overshoots a small error within a period,
        # and omega flipped sign every tick on straight approaches (+-0.1 rad/s on the
        # depot, at 60 deg/s limits)
        turn = stopping_rate(abs(error), dw, dt)
        omega = math.copysign(min(fastest, turn), error)
    # the linear change scaled as a whole (not clipped per axis), so that the velocity turns
    # towards the node's direction along a straight line instead of bending round it
    dvx, dvy = max(vx, min_vx) - command[0], vy - command[1]
    scale = max(abs(dvx), abs(dvy)) / dv
    if scale > 1.0:
        dvx, dvy = dvx / scale, dvy / scale
    return (command[0] + dvx, command[1] + dvy, command[2] + min(max(omega - command[2], -dw), dw))
