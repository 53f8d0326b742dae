"""Eq. (10)'s clearance term, dist; on the final approach, nearness to the target instead."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


@dataclass(frozen=True)
class Clearance:
    """The trajectory's least clearance, capped at the vehicle's ``clearance_cap`` (more room
    than that buys nothing). With the cycle's ``approach`` (the final approach: goals in
    docks and pockets have little clearance) the nearness of the end to the target,
    cap - min(distance, cap), replaces it. Weight: the vehicle's ``beta`` (Table 1)."""

    name: str = "clearance"
    uses_route_offsets = False

    def weight_in(self, config: DwaConfig) -> float:
        return config.beta

    def applies(self, cycle: Cycle) -> bool:
        return True

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        c = candidates
        tx, ty = float(cycle.target[0]), float(cycle.target[1])
        cap = cycle.config.clearance_cap
        return room(c.clearance, c.end_x, c.end_y, tx, ty, cycle.approach, cap)


@numba.njit(cache=True)
def room(clearance, end_x, end_y, target_x, target_y, approach, cap):
    """(n,) ``clearance`` capped at ``cap``, or with ``approach`` the end points' nearness to
    the target."""
    out = np.empty(clearance.size)
    for i in range(clearance.size):
        if approach:
            out[i] = cap - min(np.hypot(end_x[i] - target_x, end_y[i] - target_y), cap)
        else:
            out[i] = clearance[i]
        out[i] = min(out[i], cap)
    return out
