"""What DWA drives when no sample is admissible: the profile's fallback.

``Brake`` is the paper's: every component towards zero as hard as the limits allow.
``Evade`` (the default profile) is the evasive fallback of ``planner.local.evasion``
against walls and walkers; when the only moving discs in reach are other AGVs it brakes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planner.core.motion import Command
from planner.local.clearance import relevant_discs
from planner.local.cycle import Cycle
from planner.local.evasion import contact_times, evasive_index, into_wall
from planner.local.rollout import rollout
from planner.local.samples import Samples
from planner.local.window import braking_command


@dataclass(frozen=True)
class Brake:
    """The paper's fallback: brake every command component."""

    name: str = "brake"

    def command(self, samples: Samples, cycle: Cycle) -> tuple[Command, tuple]:
        """The command and its trajectory's (x, y, theta) rows."""
        cfg = cycle.config
        brake = braking_command(cfg, cycle.command)
        path = rollout(cycle.pose, np.array([brake]), cfg.dt, cfg.steps)[:, 0, :]
        return brake, path


@dataclass(frozen=True)
class Evade:
    """The sample that delays contact longest (``evasion.evasive_index``), against walls
    and walkers; braking when only other AGVs are in reach. They plan too: an AGV that
    brakes is predictable to them, one that flees at full speed into a crowded aisle is
    not (in the crowded warehouse cases the collisions were between two AGVs, one of them
    fleeing)."""

    name: str = "evade"

    def command(self, samples: Samples, cycle: Cycle) -> tuple[Command, tuple]:
        """The command and its trajectory's (x, y, theta) rows."""
        if not self._applies(samples, cycle):
            return Brake().command(samples, cycle)
        cfg, field, s = cycle.config, cycle.field, samples
        times = contact_times(
            s.xs, s.ys, field.samples, 1.0 / field.spacing, s.in_reach, cfg.dt, cfg.radius,
            *field.origin,
        )  # fmt: skip
        speeds = np.hypot(s.commands[:, 0], s.commands[:, 1])
        here = field.distance_at_point(cycle.pose[0], cycle.pose[1]) - cfg.radius
        best = evasive_index(*times, into_wall(s.walls, here), speeds, cfg.max_accel, cfg.dt)
        return tuple(s.commands[best].tolist()), (s.xs[best], s.ys[best], s.thetas[best])

    @staticmethod
    def _applies(samples: Samples, cycle: Cycle) -> bool:
        """Against walls (no disc in reach) and walkers, not when the only moving discs in
        reach are AGVs."""
        if not len(samples.in_reach):
            return True
        walkers = cycle.walkers
        if walkers is None or not len(walkers):
            return False
        walkers = np.ascontiguousarray(np.asarray(walkers, dtype=float).reshape(-1, 5))
        bound = samples.static_best
        return len(relevant_discs(cycle.config, cycle.pose, samples.span, walkers, bound)) > 0
