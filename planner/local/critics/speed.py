"""Eq. (10)'s velocity term, vel: faster is better."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


@dataclass(frozen=True)
class Speed:
    """The linear speed |(vx, vy)|. Weight: the vehicle's ``gamma`` (Table 1)."""

    name: str = "speed"
    uses_route_offsets = False

    def weight_in(self, config: DwaConfig) -> float:
        return config.gamma

    def applies(self, cycle: Cycle) -> bool:
        return True

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        return candidates.speeds
