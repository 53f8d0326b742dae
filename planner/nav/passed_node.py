"""A key node the AGV went past beside it, outside its switch reach.

The fusion controller switches to the next key node within ``reach`` of the current
one. When DWA keeps the AGV off another body near the node (an AGV waiting beside the
route, one coming the other way), the AGV can go past the node more than ``reach`` to
its side; aiming at the node still, it then turns back to it and loops (an AGV out of
a 1.0 m door swerved round one waiting beside its route, went by its next key node
1.1 m off and circled back to it).

The node counts as passed when the AGV is no more than ``reach`` short of it along the
route's leg into it, no more than ``reach`` short of it along the leg out of it (the
region a reach circle sweeps, extended past the node), and the next key node is in
plain sight: the straight way to it keeps the safety distance from every obstacle, so
going there directly cuts no corner the route went round.
"""

from __future__ import annotations

import math

from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point
from planner.route.route_check import blocked_point


def passed_beside(position: Point, before: Point, node: Point, after: Point, reach: float) -> bool:
    """Whether ``position`` is no more than ``reach`` short of ``node`` along both the leg
    ``before`` → ``node`` and the leg ``node`` → ``after``."""
    offset = (position[0] - node[0], position[1] - node[1])
    for a, b in ((before, node), (node, after)):
        length = math.dist(a, b)
        if length == 0.0:
            continue
        along = (offset[0] * (b[0] - a[0]) + offset[1] * (b[1] - a[1])) / length
        if along < -reach:
            return False
    return True


def in_plain_sight(field: DistanceField, position: Point, target: Point, safety: float) -> bool:
    """Whether the straight way from ``position`` to ``target`` keeps ``safety`` m from every
    obstacle."""
    return blocked_point(field, [position, target], safety) is None
