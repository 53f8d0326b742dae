"""Driving on reserved nodes (traffic mode "reservations"): straight from node to node.

The schedule (``planner.traffic.schedule``) keeps every AGV on nodes no other AGV holds,
so what is left to the AGV is to keep to the lattice: it drives straight to the point
``planner.traffic.follow`` gives (the end of the first straight run of its reserved
nodes), on the braking curve, and stops there (``planner.nav.tight_turns``' straight
approach: an omnidirectional body slides back onto the line, and turns on the spot at
a corner). DWA's arcs drifted across a one-cell aisle (a 0.3 m body 0.29 m from the
shelf on the warehouse map); its AGV-versus-AGV rules are not needed where nobody else
is planned. Where a moving obstacle (a walker, which follows no schedule) is near,
or the straight way is not clear, DWA drives to the same point and avoids.
"""

from __future__ import annotations

import math

import numpy as np

from planner.core.status import ARRIVED, DRIVING, WAITING
from planner.maps.grid import Point
from planner.nav.fusion import ControlStep, FusionController
from planner.nav.mode import Mode
from planner.nav.tight_turns import approach_command, approach_path

STOPPED = 0.02
"""m/s and rad/s: below this the AGV stands."""


def drive_reserved(
    controller: FusionController,
    pose,
    command,
    now: float,
    point: Point,
    final: bool,
    moving: np.ndarray,
    walkers: np.ndarray,
) -> ControlStep:
    """One control cycle towards ``point`` (the AGV's goal when ``final``)."""
    position = (pose[0], pose[1])
    cfg = controller.config
    if controller.mode is Mode.FAILED:
        return ControlStep((0.0, 0.0, 0.0), "failed", None, np.empty((0, 3)), None, 0.0)
    standing = all(abs(v) < STOPPED for v in command)
    there = math.dist(position, point) <= cfg.goal_tolerance
    if final and there and standing:
        controller.arrive()
        return ControlStep((0.0, 0.0, 0.0), ARRIVED, point, np.empty((0, 3)), None, 0.0)
    status = WAITING if there else DRIVING
    dwa = cfg.dwa
    if len(walkers) == 0:
        path = approach_path(dwa, pose, command, point, dwa.max_speed)
        if controller.dwa.clearance_along(path, walkers) > 0.0:
            cmd = approach_command(dwa, pose, command, point, dwa.max_speed)
            return ControlStep(tuple(map(float, cmd)), status, point, path, None, 0.0)
    return controller.step(pose, command, now, moving, walkers, hold=point)
