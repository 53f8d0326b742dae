"""Never drive away from the target to make room for another AGV (default profile).

DWA treats another AGV as a disc moving on at its velocity. Against a disc
coming its way, the samples that keep the most clearance over the horizon are
those that run ahead of it: an AGV met head-on in a 2 m aisle turned and drove
off with the other behind it, circled back, met the next one and circled again
(in a crowded warehouse an AGV circled in a cross aisle for 40 s, its path
crossing itself 12 times); in a corridor an AGV backed out metres ahead of
an oncoming pair. The other AGV plans too: one that brakes or steps aside is
predictable to it, one that flees keeps it coming. So while another AGV can
lower a sample's clearance, the samples whose displacement over the horizon
points away from the target by more than ``RETREAT_ANGLE`` are dropped; with
nothing else admissible the AGV brakes (as DWA does when only AGVs are in reach,
``planner.local.fallback.Evade``). Walkers do not plan: from them the AGV still backs
off (``planner.local.yielding``).

"Away" is measured from where the route goes on (``ahead_on_route``), not from the
target as the crow flies: an AGV pushed off its route into a side aisle, with its
target beyond a shelf, otherwise counted driving on down that aisle as a step
aside (an AGV pushed into a side aisle fled 3 m down it, came back and crossed
its own path five times).
"""

from __future__ import annotations

import math

import numba
import numpy as np

RETREAT_ANGLE = math.radians(100.0)
"""rad: a displacement further than this from the direction to the target drives away
from it (a step straight aside, 90 degrees, is not a retreat)."""

STANDING = 0.1
"""m: a displacement over the horizon shorter than this (braking, turning on the spot) is
no retreat."""


LOOKAHEAD = 3.0
"""m: how far along the route segment, beyond the AGV's projection on it, "ahead" lies
(long enough that an AGV stepping aside by up to half an aisle still counts a step
straight aside as no retreat)."""


def ahead_on_route(pose, target, segment) -> tuple[float, float]:
    """The point ``LOOKAHEAD`` beyond ``pose``'s projection on the route ``segment``
    (its start, its end ``target``), clamped to the segment; the target itself
    without a segment."""
    if segment is None:
        return target
    (ax, ay), (bx, by) = segment
    dx, dy = bx - ax, by - ay
    length = math.hypot(dx, dy)
    if length < 1e-9:
        return target
    along = ((pose[0] - ax) * dx + (pose[1] - ay) * dy) / length
    s = min(max(along + LOOKAHEAD, 0.0), length) / length
    return (ax + s * dx, ay + s * dy)


def retreating(pose, end_x: np.ndarray, end_y: np.ndarray, target) -> np.ndarray:
    """(N,) whether each sample, from ``pose`` to its end point (``end_x``, ``end_y``),
    drives away from ``target``."""
    x, y = float(pose[0]), float(pose[1])
    tx, ty = target[0] - x, target[1] - y
    end_x, end_y = np.ascontiguousarray(end_x, float), np.ascontiguousarray(end_y, float)
    return _away(end_x, end_y, x, y, tx, ty, math.hypot(tx, ty))


_COS_RETREAT = math.cos(RETREAT_ANGLE)


@numba.njit(cache=True)
def _away(end_x, end_y, x, y, tx, ty, target_distance):
    """``retreating``, compiled (it runs every control cycle on every sample)."""
    out = np.empty(end_x.size, dtype=np.bool_)
    for i in range(end_x.size):
        dx, dy = end_x[i] - x, end_y[i] - y
        shift = np.hypot(dx, dy)
        out[i] = shift > STANDING and dx * tx + dy * ty < _COS_RETREAT * shift * target_distance
    return out
