"""A control cycle's samples: the window's commands, their rollouts and their clearance.

``Samples.of`` computes them in one compiled call (``roll_out_window``): the window
(``planner.local.window``), the rollout (``planner.local.rollout``), each trajectory's least
clearance to the map and to the moving discs (``planner.local.clearance``), how far each
strays from the route, and the room that bounds each sample's linear speed in Eq. (7): its
clearance, or along the route the lane's braking room (``planner.local.lane_speed``). The
dozen kernels and numpy calls this is, called one by one from Python, cost an AGV process
(whose caches are cold at every tick with 50 of them on 2 cores) more than their
arithmetic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from planner.local.admissible import admissible
from planner.local.clearance import discs_by_gap, lower_by_discs, static_clearance
from planner.local.cycle import Cycle
from planner.local.lane_speed import (
    ROUTE_TOLERANCE,
    braking_room,
    node_room,
    on_route_room,
    stop_room,
)
from planner.local.rollout import largest_offsets, largest_square_distance, rollout_turns
from planner.local.window import window_samples

_NO_SEGMENT = ((0.0, 0.0), (0.0, 0.0))  # the kernel's segment when there is none


@dataclass(slots=True)
class Samples:
    """One cycle's samples, each row of every array one sample (N of them).

    ``commands`` (N, 3); ``xs``, ``ys``, ``thetas`` (N, K) the poses after steps 1..K;
    ``walls`` the least clearance to the map, ``clearance`` with the moving discs too;
    ``room`` what bounds the linear speed (Eq. 7's clearance, or the lane's braking room);
    ``admissible`` Eq. (7)'s mask (``planner.local.admissible``: the ``Admissible`` filter's);
    ``offsets`` how far each strays from the route segment (None: not asked). Of the
    discs (sorted nearest first), ``in_reach`` are those in reach of the fastest sample
    the lane admits (the fallback looks at them) and ``lowering`` those that lower some
    sample's clearance below ``static_best``, the best clearance to the map; ``span`` is
    how far the trajectories reach.
    """

    commands: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    thetas: np.ndarray
    walls: np.ndarray
    clearance: np.ndarray
    room: np.ndarray
    admissible: np.ndarray
    offsets: np.ndarray | None
    in_reach: np.ndarray
    lowering: np.ndarray
    span: float
    static_best: float

    @classmethod
    def of(cls, cycle: Cycle, wants_offsets: bool) -> Samples:
        """The samples of ``cycle``; ``wants_offsets``: a critic scores the route offsets
        (the lane always needs them)."""
        cfg, field, pose, command = cycle.config, cycle.field, cycle.pose, cycle.command
        lane = cycle.lane
        offsets_wanted = cycle.segment is not None and (lane or wants_offsets)
        room, behind = 0.0, 0.0
        if lane:
            # never less than the hardest braking from the current command needs: a replan
            # that turns the route close ahead of a fast AGV leaves it braking along the
            # route, not with nothing admissible and the fallback's choice
            hardest = braking_room(math.hypot(command[0], command[1]), cfg.max_accel, cfg.dt)
            room = float(max(cycle.lane_room, hardest))
            if cycle.stop:  # the room before what stands behind the place it stops at
                behind = node_room(field, cfg.radius, cycle.target)
        (ax, ay), (bx, by) = _NO_SEGMENT if cycle.segment is None else cycle.segment
        vx, vy, omega = (float(v) for v in command)
        out = roll_out_window(
            float(pose[0]), float(pose[1]), float(pose[2]), vx, vy, omega,
            cfg.min_vx, cfg.max_speed, cfg.max_omega, cfg.max_accel * cfg.dt,
            cfg.max_alpha * cfg.dt, cfg.v_resolution, cfg.omega_resolution, cfg.dt, cfg.steps,
            cfg.horizon_s, cfg.radius, cfg.max_accel, cfg.max_alpha, field.samples,
            1.0 / field.spacing, *field.origin,
            cycle.discs, lane, room, lane and cycle.stop, cycle.distance, behind,
            offsets_wanted, float(ax), float(ay), float(bx - ax), float(by - ay),
        )  # fmt: skip
        commands, paths, walls, clearance, linear, eq7, offsets, in_reach, lowering = out[:9]
        return cls(
            commands, paths[0], paths[1], paths[2], walls, clearance, linear, eq7,
            offsets if offsets_wanted else None, in_reach, lowering, *out[9:],
        )  # fmt: skip


@numba.njit(cache=True)
def roll_out_window(
    x, y, theta, vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step,
    dt, steps, horizon_s, radius, max_accel, max_alpha, samples, inv_spacing, ox, oy, discs,
    lane, room, stopping, distance, behind, offsets_wanted, ax, ay, dx, dy,
):  # fmt: skip
    """``Samples.of``'s arrays in one compiled call: the window's commands, their
    trajectories (3, N, K), each one's least clearance to the map (``walls``) and with the
    moving ``discs`` (sorted nearest first, as ``relevant_discs``), the room bounding its
    linear speed, Eq. (7)'s admissible mask, the route offsets (when ``offsets_wanted``;
    else empty), the discs in reach of the fastest sample the lane admits, those that can
    lower a clearance below the best static one, the samples' reach and that best
    clearance.

    With a ``lane`` (``planner.local.lane_speed``) the linear speed of the samples that follow
    the route segment (from (ax, ay) along (dx, dy)) is bounded by their room to brake
    along it before the moving discs instead of by their clearance: the path's length
    over the horizon, the route's ``room`` and, when ``stopping`` ``distance`` away,
    the room before what stands ``behind`` that place. The others keep Eq. (7)'s
    clearance, which the lane only ever relaxes.
    """
    commands, which, omegas = window_samples(
        vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step
    )
    paths = rollout_turns(x, y, theta, commands, omegas, which, dt, steps)
    xs, ys = paths[0], paths[1]
    walls = static_clearance(xs, ys, samples, inv_spacing, radius, ox, oy)
    static_best = walls.max()
    bound = static_best
    braking = np.empty(0)
    if lane:
        speed = np.hypot(commands[:, 0], commands[:, 1])
        braking = np.minimum(speed * horizon_s, room)
        if stopping:
            braking = np.minimum(braking, stop_room(distance, behind, speed, horizon_s))
        bound = max(static_best, braking.max())
    span = math.sqrt(largest_square_distance(xs, ys, x, y))
    by_gap, least = discs_by_gap(discs, x, y, span, radius, horizon_s)
    reached = by_gap[least < bound]
    lowering = by_gap[least < static_best]
    clearance = walls
    if len(lowering):
        clearance = lower_by_discs(xs, ys, walls, lowering, dt, radius)
    offsets = np.empty(0)
    if offsets_wanted:
        offsets = largest_offsets(xs, ys, ax, ay, dx, dy)
    linear = clearance
    if lane:
        # only the samples that follow the route get the room (0: the discs' kernel
        # skips the others); the gap to moving discs bounds it too (Eq. 7 for them)
        braking = on_route_room(offsets, braking, clearance, ROUTE_TOLERANCE)
        near = by_gap[least < braking.max()]
        if len(near):
            braking = lower_by_discs(xs, ys, braking, near, dt, radius)
        linear = np.maximum(braking, clearance)
    mask = admissible(commands, clearance, linear, max_accel, max_alpha)
    return (
        commands, paths, walls, clearance, linear, mask, offsets, reached, lowering, span,
        static_best,
    )  # fmt: skip
