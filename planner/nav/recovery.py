"""Bounded recoveries for a stalled AGV, in the manner of Nav2's behaviours.

When the progress checker finds no progress, the controller runs the next
recovery of ``RECOVERIES``; progress resets the sequence. When the sequence
is exhausted without progress the AGV fails with the reason, instead of
orbiting for ever. Each recovery is a few seconds of commands within the
acceleration limits (``replan`` is instant: plan again with every sensed
blocker marked).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from planner.core.motion import Command, Pose
from planner.core.status import BACK_OFF, REPLAN, ROTATE, WAIT
from planner.local.config import DwaConfig
from planner.maps.distance_field import DistanceField

RECOVERIES = (REPLAN, WAIT, BACK_OFF, REPLAN, ROTATE, REPLAN)
"""Cheapest first, a replan after each move (what the move uncovered is planned round), as
Nav2's recovery subtree clears the costmap before it spins and backs up."""
DURATION_S = {REPLAN: 0.0, WAIT: 3.0, BACK_OFF: 2.0, ROTATE: 3.0}
"""s each recovery drives: a wait of a few seconds for a walker or AGV in the way to move
on; a back-off and a rotation just long enough (a few tenths of a metre, some 60° at the
default limits) to change what DWA sees, not to wander off the route."""
BACK_OFF_SPEED = 0.3
"""m/s: a slow back-off, from a stall in cramped space, reached and braked within a second
or two at the default acceleration."""


@dataclass(frozen=True)
class Recovery:
    kind: str
    until: float  # sim time at which it ends


def towards(config: DwaConfig, command: Command, wanted: Command) -> Command:
    """``command`` moved towards ``wanted`` by at most one period of acceleration per axis."""
    dv, dw = config.max_accel * config.dt, config.max_alpha * config.dt
    return step_towards(tuple(map(float, command)), tuple(map(float, wanted)), dv, dw)


@numba.njit(cache=True)
def step_towards(command, wanted, dv, dw):
    """``command`` (vx, vy, omega) moved towards ``wanted`` by at most ``dv`` on each linear
    axis and ``dw`` in turn rate (compiled: the tight corners' approach calls it too)."""
    return (
        command[0] + min(max(wanted[0] - command[0], -dv), dv),
        command[1] + min(max(wanted[1] - command[1], -dv), dv),
        command[2] + min(max(wanted[2] - command[2], -dw), dw),
    )


