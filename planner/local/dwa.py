"""The dynamic window approach (DWA) for an omnidirectional AGV (Guo et al. 2023, section 3).

State (x, y, theta) in the world frame; command (vx, vy, omega) in the body
frame, moved by the motion model Eq. (4). Units are SI throughout: metres,
seconds, radians (so 20 deg/s is ``math.radians(20)``).

One control cycle (``DwaPlanner.plan``) reads top-down, each step a part of its own:

1. Samples (``planner.local.samples``): the window of Eqs. 5, 6 (``planner.local.window``),
   every sample rolled out for ``predict_time`` (``planner.local.rollout``), each
   trajectory's least clearance to the map and to moving discs predicted at constant
   velocity (``planner.local.clearance``), in one compiled call.
2. Filters (``planner.local.filters``): the profile's, in order; Eq. (7) first.
3. Nothing left: the profile's fallback (``planner.local.fallback``): the paper brakes.
4. Critics (``planner.local.critics``) score the candidates left; the choice
   (``planner.local.choice``) normalises each critic's scores by their sum, weighs and
   adds them (Eq. 10: G = alpha xhead + beta dist + gamma vel, plus the profile's own
   terms) and takes the first best, or with the profile's steady choice the near-best
   that changes the acceleration least.

Which critics and filters run, and with which weights, is the profile
(``planner.local.behaviour``): ``paper`` is the paper's DWA; ``default`` adds its own
critics, filters, the lane's braking room and the evasive fallback.

Beyond the paper, for arriving (at 0.2 m/s² an AGV at 2 m/s needs 10 m to
stop, and a 3 s rollout's end lies past a nearby target, so plain DWA circles
its goal): ``plan(..., reach=r)`` gives full xhead to a trajectory that comes
within r of the target (its end heading no longer says anything), and
``stop=True`` drops the samples too fast to brake to zero at the target,
sqrt(2 a_max d), while always keeping the hardest deceleration the window has.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from planner.core.motion import Command, Pose, wrap_angle
from planner.local.behaviour import PAPER_BEHAVIOUR, LocalBehaviour
from planner.local.candidates import Candidates
from planner.local.choice import choose
from planner.local.clearance import lower_by_discs, static_clearance
from planner.local.config import DwaConfig
from planner.local.cycle import Cycle
from planner.local.evasion import contact_times
from planner.local.rollout import rollout
from planner.local.samples import Samples
from planner.maps.distance_field import DistanceField


@dataclass(frozen=True)
class DwaResult:
    """The outcome of one control cycle.

    ``trajectory`` (K x 3) holds the predicted poses after each of the K
    rollout steps of the chosen command (for the fallback's command when
    nothing is admissible).
    """

    command: Command
    trajectory: np.ndarray
    samples: int
    admissible_samples: int

    @property
    def admissible(self) -> bool:
        """False when no sample was admissible and the command is the fallback's."""
        return self.admissible_samples > 0


