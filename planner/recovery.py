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

import numpy as np

from planner.distance_field import DistanceField
from planner.dwa import Command, DwaConfig, Pose

RECOVERIES = ("replan", "wait", "back off", "replan", "rotate", "replan")
DURATION_S = {"replan": 0.0, "wait": 3.0, "back off": 2.0, "rotate": 3.0}
BACK_OFF_SPEED = 0.3  # m/s


@dataclass(frozen=True)
class Recovery:
    kind: str
    until: float  # sim time at which it ends


def towards(config: DwaConfig, command: Command, wanted: Command) -> Command:
    """``command`` moved towards ``wanted`` by at most one period of acceleration per axis."""
    dv, dw = config.max_accel * config.dt, config.max_alpha * config.dt
    return tuple(  # type: ignore[return-value]
        c + min(max(w - c, -d), d) for c, w, d in zip(command, wanted, (dv, dv, dw), strict=True)
    )


def clearance_at(field: DistanceField, discs: np.ndarray | None, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest obstacle: the map's, or a disc's edge (rows
    [x, y, vx, vy, r], where they stand now)."""
    gap = float(field.distance_at(x, y))
    if discs is not None and len(discs):
        gap = min(gap, float((np.hypot(discs[:, 0] - x, discs[:, 1] - y) - discs[:, 4]).min()))
    return gap


def away_from_obstacles(
    field: DistanceField, pose: Pose, discs: np.ndarray | None = None
) -> tuple[float, float]:
    """Unit world-frame direction in which the distance to the nearest obstacle (walls, and
    the discs if given) grows fastest."""
    h = field.spacing
    x, y = pose[0], pose[1]
    gx = clearance_at(field, discs, x + h, y) - clearance_at(field, discs, x - h, y)
    gy = clearance_at(field, discs, x, y + h) - clearance_at(field, discs, x, y - h)
    norm = math.hypot(float(gx), float(gy))
    if norm < 1e-9:
        return (-math.cos(pose[2]), -math.sin(pose[2]))  # flat: straight back
    return (float(gx) / norm, float(gy) / norm)


def recovery_command(
    kind: str, config: DwaConfig, field: DistanceField, pose: Pose, command: Command,
    discs: np.ndarray | None = None,
) -> Command:  # fmt: skip
    """One period of the recovery ``kind``: ``wait`` brakes, ``back off`` drives slowly away
    from the nearest obstacle, a wall or one of the ``discs`` (other AGVs, walkers; body
    frame, so an omnidirectional AGV needs no turn), ``rotate`` turns in place at the
    highest rate."""
    if kind == "back off":
        ux, uy = away_from_obstacles(field, pose, discs)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        speed = min(BACK_OFF_SPEED, config.max_speed)
        vx, vy = speed * (ux * c + uy * s), speed * (-ux * s + uy * c)
        wanted = (max(vx, config.min_vx), vy, 0.0)
    elif kind == "rotate":
        wanted = (0.0, 0.0, config.max_omega)
    else:
        wanted = (0.0, 0.0, 0.0)
    return towards(config, command, wanted)


def is_stopped(command: Command | np.ndarray, tolerance: float = 1e-6) -> bool:
    """True when every component of ``command`` is zero (within ``tolerance``)."""
    return all(abs(float(v)) <= tolerance for v in command)
