"""Whether the AGV has arrived (Nav2's ``GoalChecker``: ``isGoalReached(pose, goal, velocity)``)."""

from __future__ import annotations

import math

from planner.core.motion import Command
from planner.maps.grid import Point
from planner.nav.recovery import is_stopped


class GoalChecker:
    """Arrived: within ``tolerance`` of the goal, and (``stop_required``, the default
    profile's smooth arrival) stopped there; the paper's AGV arrives on entering the
    tolerance, at whatever speed."""

    def __init__(self, tolerance: float, stop_required: bool):
        self.tolerance = tolerance
        self.stop_required = stop_required

    def within(self, position: Point, goal: Point) -> bool:
        """Whether ``position`` is inside the goal's tolerance."""
        return math.dist(position, goal) <= self.tolerance

    def is_goal_reached(self, position: Point, goal: Point, velocity: Command) -> bool:
        """Whether the AGV at ``position`` moving at ``velocity`` has arrived at ``goal``."""
        if not self.within(position, goal):
            return False
        return not self.stop_required or is_stopped(velocity)