class DwaPlanner:
    """DWA over a static DistanceField (assignable: temporary obstacles become known)."""

    def __init__(
        self,
        config: DwaConfig,
        distance_field: DistanceField,
        behaviour: LocalBehaviour = PAPER_BEHAVIOUR,
    ):
        self.config = config
        self.distance_field = distance_field
        self.behaviour = behaviour

    def plan(
        self,
        pose: Pose,
        command: Command,
        target_xy: tuple[float, float],
        moving: np.ndarray | None = None,
        *,
        reach: float = 0.0,
        stop: bool = False,
        previous: Command | None = None,
        approach: bool = False,
        segment: tuple[tuple[float, float], tuple[float, float]] | None = None,
        route: list[tuple[float, float]] | None = None,
        came_by: Sequence[tuple[float, float]] = (),
        walkers: np.ndarray | None = None,
        lane_room: float | None = None,
    ) -> DwaResult:
        """One control cycle from ``pose`` with current ``command`` towards the local target.

        ``moving``: (M, 5) discs [x, y, vx, vy, radius] in the world frame (other
        AGVs, moving obstacles), or None. ``reach``: a trajectory within this
        distance of the target scores full xhead. ``stop``: brake to arrive at
        the target at rest (the final goal). ``previous``: the command of the
        cycle before (for the steady choice; None: the current one).
        ``approach``: the final approach, where the clearance critic scores
        nearness to the target (goals in docks and pockets have little clearance).
        ``segment``: the global route's segment to the target, for the route critic.
        ``route``: the remaining global route from the AGV, along which head-on
        ``walkers`` (rows as ``moving``: the discs that do not avoid the AGV) are
        predicted, to get out of their way early (``planner.local.yielding``), and on along
        ``came_by``: the way the AGV came, from it back.
        ``lane_room``: the braking room the route ahead grants (``planner.local.lane_speed``);
        with a ``segment``, the samples that follow it are bounded by the room to brake
        along their path instead of by their clearance (None: Eq. 7 for all).
        """
        discs = np.zeros((0, 5)) if moving is None else np.asarray(moving, dtype=float)
        cycle = Cycle(
            self.config, self.distance_field, pose, command, target_xy,
            np.ascontiguousarray(discs.reshape(-1, 5)), reach, stop,
            command if previous is None else previous, approach, segment, route, came_by,
            walkers, lane_room, math.dist(pose[:2], target_xy) if stop else 0.0,
        )  # fmt: skip
        profile = self.behaviour
        samples = Samples.of(cycle, profile.wants_route_offsets)
        mask = np.ones(len(samples.commands), dtype=bool)
        for kept in profile.filters:
            mask = kept.narrow(mask, samples, cycle)
        ok = np.flatnonzero(mask)
        if ok.size == 0:
            chosen, path = profile.fallback.command(samples, cycle)
            return DwaResult(chosen, _poses(path), len(samples.commands), 0)
        best = choose(Candidates.of(ok, samples), profile.critics, cycle, profile.steady_tolerance)
        chosen = tuple(samples.commands[best].tolist())
        path = (samples.xs[best], samples.ys[best], samples.thetas[best])
        return DwaResult(chosen, _poses(path), len(samples.commands), len(ok))

    def clearance_along(self, path: np.ndarray, moving: np.ndarray | None) -> float:
        """The least clearance of the (K, 3) ``path`` (poses at steps 1..K, as a rollout's)
        to the map and to the moving discs, as a DWA sample's is computed."""
        cfg, field = self.config, self.distance_field
        xs, ys = np.ascontiguousarray(path[None, :, 0]), np.ascontiguousarray(path[None, :, 1])
        clearance = static_clearance(
            xs, ys, field.samples, 1.0 / field.spacing, cfg.radius, *field.origin
        )
        if moving is not None and len(moving):
            discs = np.ascontiguousarray(np.asarray(moving, dtype=float).reshape(-1, 5))
            clearance = lower_by_discs(xs, ys, clearance, discs, cfg.dt, cfg.radius)
        return float(clearance[0])

    def threatened(self, pose: Pose, moving: np.ndarray | None) -> bool:
        """True when standing still at ``pose`` a moving disc reaches the AGV within the horizon."""
        if moving is None or not len(moving):
            return False
        cfg, field = self.config, self.distance_field
        xs, ys, _ = rollout(pose, np.zeros((1, 3)), cfg.dt, cfg.steps)
        discs = np.ascontiguousarray(np.asarray(moving, dtype=float).reshape(-1, 5))
        _, moving_first, _ = contact_times(
            xs, ys, field.samples, 1.0 / field.spacing, discs, cfg.dt, cfg.radius, *field.origin
        )
        return bool(np.isfinite(moving_first[0]))


def _poses(path) -> np.ndarray:
    """(K, 3) poses from x, y, theta rows, theta wrapped to [-pi, pi)."""
    out = np.empty((len(path[0]), 3))  # np.column_stack's, without its checks
    out[:, 0], out[:, 1], out[:, 2] = path
    out[:, 2] = wrap_angle(out[:, 2])
    return out
