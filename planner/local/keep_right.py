"""Keep right when another AGV comes the other way, as traffic does.

Two AGVs that meet head-on where there is room for both (a corridor 1.5 m wide,
an aisle) each follow the same centred route. DWA treats the other as a moving
disc, and two mirror-image AGVs make mirror-image choices: they stepped the same
way, backed off, turned, met again (two mirror-image AGVs in a corridor: 40 s of
dancing in its middle before they passed). A convention breaks the
symmetry without talking: while an AGV comes towards it, each follows its route
shifted to its right, by as much as the free space beside the route allows
(``right_offset``); the route's own key nodes, switching and corners are unchanged.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point

MARGIN = 0.05
"""m: kept between the body and a wall on the right."""

HEAD_ON = math.radians(135.0)
"""rad: an AGV moving more than this off the travel direction comes the other way."""

GAP = 0.2
"""m: two AGVs whose lines of travel pass at least this far apart are in lanes of their own."""

PASSED = 1.0
"""m: the shift holds until the other is this far behind (dropping it alongside swung the
body back towards the other)."""

REACH = 8.0
"""m: an AGV coming this near (centre to centre) makes the other keep right: at Table 1's
limits two AGVs closing at 2 x 0.45 m/s are 9 s apart, time enough to move over."""


def right_offset(field: DistanceField, radius: float, segment: tuple[Point, Point]) -> float:
    """How far right of ``segment`` (m) the AGV keeps: as far as one body's width, less
    where the free space beside the route is narrower (its least clearance along the
    segment, centred routes having as much on either side)."""
    (ax, ay), (bx, by) = segment
    steps = max(2, int(math.dist(segment[0], segment[1]) / field.spacing) + 1)
    t = np.linspace(0.0, 1.0, steps)
    free = float(field.distance_at(ax + t * (bx - ax), ay + t * (by - ay)).min())
    return min(max(0.0, free - radius - MARGIN), radius + MARGIN)


def shifted_right(segment: tuple[Point, Point], offset: float) -> tuple[Point, Point]:
    """``segment`` moved ``offset`` to the right of its direction."""
    (ax, ay), (bx, by) = segment
    length = math.dist(segment[0], segment[1])
    if length < 1e-9 or offset <= 0.0:
        return segment
    nx, ny = (by - ay) / length, -(bx - ax) / length  # the right normal
    return (ax + offset * nx, ay + offset * ny), (bx + offset * nx, by + offset * ny)


def agv_coming(position: Point, segment, radius: float, agvs, reach: float = REACH) -> bool:
    """Whether an AGV (rows [x, y, vx, vy, r]) within ``reach`` ahead along the route's
    ``segment``, or alongside until ``PASSED`` behind, comes head-on (moving more than
    ``HEAD_ON`` off the segment's direction) on a line that passes the route closer than
    ``GAP``. AGVs crossing at an aisle's end, followed, or already in a lane of their own
    do not count: shifting for them only bent the way (the warehouses' main aisles; two
    AGVs in the lanes of a 2 m corridor wove towards each other as the shift came and
    went). The route's direction, not the body's, decides: a body turned by a few
    degrees moved an AGV 8 m ahead by half a metre across."""
    (ax, ay), (bx, by) = segment
    length = math.dist(segment[0], segment[1])
    if agvs is None or not len(agvs) or length < 1e-9:
        return False
    hx, hy = (bx - ax) / length, (by - ay) / length
    agvs = np.ascontiguousarray(agvs, dtype=float)
    px, py = float(position[0]), float(position[1])
    return _coming(agvs, px, py, float(ax), float(ay), float(hx), float(hy), radius, reach)


_COS_HEAD_ON = math.cos(HEAD_ON)


@numba.njit(cache=True)
def _coming(agvs, px, py, ax, ay, hx, hy, radius, reach):
    """``agv_coming``'s test of each AGV, compiled (it runs every control cycle)."""
    for i in range(agvs.shape[0]):
        x, y, vx, vy, r = agvs[i, 0], agvs[i, 1], agvs[i, 2], agvs[i, 3], agvs[i, 4]
        along = (x - px) * hx + (y - py) * hy
        across = abs((y - ay) * hx - (x - ax) * hy)
        their_speed = np.hypot(vx, vy)
        against = vx * hx + vy * hy < _COS_HEAD_ON * their_speed
        coming = their_speed > 1e-3 and against and along > -PASSED and along < reach
        if coming and across < radius + r + GAP:
            return True
    return False
