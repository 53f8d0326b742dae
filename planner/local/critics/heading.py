"""Eq. (10)'s heading term, xhead: the direction of travel at the trajectory's end points at
the target."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.core.motion import wrap_angle
from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


@dataclass(frozen=True)
class Heading:
    """pi - |error| between the bearing from the trajectory's end to the target and the
    direction of travel (body heading plus atan2(vy, vx)): that direction, not the body
    heading, is what an omnidirectional AGV must point at the target. A trajectory that
    comes within the cycle's ``reach`` of the target scores full xhead (its end heading
    says nothing any more). Weight: the vehicle's ``alpha`` (Table 1)."""

    name: str = "heading"
    uses_route_offsets = False

    def weight_in(self, config: DwaConfig) -> float:
        return config.alpha

    def applies(self, cycle: Cycle) -> bool:
        return True

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        c, s = candidates, candidates.samples
        tx, ty = float(cycle.target[0]), float(cycle.target[1])
        head = xhead(c.travel, c.end_x, c.end_y, c.end_theta, tx, ty)
        if cycle.reach > 0:
            passing(head, c.ok, s.xs, s.ys, tx, ty, float(cycle.reach))
        return head


@numba.njit(cache=True)
def xhead(travel, end_x, end_y, end_theta, target_x, target_y):
    """(n,) pi - |error| between the bearing from each end point to the target and the
    direction of travel (``travel`` off the end heading)."""
    out = np.empty(travel.size)
    for i in range(travel.size):
        bearing = np.arctan2(target_y - end_y[i], target_x - end_x[i])
        out[i] = np.pi - abs(wrap_angle(bearing - (end_theta[i] + travel[i])))
    return out


@numba.njit(cache=True)
def passing(head, ok, xs, ys, target_x, target_y, reach):
    """Full xhead (pi, in ``head``) for the trajectories ``ok`` of ``xs``, ``ys`` that come
    within ``reach`` of the target."""
    for i in range(ok.size):
        k, near = ok[i], np.inf
        for step in range(xs.shape[1]):
            gap_x, gap_y = xs[k, step] - target_x, ys[k, step] - target_y
            near = min(near, gap_x * gap_x + gap_y * gap_y)
        if near <= reach * reach:
            head[i] = np.pi
