"""Where a stalled AGV has been since it first stalled: coming back there is no progress.

Progress is the remaining route shrinking (``planner.nav.progress_checker``), and each
recovery's replan measures it anew from the new route, where the AGV stands. An AGV
stalled at a stop corner whose way on is blocked backed off, drove back to the corner
along its new route and crept there again: the new route's metres back counted as
progress, the recoveries started from the first again (``CALM_WINDOWS``), and it drove
round them until the time limit. As Nav2's progress checker asks the robot to get away
from where it was, the places reached between the sequence's first and last stall are
old ground: driving on the new route counts again only off them.
"""

from __future__ import annotations

import math

import numpy as np

from planner.maps.grid import Point


class OldGround:
    """The places reached in one sequence of stalls, up to its last stall."""

    def __init__(self, reach: float):
        self.reach = reach  # m: this near a place reached is that place
        self._trail: list[Point] = []  # since the sequence's first stall, ``reach`` / 2 apart
        self._old = np.zeros((0, 2))  # the trail up to the last stall

    def note(self, position: Point) -> None:
        """The AGV is at ``position``: a place of the trail while a sequence runs."""
        if self._trail and math.dist(self._trail[-1], position) >= self.reach / 2:
            self._trail.append(position)

    def stall(self, position: Point) -> None:
        """A stall at ``position``: every place reached so far in the sequence is old."""
        self._trail.append(position)
        self._old = np.array(self._trail)

    def reached(self, position: Point) -> bool:
        """Whether ``position`` is within ``reach`` of old ground."""
        old = self._old
        if not len(old):
            return False
        return bool((np.hypot(old[:, 0] - position[0], old[:, 1] - position[1]) < self.reach).any())

    def clear(self) -> None:
        """A new sequence: nothing is old ground."""
        self._trail, self._old = [], np.zeros((0, 2))
