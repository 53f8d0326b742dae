"""Which key node is DWA's local target, when it switches to the next, and which are passed.

The global plan's key nodes (improved A*; for ``astar-dwa`` the traditional path's turning
points) are DWA's successive local targets; the last is the goal, never switched from. The
target switches to the next key node as soon as the AGV is within its reach: the paper's
``switch_distance``, or (default profile) less where switching early would cut into a
narrow stretch (``planner.nav.tight_turns``). A tight corner with a sharp turn is driven
to straight, stopped at and switched from only then (the AGV then turns on the spot). A key
node gone by beside it is switched from when the next is in plain sight
(``planner.nav.passed_node``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np

from planner.core.motion import Command, Pose
from planner.local.behaviour import LocalBehaviour
from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point
from planner.nav.config import FusionConfig
from planner.nav.passed_node import in_plain_sight, passed_beside
from planner.nav.tight_turns import Corner, corners, stopped_enough

Approach = tuple[Command, np.ndarray]
"""A straight approach to a node: its command and its predicted (K, 3) path."""


class KeyNodeTargets:
    """The key nodes of the route the AGV follows, the current one and how each is passed."""

    def __init__(self, config: FusionConfig, behaviour: LocalBehaviour, goal: Point):
        self.config = config
        self.behaviour = behaviour
        self.nodes: list[Point] = []
        self.index = 0
        self.corners: list[Corner] = []  # how each node but the goal is passed
        self.planned_at = goal  # where the AGV was when it last planned

    # --- a new route ----------------------------------------------------------------
    def follow(self, nodes: list[Point], position: Point, field: DistanceField) -> None:
        """Follow ``nodes`` (a new plan's key nodes after the start, the goal last) from
        ``position``, where the AGV planned them."""
        self.planned_at = position
        self.nodes = nodes
        self.index = 0
        self.corners = self.corners_of(position, field)

    def aim_at(self, goal: Point, position: Point) -> None:
        """No route (DWA alone): the goal is the one target."""
        self.nodes = [goal]
        self.index = 0
        self.planned_at = position

    def drop(self) -> None:
        """No way to the goal: no targets left."""
        self.nodes = []

    def corners_of(self, position: Point, field: DistanceField) -> list[Corner]:
        """Each node's switch reach: the paper's ``switch_distance``, or (default profile)
        less where switching early would cut into a narrow stretch."""
        reach = self.config.switch_distance
        if not self.behaviour.tight_turns:
            return [Corner(reach, False)] * (len(self.nodes) - 1)
        return corners(field, self.config.dwa.radius, position, self.nodes, reach)

    # --- where the AGV is on it -------------------------------------------------------
    @property
    def current(self) -> Point:
        return self.nodes[self.index]

    @property
    def final(self) -> bool:
        """Whether the current target is the goal."""
        return self.index == len(self.nodes) - 1

    def ahead(self) -> list[Point]:
        """The targets still ahead, the current one first."""
        return self.nodes[self.index :]

    def segment_start(self) -> Point:
        """Where the route's current segment starts: the previous key node, or where the
        AGV was when it planned."""
        return self.nodes[self.index - 1] if self.index else self.planned_at

    def route_ahead(self) -> list[Point]:
        """The rest of the route: from the start of the current segment, the targets ahead."""
        return [self.segment_start(), *self.ahead()]

    def remaining(self, position: Point) -> float:
        """Route length left: to the current target, then along the remaining targets."""
        route = [position, *self.ahead()]
        return float(sum(math.dist(a, b) for a, b in itertools.pairwise(route)))

    def dwa_reach(self) -> float:
        """How near DWA must come to the current key node to switch to the next: the
        corner's reach, or the paper's ``switch_distance`` at a stop corner (DWA cannot
        stop on a point: near one its near-best samples spiral round it)."""
        corner = self.corners[self.index]
        return self.config.switch_distance if corner.stop else corner.reach

    # --- switching ----------------------------------------------------------------------
    def advance(
        self,
        pose: Pose,
        command: Command,
        field: DistanceField,
        straight_to: Callable[[Point], Approach | None],
    ) -> tuple[Approach | None, bool]:
        """Switch to the next target within the current one's reach. ``straight_to(node)``
        is the straight approach to a node when it is clear (None: DWA drives). A tight
        corner that the approach can drive to is switched from only once stopped there;
        returns that approach for the current target (None when DWA drives: then a tight
        corner whose approach is not clear, e.g. with a walker near, is passed like any key
        node), and True when the AGV has just stopped at such a corner and switched: it
        turns on the spot towards the next stretch."""
        last = len(self.nodes) - 1
        while self.index < last:
            corner = self.corners[self.index]
            node = self.nodes[self.index]
            distance = math.dist(pose[:2], node)
            straight = straight_to(node) if corner.stop else None
            if straight is None:
                if distance > self.dwa_reach() and not self._passed_beside(pose, corner, field):
                    return None, False
            elif distance > corner.reach or not stopped_enough(self.config.dwa, command):
                return straight, False  # not there, or not stopped yet
            self.index += 1
            if straight is not None:
                return None, True
        return None, False

    def _passed_beside(self, pose: Pose, corner: Corner, field: DistanceField) -> bool:
        """Default profile: the AGV went past the current key node beside it, beyond its
        reach, and sees the next one in plain sight: it switches on instead of turning back
        to the node. Not at a stop corner (a narrow stretch follows: it is entered from the
        node)."""
        if not self.behaviour.pass_beside or corner.stop:
            return False
        position = (pose[0], pose[1])
        node, after = self.nodes[self.index], self.nodes[self.index + 1]
        if not passed_beside(position, self.segment_start(), node, after, corner.reach):
            return False
        return in_plain_sight(field, position, after, self.config.safety_distance)
