"""The filters: which of a cycle's samples DWA may drive, each a named object.

A filter narrows the boolean mask over the cycle's ``Samples`` (``narrow(mask, samples,
cycle) -> mask``); a profile (``planner.local.behaviour``) lists its filters, applied in
order. What is left is scored by the critics; when nothing is, the profile's fallback
drives.

- ``Admissible``: Eq. (7) plus no contact (the paper).
- ``NoRetreat``: while another AGV can lower a clearance, no driving off the target
  (``planner.local.no_retreat``).
- ``YieldEarly``: keep to the samples that leave the AGV off a walker's way
  (``planner.local.yielding``).
- ``ArrivalSpeed``: towards the place it stops at, no sample too fast to brake to rest
  there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from planner.core.physics import braking_speed
from planner.local.cycle import Cycle
from planner.local.no_retreat import ahead_on_route, retreating
from planner.local.refuge import REFUGE_SLACK, refuge
from planner.local.samples import Samples
from planner.local.yielding import agvs_of, contact_later, yield_horizon

_EPS = 1e-9


class Filter(Protocol):
    """Narrows the mask of a cycle's samples DWA may drive."""

    name: str

    def narrow(self, mask: np.ndarray, samples: Samples, cycle: Cycle) -> np.ndarray:
        """``mask`` without the samples this filter drops."""
        ...


@dataclass(frozen=True)
class Admissible:
    """Eq. (7) plus no contact: the AGV can brake to zero within the trajectory's clearance
    (Fox et al.'s minimum over the trajectory; the paper says "from its end", the minimum
    is the safe reading). The linear speed is bounded by the samples' ``room`` (the lane's
    braking room along the route, else the clearance), the turn rate by the clearance
    (``planner.local.admissible``)."""

    name: str = "admissible"

    def narrow(self, mask: np.ndarray, samples: Samples, cycle: Cycle) -> np.ndarray:
        return mask & samples.admissible  # computed with the samples, in their compiled call


@dataclass(frozen=True)
class NoRetreat:
    """While another AGV (a disc that is no walker) can lower a sample's clearance, the
    samples that drive away from where the route goes on are dropped."""

    name: str = "no_retreat"

    def narrow(self, mask: np.ndarray, samples: Samples, cycle: Cycle) -> np.ndarray:
        if not len(agvs_of(samples.lowering, cycle.walkers)):
            return mask
        ahead = ahead_on_route(cycle.pose, cycle.target, cycle.segment)
        return mask & ~retreating(cycle.pose, samples.xs[:, -1], samples.ys[:, -1], ahead)


@dataclass(frozen=True)
class YieldEarly:
    """The samples whose end point no walker reaches before the yield horizon. When no
    admissible one is such: those that end nearest the refuge (``planner.local.refuge``),
    the nearest place off the walkers' way the AGV reaches first; with none, those a walker
    reaches latest, within a control cycle: the AGV backs off along the walker's way rather
    than driving on into a walker it can no longer avoid."""

    name: str = "yield_early"

    def narrow(self, mask: np.ndarray, samples: Samples, cycle: Cycle) -> np.ndarray:
        if cycle.walkers is None or not len(cycle.walkers) or not mask.any():
            return mask
        cfg, command = cycle.config, cycle.command
        walkers = np.asarray(cycle.walkers, dtype=float).reshape(-1, 5)
        speed = math.hypot(command[0], command[1])
        end_x, end_y = samples.xs[:, -1], samples.ys[:, -1]
        contact = contact_later(cfg, end_x, end_y, walkers, speed, cycle.route, cycle.came_by)
        latest = contact[mask].max()
        if math.isinf(latest):
            return mask & np.isinf(contact)
        horizon = yield_horizon(cfg, speed, float(walkers[:, 4].max()))
        place = refuge(
            cfg, cycle.field, cycle.pose[:2], speed, walkers, horizon, cycle.route, cycle.came_by
        )
        if place is None:
            return mask & (contact >= latest - cfg.dt)
        near = np.hypot(end_x - place[0], end_y - place[1])
        return mask & (near <= near[mask].min() + REFUGE_SLACK)


@dataclass(frozen=True)
class ArrivalSpeed:
    """Towards the place the AGV stops at (``stop``), the samples too fast to brake to
    rest there, √(2 a d), are dropped, the hardest deceleration the window has always
    kept: a 3 s rollout's end lies past a nearby target, and plain DWA circles it."""

    name: str = "arrival_speed"

    def narrow(self, mask: np.ndarray, samples: Samples, cycle: Cycle) -> np.ndarray:
        if not cycle.stop:
            return mask
        commands = samples.commands
        speed = np.hypot(commands[:, 0], commands[:, 1])
        limit = max(braking_speed(cycle.distance, cycle.config.max_accel), float(speed.min()))
        return mask & (speed <= limit + _EPS)
