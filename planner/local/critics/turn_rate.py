"""The default profile's turn-rate term: omega changes only as much as the score needs."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle
from planner.local.yielding import walker_coming


@dataclass(frozen=True)
class SteadyTurn:
    """alpha dt - |omega - the current omega| (a period's largest change, the window's
    reach): of near-equal samples on either side of the current turn rate, the one that
    changes it least, so omega follows the route's turns instead of swinging from one
    side to the other. Its spread over the window is its whole range, where the speed
    and facing terms differ by a few per cent between neighbours: a small weight does.

    Comfort yields to getting out of the way: not while a walker is coming
    (``walker_coming``, as the steady choice stops speeding up then). An AGV let a
    walker by from a bay no more: held to its turn rate near zero, it turned away from
    the bay, was caught in the lane and pushed to its end. Weight: ``weight``, the
    profile's."""

    weight: float
    name: str = "steady_turn"
    uses_route_offsets = False

    def weight_in(self, config: DwaConfig) -> float:
        return self.weight

    def applies(self, cycle: Cycle) -> bool:
        return not walker_coming(cycle.pose, cycle.walkers)

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        cfg = cycle.config
        return steady_turn(candidates.commands, float(cycle.command[2]), cfg.max_alpha * cfg.dt)


@numba.njit(cache=True)
def steady_turn(commands, omega, reach):
    """(n,) ``reach`` - |each command's omega - ``omega``| (at least 0)."""
    out = np.empty(len(commands))
    for i in range(len(commands)):
        out[i] = reach - min(abs(commands[i, 2] - omega), reach)
    return out
