"""The turn on the spot towards a target behind an AGV that cannot reverse (default
profile): DWA's arcs only circle, turning the body while driving on."""

from __future__ import annotations

import math

from planner.core.motion import Command, Pose, wrap_angle
from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.local.turning import turn_command
from planner.local.window import braking_command
from planner.maps.grid import Point

BEHIND = math.radians(120.0)
"""A target this far off the body's heading is behind it: turn round on the spot first ..."""
FACED = math.radians(30.0)
"""... and to a waiting place, until it is this near the heading. Handing over to DWA at
``BEHIND`` left it 120° off, and DWA's arc to it from there is a loop (an AGV sent from
one waiting place to another behind it looped in a crowded room). Not for route targets:
a longer turn there set the progress checker's recoveries off at tight corners."""


class TurnRound:
    """Whether the AGV is turning round on the spot, and the command that does it."""

    def __init__(self, config: DwaConfig, enabled: bool):
        self.config = config
        self.enabled = enabled and config.min_vx >= 0
        self.turning = False  # turning round: on until the target is ``faced`` off the heading

    def command(
        self, dwa: DwaPlanner, pose: Pose, command: Command, target: Point, moving,
        faced: float = BEHIND,
    ) -> Command | None:  # fmt: skip
        """The turn on the spot towards ``target`` when it is behind, unless a disc is
        coming (``dwa.threatened``); None otherwise. An AGV too fast to stop within its
        clearance brakes straight first: turning while it braked from lane speed swept an
        arc into a wall (a replan at top speed that sent the route back the way it came),
        while the way straight ahead is the old route's, clear at least to what made it
        replan. Once turning, it turns on until the target is ``faced`` off the heading."""
        if not self.enabled:
            return None
        bearing = math.atan2(target[1] - pose[1], target[0] - pose[0])
        error = float(wrap_angle(bearing - pose[2]))
        if abs(error) <= (faced if self.turning else BEHIND) or dwa.threatened(pose, moving):
            self.turning = False
            return None
        cfg = self.config
        stopping = math.hypot(command[0], command[1]) ** 2 / (2.0 * cfg.max_accel)
        if stopping > dwa.distance_field.distance_at_point(pose[0], pose[1]) - cfg.radius:
            return braking_command(cfg, command)
        turn = turn_command(cfg, error, command)
        self.turning = turn is not None
        return turn
