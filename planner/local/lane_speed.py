"""The speed an AGV may keep along its route: braking room ahead, not clearance beside.

Eq. (7) bounds a sample's speed by its trajectory's least clearance, so an AGV
that faces its travel along a wall 0.2 m away may go sqrt(2 a 0.2) = 0.28 m/s
at Table 1's limits, however clear the way ahead (along a corridor, half as long
again as the paper's DWA, which slides sideways to the middle first). Fox et al.'s
rule bounds it by the distance the AGV can still travel without contact, which
a wall beside the lane does not shorten.

On its route (trajectories within ``ROUTE_TOLERANCE`` of the current segment,
whose key nodes keep the body clear), the default profile bounds the linear
speed by the least of:

- the length of the contact-free predicted path (braking along it cannot touch
  a known obstacle; stopping within the horizon also keeps the stop within the
  sensing radius, where a newly sensed wall can be);
- ``route_room``: the route's braking profile, so that the AGV is already at
  the speed Eq. (7) allows where the route turns (the clearance at that node)
  or at rest where it stops (a waiting place, the goal): an
  AGV that ran fast along a lane and met Eq. (7) again only after the turn had
  to shed its speed in one go (the first room-ahead bound: nav_bench jerk
  0.82 m/s³);
- the gap to moving discs (their future is only predicted: Eq. (7) as the paper);
- towards a place it stops at, the room left before what stands behind it once
  the constant-velocity horizon runs past (``stop_room``).

The turn rate keeps Eq. (7)'s clearance bound; off the route the paper's bound
applies unchanged. With a walker within ``WALKER_RANGE`` (the room to yield, as
elsewhere) or a disc closing fast (``oncoming``) the route grants no room: only the
hardest braking from the current speed (``braking_room``), which DWA always allows
the samples on the route, until Eq. (7) holds again.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.core.motion import turned_velocity
from planner.core.path_metrics import turn_angle
from planner.core.physics import braking_distance
from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point

ROUTE_TOLERANCE = 0.25
"""m: a trajectory this near the route's current segment follows the route."""

STRAIGHT_ON = math.radians(5.0)
"""rad: a key node turning the route by less than this does not slow the AGV."""


def node_room(field: DistanceField, radius: float, node: Point) -> float:
    """Eq. (7)'s room at ``node``: the body's clearance there (m, >= 0)."""
    return max(0.0, field.distance_at_point(node[0], node[1]) - radius)


def route_room(
    field: DistanceField,
    radius: float,
    position: Point,
    nodes: list[Point],
    reaches: list[float],
    horizon: float,
) -> float:
    """The braking room (m) the route ahead grants at ``position``: the AGV may go
    sqrt(2 a room) and still meet the next turn at Eq. (7)'s speed there, or stop at
    the last node.

    ``nodes`` are the targets ahead (the AGV stops at the last); the next segment's
    bound applies within ``reaches[i]`` of node i (where the controller switches to
    the next target, or a tight corner's straight approach begins). A node the route
    goes straight on through does not count. Nodes farther than ``horizon`` along the
    route (more than any braking distance) are not looked at: ``math.inf``.
    """
    along, previous = 0.0, position
    for i, node in enumerate(nodes):
        along += math.dist(previous, node)
        if i == len(nodes) - 1:
            return along
        if turn_angle(previous, node, nodes[i + 1]) > STRAIGHT_ON:
            return max(0.0, along - reaches[i]) + node_room(field, radius, node)
        if along > horizon:
            return math.inf
        previous = node
    return math.inf


def braking_room(speed: float, max_accel: float, dt: float) -> float:
    """The room (m) to stop from ``speed`` less one period of the hardest deceleration:
    granted, only the samples that brake that hard, or that Eq. (7) admits, stay admissible."""
    return braking_distance(max(0.0, speed - max_accel * dt), max_accel)


def oncoming(pose, command, moving, max_accel: float, horizon_s: float) -> bool:
    """Whether a moving disc (rows [x, y, vx, vy, r]) closes on the AGV so fast that they
    meet before it could brake from its speed and still look a horizon ahead: then the
    lane's speed is shed before they meet. Two AGVs at 1.2 m/s head-on in neighbouring
    lanes saw each other within the horizon (7 m) too late to slow to Eq. (7)'s speed
    for their 0.4 m gap, and wove about as they passed."""
    if moving is None or not len(moving):
        return False
    discs = np.ascontiguousarray(np.asarray(moving, dtype=float).reshape(-1, 5))
    vx, vy = turned_velocity(float(pose[2]), float(command[0]), float(command[1]), 0.0, 0.0)
    lead = math.hypot(vx, vy) / max_accel + horizon_s  # s: braking, then a horizon's look
    return _closing_in_time(discs, float(pose[0]), float(pose[1]), vx, vy, lead)


@numba.njit(cache=True)
def _closing_in_time(discs, x, y, vx, vy, lead):
    """``oncoming``'s test of each disc, compiled (it runs every control cycle)."""
    for i in range(discs.shape[0]):
        dx, dy = discs[i, 0] - x, discs[i, 1] - y
        distance = max(np.hypot(dx, dy), 1e-9)
        closing = ((vx - discs[i, 2]) * dx + (vy - discs[i, 3]) * dy) / distance
        if closing > 0.0 and distance < closing * lead:
            return True
    return False


@numba.njit(cache=True)
def stop_room(distance: float, behind: float, speed: np.ndarray, horizon_s: float) -> np.ndarray:
    """(N,) the room to brake before a place the AGV stops at, ``distance`` away with
    ``behind`` of clearance round it: the constant-velocity horizon of a sample at
    ``speed`` runs past the place and must stop short of what stands behind it, else
    near the place every fast sample touches the wall behind and none is admissible."""
    return np.maximum(np.minimum(distance, distance + behind - speed * horizon_s), 0.0)


@numba.njit(cache=True)
def on_route_room(offsets, braking, clearance, tolerance):
    """``braking`` where a sample follows the route (within ``tolerance``) and it exceeds
    the clearance, else 0: numpy's ``where`` of the two tests, in one call."""
    out = np.empty(len(braking))
    for i in range(len(braking)):
        follows = offsets[i] <= tolerance and braking[i] > clearance[i]
        out[i] = braking[i] if follows else 0.0
    return out
