"""The default profile's route term: trajectories that stay on the global route."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


@dataclass(frozen=True)
class OnRoute:
    """cap - each trajectory's largest distance from the route's current segment (capped at
    the vehicle's ``clearance_cap``): the AGV lines up with a narrow passage the route goes
    through before it gets there. Only with a segment to score against. Weight:
    ``weight``, the profile's."""

    weight: float
    name: str = "on_route"
    uses_route_offsets = True  # the samples must carry them

    def weight_in(self, config: DwaConfig) -> float:
        return self.weight

    def applies(self, cycle: Cycle) -> bool:
        return cycle.segment is not None

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        offsets = candidates.samples.offsets[candidates.ok]
        return on_route(offsets, cycle.config.clearance_cap)


@numba.njit(cache=True)
def on_route(offsets, cap):
    """(n,) cap - ``offsets`` (capped at ``cap``)."""
    out = np.empty(offsets.size)
    for i in range(offsets.size):
        out[i] = cap - min(offsets[i], cap)
    return out
