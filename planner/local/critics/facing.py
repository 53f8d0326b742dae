"""The default profile's facing term: the body faces its direction of travel."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


@dataclass(frozen=True)
class Facing:
    """pi - the angle between the body heading and the direction of travel, atan2(vy, vx)
    (pi standing): a body that faces its travel has its sensors and its narrow side
    ahead. Weight: ``weight``, the profile's."""

    weight: float
    name: str = "facing"
    uses_route_offsets = False

    def weight_in(self, config: DwaConfig) -> float:
        return self.weight

    def applies(self, cycle: Cycle) -> bool:
        return True

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        return facing(candidates.travel)


@numba.njit(cache=True)
def facing(travel):
    """(n,) pi - |travel|, ``travel`` the directions of travel off the body heading."""
    out = np.empty(travel.size)
    for i in range(travel.size):
        out[i] = np.pi - abs(travel[i])
    return out
