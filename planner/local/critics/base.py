"""The one interface every critic has (``planner.local.critics`` lists them)."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from planner.local.candidates import Candidates
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle


class Critic(Protocol):
    """A term of DWA's score: it scores every candidate at once, higher is better.

    The choice (``planner.local.choice``) divides each critic's scores by their sum over
    the candidates and adds them up, each times its ``weight_in`` the vehicle's config;
    a critic that does not ``apply`` to a cycle (it lacks what it scores) is left out of
    that cycle's sum.
    """

    name: str
    uses_route_offsets: bool  # the samples must carry their route offsets

    def weight_in(self, config: DwaConfig) -> float:
        """The critic's weight for a vehicle with ``config``."""
        ...

    def applies(self, cycle: Cycle) -> bool:
        """Whether the critic has something to score in ``cycle``."""
        ...

    def score(self, candidates: Candidates, cycle: Cycle) -> np.ndarray:
        """(n,) each candidate's score, in ``candidates``' order."""
        ...