def clearance_at(field: DistanceField, discs: np.ndarray | None, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest obstacle: the map's, or a disc's edge (rows
    [x, y, vx, vy, r], where they stand now)."""
    gap = field.distance_at_point(x, y)
    if discs is not None and len(discs):
        gap = min(gap, float((np.hypot(discs[:, 0] - x, discs[:, 1] - y) - discs[:, 4]).min()))
    return gap


def _gradient(distance, x: float, y: float, h: float) -> tuple[float, float] | None:
    """Unit direction in which ``distance(x, y)`` grows fastest (central differences over
    ``h``); None where it is flat."""
    gx = distance(x + h, y) - distance(x - h, y)
    gy = distance(x, y + h) - distance(x, y - h)
    norm = math.hypot(gx, gy)
    return None if norm < 1e-9 else (gx / norm, gy / norm)


def away_from_obstacles(
    field: DistanceField, pose: Pose, discs: np.ndarray | None = None, radius: float = 0.0
) -> tuple[float, float]:
    """Unit world-frame direction in which the distance to the nearest obstacle (walls, and
    the discs if given) grows fastest, kept off the walls (``off_walls``) for a body of
    ``radius``; (0, 0) where there is no such way."""
    x, y = pose[0], pose[1]
    away = _gradient(lambda px, py: clearance_at(field, discs, px, py), x, y, field.spacing)
    if away is None:
        away = (-math.cos(pose[2]), -math.sin(pose[2]))  # flat: straight back
    return off_walls(field, x, y, away, radius)


def off_walls(
    field: DistanceField, x: float, y: float, direction: tuple[float, float], radius: float
) -> tuple[float, float]:
    """``direction`` from (x, y), less its part into a wall a body of ``radius`` would press
    against; (0, 0) when nothing is left (a corner).

    Away from a walker that stands on the AGV is often into a wall: a back-off from a
    walker standing on an AGV in a corner drove 0.3 m into the corner where two wall
    cells meet. Discs give way or are merely predicted; a wall does not.
    """

    if not presses_wall(field, x, y, direction, radius):
        return direction
    normal = _gradient(lambda px, py: field.distance_at_point(px, py), x, y, field.spacing)
    if normal is None:
        return (0.0, 0.0)
    into = direction[0] * normal[0] + direction[1] * normal[1]
    tx, ty = direction[0] - into * normal[0], direction[1] - into * normal[1]
    norm = math.hypot(tx, ty)
    if norm < 1e-6:
        return (0.0, 0.0)
    along = (tx / norm, ty / norm)
    return (0.0, 0.0) if presses_wall(field, x, y, along, radius) else along


def presses_wall(
    field: DistanceField, x: float, y: float, direction: tuple[float, float], radius: float
) -> bool:
    """Whether a body of ``radius`` at (x, y) moving along the unit ``direction`` comes
    nearer a wall than it may: than touching, or than it already is where it touches."""
    floor = min(radius, field.distance_at_point(x, y))
    step = field.spacing
    ahead = field.distance_at_point(x + direction[0] * step, y + direction[1] * step)
    return ahead < floor - 1e-9


def recovery_command(
    kind: str, config: DwaConfig, field: DistanceField, pose: Pose, command: Command,
    discs: np.ndarray | None = None,
) -> Command:  # fmt: skip
    """One period of the recovery ``kind``: ``wait`` brakes, ``back off`` drives slowly away
    from the nearest obstacle, a wall or one of the ``discs`` (other AGVs, walkers; body
    frame, so an omnidirectional AGV needs no turn), ``rotate`` turns in place at the
    highest rate."""
    if kind == BACK_OFF:
        wanted = (*_backing(config, field, pose, discs), 0.0)
    elif kind == ROTATE:
        wanted = (0.0, 0.0, config.max_omega)
    else:
        wanted = (0.0, 0.0, 0.0)
    return towards(config, command, wanted)


def _backing(config: DwaConfig, field: DistanceField, pose: Pose, discs) -> tuple[float, float]:
    """The body-frame (vx, vy) of backing off: away from the nearest obstacle, off the walls,
    and no slower than ``min_vx`` allows. Where that floor cuts off part of the way back,
    what is left must still keep off the walls, or the AGV stands: an AGV that cannot
    reverse and faces a shelf kept only the sideways part of "back along the shelf", and
    that pressed it into the shelf (an AGV stalled nose-on to a shelf in a crowded
    warehouse aisle)."""
    ux, uy = away_from_obstacles(field, pose, discs, config.radius)
    if not (ux or uy):
        return (0.0, 0.0)
    speed = min(BACK_OFF_SPEED, config.max_speed)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    vx, vy = speed * (ux * c + uy * s), speed * (-ux * s + uy * c)
    if vx >= config.min_vx:
        return (vx, vy)
    vx = config.min_vx
    wx, wy = vx * c - vy * s, vx * s + vy * c  # what is left, in the world frame
    norm = math.hypot(wx, wy)
    if norm < 1e-9:
        return (0.0, 0.0)
    left = (wx / norm, wy / norm)
    if presses_wall(field, pose[0], pose[1], left, config.radius):
        return (0.0, 0.0)
    return (vx, vy)


def is_stopped(command: Command | np.ndarray, tolerance: float = 1e-6) -> bool:
    """True when every component of ``command`` is zero (within ``tolerance``)."""
    return all(abs(float(v)) <= tolerance for v in command)
