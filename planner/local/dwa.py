"""The dynamic window approach (DWA) for an omnidirectional AGV (Guo et al. 2023, section 3).

State (x, y, theta) in the world frame; command (vx, vy, omega) in the body
frame, moved by the motion model Eq. (4). Units are SI throughout: metres,
seconds, radians (so 20 deg/s is ``math.radians(20)``).

One control cycle (``DwaPlanner.plan``):

1. Window (Eqs. 5, 6): per axis, the speed limits intersected with what one
   control period of acceleration reaches from the current command, sampled
   on the resolution grid centred on the current command (so the current
   command is always a sample), then the samples faster than ``max_speed``
   in |(vx, vy)| are dropped.
2. Rollout: every sample held for ``predict_time``, all samples and steps
   as arrays; positions are ``vx * C(omega) - vy * S(omega)`` with C, S
   cumulative sums of the heading's cosine and sine, so trigonometry is only
   evaluated per distinct omega.
3. Clearance (a numba kernel): the minimum over the predicted steps of the
   distance to static obstacles (the DistanceField) and to moving discs
   predicted at constant velocity, minus the AGV radius.
4. Admissible (Eq. 7): clearance > 0, speed <= sqrt(2 clearance a_max) and
   |omega| <= sqrt(2 clearance alpha_max), clearance being the trajectory's
   minimum (the paper says "from the end of the trajectory"; the minimum is
   Fox et al.'s definition and the safe one).
5. Score (Eq. 10) over the admissible samples (``planner.local.scores``, compiled):
   G = alpha xhead + beta dist + gamma vel, each term divided by its sum over
   them; xhead = pi - |heading error| at the trajectory's end towards the
   local target, the heading being the direction of travel (body heading plus
   atan2(vy, vx); the body heading when standing) since an omnidirectional
   AGV need not face where it goes, dist = clearance capped at ``clearance_cap``, vel = speed
   |(vx, vy)|. The first maximum wins.

When nothing is admissible the command brakes every component towards zero
as hard as the acceleration limits allow (the paper), or, with the default
profile's ``LocalBehaviour.evade``, is the evasive fallback of
``planner/evasion.py``.

The default profile adds a term to Eq. (10), normalised like the others:
``facing`` (pi - |atan2(vy, vx)|: the body faces its direction of travel) and
``on_route`` (the trajectory stays near the global route's current segment);
and it picks, among the samples scoring near the best, the one that changes
the last cycle's acceleration least (``steady_choice``), so the chosen
acceleration stops flipping every cycle. Along the route it bounds the linear
speed by the room to brake along the path rather than the clearance beside it
(``planner.local.lane_speed``). While another AGV can lower a sample's clearance, the
samples that drive away from the target are dropped (``planner.local.no_retreat``).

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

import numba
import numpy as np

from planner.core.motion import Command, Pose, wrap_angle
from planner.local.behaviour import PAPER_BEHAVIOUR, LocalBehaviour
from planner.local.config import DwaConfig
from planner.local.evasion import contact_times, evasive_index, into_wall
from planner.local.lane_speed import ROUTE_TOLERANCE, braking_room, node_room, stop_room
from planner.local.no_retreat import ahead_on_route, retreating
from planner.local.scores import choose
from planner.local.yielding import (
    YIELD_SLACK,
    agvs_of,
    parked_clearance,
    walker_coming,
    yield_horizon,
)
from planner.maps.distance_field import DistanceField, lookup

_EPS = 1e-9
_NO_OFFSETS = np.zeros(0)  # ``choose``'s offsets when the route term is off
_NO_SEGMENT = ((0.0, 0.0), (0.0, 0.0))  # ``_evaluate``'s segment when there is none


@dataclass(frozen=True)
class DwaResult:
    """The outcome of one control cycle.

    ``trajectory`` (K x 3) holds the predicted poses after each of the K
    rollout steps of the chosen command (for the braking command when
    nothing is admissible).
    """

    command: Command
    trajectory: np.ndarray
    samples: int
    admissible_samples: int

    @property
    def admissible(self) -> bool:
        """False when no sample was admissible and the command is the braking fallback."""
        return self.admissible_samples > 0


@numba.njit(cache=True)
def window_axis(current: float, lowest: float, highest: float, reach: float, step: float):
    """One command axis: [lowest, highest] ∩ [current ± reach], on a grid through ``current``.

    A ``current`` on the resolution grid (as every command DWA chose from rest
    is) snaps to it, so that stopping is exactly 0 and the samples do not
    drift with rounding. If ``current`` lies outside the limits by more than
    ``reach``, the only sample is the value one period closer to them.
    """
    lo, hi = max(lowest, current - reach), min(highest, current + reach)
    if lo > hi + _EPS:
        return np.array([current - reach if current > highest else current + reach])
    centre = min(max(current, lo), hi)
    offsets = np.arange(
        -math.floor((centre - lo) / step + _EPS), math.floor((hi - centre) / step + _EPS) + 1
    )
    nearest = round(centre / step)
    if abs(centre / step - nearest) < 1e-6:  # on the resolution grid: no rounding drift, exact 0
        return (nearest + offsets) * step
    return centre + step * offsets


def dynamic_window(config: DwaConfig, command: Command) -> np.ndarray:
    """(N, 3) sampled commands of the window (Eqs. 5, 6), speed-limited in |(vx, vy)|."""
    return window(config, command).commands


@dataclass(frozen=True)
class Window:
    """The window's samples, with the distinct turn rates they hold (ascending) and each
    sample's index into them: what ``rollout`` would otherwise find with ``np.unique``."""

    commands: np.ndarray
    which: np.ndarray
    omegas: np.ndarray


def window(config: DwaConfig, command: Command) -> Window:
    """``dynamic_window``'s samples as a ``Window``."""
    vx, vy, omega = (float(v) for v in command)
    dv, dw = config.max_accel * config.dt, config.max_alpha * config.dt
    return Window(
        *_window(
            vx, vy, omega, config.min_vx, config.max_speed, config.max_omega, dv, dw,
            config.v_resolution, config.omega_resolution,
        )
    )  # fmt: skip


@numba.njit(cache=True)
def _window(vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step):
    """``window``'s commands, their turn rates' indices and the turn rates, in one call (four
    from Python cost more than the sampling)."""
    vxs = window_axis(vx, min_vx, max_speed, dv, v_step)
    vys = window_axis(vy, -max_speed, max_speed, dv, v_step)
    omegas = window_axis(omega, -max_omega, max_omega, dw, omega_step)
    commands, which = _window_grid(vxs, vys, omegas, max_speed + _EPS)
    return commands, which, omegas


@numba.njit(cache=True)
def _window_grid(vxs, vys, omegas, fastest):
    """The product of the axes' samples (vx slowest, omega fastest, as ``np.meshgrid``'s
    with ``indexing="ij"``) without those faster than ``fastest`` in |(vx, vy)|, and each
    kept sample's index into ``omegas``. Every turn rate is kept with the same speeds:
    the speed limit drops none of them."""
    kept = 0
    for vx in vxs:
        for vy in vys:
            kept += np.hypot(vx, vy) <= fastest
    commands = np.empty((kept * len(omegas), 3))
    which = np.empty(kept * len(omegas), dtype=np.int64)
    row = 0
    for vx in vxs:
        for vy in vys:
            if np.hypot(vx, vy) <= fastest:
                for w in range(len(omegas)):
                    commands[row, 0], commands[row, 1], commands[row, 2] = vx, vy, omegas[w]
                    which[row] = w
                    row += 1
    return commands, which


def braking_command(config: DwaConfig, command: Command) -> Command:
    """Every component towards zero by at most one period of acceleration."""
    dv, dw = config.max_accel * config.dt, config.max_alpha * config.dt
    vx, vy, omega = command
    return (
        math.copysign(max(abs(vx) - dv, 0.0), vx),
        math.copysign(max(abs(vy) - dv, 0.0), vy),
        math.copysign(max(abs(omega) - dw, 0.0), omega),
    )


def rollout(pose: Pose, commands: np.ndarray, dt: float, steps: int) -> np.ndarray:
    """(3, N, K): x, y and theta after steps 1..K of each command held constant (Eq. 4).
    (A control cycle rolls out the window's samples with their turn rates as ``window``
    found them, in ``_evaluate``: no search.)"""
    x0, y0, theta0 = pose
    omegas, which = np.unique(commands[:, 2], return_inverse=True)
    return _rollout(float(x0), float(y0), float(theta0), commands, omegas, which, dt, steps)


@numba.njit(cache=True)
def _rollout(x0, y0, theta0, commands, omegas, which, dt, steps):
    """``rollout``'s (3, N, K) from each distinct turn rate's headings and the cumulative
    sums of their cosines and sines (in numpy's order, so bit for bit what the array
    expressions gave), without the (N, K) temporaries."""
    headings = np.empty((len(omegas), steps + 1))  # steps 0..K
    cos_sum = np.empty((len(omegas), steps))
    sin_sum = np.empty((len(omegas), steps))
    for w in range(len(omegas)):
        for k in range(steps + 1):
            headings[w, k] = theta0 + omegas[w] * (k * dt)
        # the displacement of step k uses the heading at its start (step k - 1)
        cos_sum[w, 0], sin_sum[w, 0] = np.cos(headings[w, 0]), np.sin(headings[w, 0])
        for k in range(1, steps):
            cos_sum[w, k] = cos_sum[w, k - 1] + np.cos(headings[w, k])
            sin_sum[w, k] = sin_sum[w, k - 1] + np.sin(headings[w, k])
    out = np.empty((3, len(commands), steps))
    for i in range(len(commands)):
        w, vx, vy = which[i], commands[i, 0], commands[i, 1]
        for k in range(steps):
            c, s = cos_sum[w, k] * dt, sin_sum[w, k] * dt
            out[0, i, k] = x0 + vx * c - vy * s
            out[1, i, k] = y0 + vx * s + vy * c
            out[2, i, k] = headings[w, k + 1]
    return out


@numba.njit(cache=True)
def static_clearance(xs, ys, samples, inv_spacing, radius, ox=0.0, oy=0.0):
    """(N,) minimum over steps of the clearance of trajectories ``xs``, ``ys`` (N, K) to
    the static map: the distance field (of a map whose origin is (ox, oy)) minus ``radius``.
    A trajectory stops being evaluated at its first contact (its clearance is then <= 0,
    which is all that matters).
    """
    n_traj, n_steps = xs.shape
    out = np.empty(n_traj)
    for n in range(n_traj):
        worst = np.inf
        for k in range(n_steps):
            worst = min(worst, lookup(samples, inv_spacing, xs[n, k] - ox, ys[n, k] - oy) - radius)
            if worst <= 0.0:
                break
        out[n] = worst
    return out


@numba.njit(cache=True)
def lower_by_discs(xs, ys, clearance, moving, dt, radius):
    """(N,) ``clearance`` (from ``static_clearance``) lowered by moving discs (M, 5) rows
    [x, y, vx, vy, r], each at step k (time (k+1) dt) at constant velocity: centre
    distance minus r minus ``radius``; the minimum of the two is the trajectory's.

    Work is skipped only where it cannot lower the clearance found so far (with 1 nm of
    slack, so the result is exact): a disc whose path's bounding box stays farther from
    the trajectory's bounding box (a disc behind the AGV or beside the fan of samples),
    and the square root of a (step, disc) pair too far apart. As in
    ``static_clearance``, a trajectory stops being evaluated at its first contact.
    """
    n_traj, n_steps = xs.shape
    first, last = dt, n_steps * dt
    boxes = np.empty((moving.shape[0], 4))  # each disc's path: x low, x high, y low, y high
    for m in range(moving.shape[0]):
        for axis in range(2):
            a = moving[m, axis] + moving[m, axis + 2] * first
            b = moving[m, axis] + moving[m, axis + 2] * last
            boxes[m, 2 * axis], boxes[m, 2 * axis + 1] = min(a, b), max(a, b)
    out = np.empty(n_traj)
    for n in range(n_traj):
        worst = clearance[n]
        x_lo, x_hi, y_lo, y_hi = xs[n, 0], xs[n, 0], ys[n, 0], ys[n, 0]
        for k in range(1, n_steps):
            x_lo, x_hi = min(x_lo, xs[n, k]), max(x_hi, xs[n, k])
            y_lo, y_hi = min(y_lo, ys[n, k]), max(y_hi, ys[n, k])
        for m in range(moving.shape[0]):
            if worst <= 0.0:
                break
            reach = worst + moving[m, 4] + radius + 1e-9
            gx = max(0.0, boxes[m, 0] - x_hi, x_lo - boxes[m, 1])
            gy = max(0.0, boxes[m, 2] - y_hi, y_lo - boxes[m, 3])
            if gx * gx + gy * gy >= reach * reach:
                continue
            for k in range(n_steps):
                t = (k + 1) * dt
                dx = xs[n, k] - (moving[m, 0] + moving[m, 2] * t)
                dy = ys[n, k] - (moving[m, 1] + moving[m, 3] * t)
                near = worst + moving[m, 4] + radius + 1e-9
                d2 = dx * dx + dy * dy
                if d2 < near * near:
                    worst = min(worst, math.sqrt(d2) - moving[m, 4] - radius)
                    if worst <= 0.0:
                        break
        out[n] = worst
    return out


def sample_reach(pose: Pose, xs: np.ndarray, ys: np.ndarray) -> float:
    """How far from ``pose`` the samples' trajectories (N, K) reach."""
    return math.sqrt(_largest_square_distance(xs, ys, float(pose[0]), float(pose[1])))


@numba.njit(cache=True)
def _largest_square_distance(xs, ys, x0, y0):
    """The largest (x - x0)² + (y - y0)² over the trajectories, in one pass (numpy's four
    (N, K) temporaries were 5 % of a 40-AGV stress case's planning time); the same
    operations, so the same value."""
    largest = -np.inf
    for n in range(xs.shape[0]):
        for k in range(xs.shape[1]):
            dx, dy = xs[n, k] - x0, ys[n, k] - y0
            largest = max(largest, dx * dx + dy * dy)
    return largest


def relevant_discs(
    config: DwaConfig, pose: Pose, agv_reach: float, discs: np.ndarray, bound: float
) -> np.ndarray:
    """The discs that can lower some trajectory's clearance below ``bound``.

    ``bound`` is the largest static clearance over the samples: a disc that
    cannot come closer than that to any trajectory point within the horizon
    (its distance now, less how far the AGV (``agv_reach``: ``sample_reach``) and the
    disc can travel) changes no sample's minimum clearance, so dropping it changes
    nothing. With many AGVs on a map most discs are such, and the clearance kernel's
    cost is linear in the number of discs. The nearest come first: ``lower_by_discs``
    then finds a trajectory's clearance early and skips more of the others.
    """
    nearest_first, least = _by_gap(
        discs, float(pose[0]), float(pose[1]), agv_reach, config.radius, config.horizon_s
    )
    return np.ascontiguousarray(nearest_first[least < bound])


@numba.njit(cache=True)
def _by_gap(discs, x, y, agv_reach, radius, horizon_s):
    """The discs sorted by the gap now, stably (an insertion sort: a few dozen discs, and
    numba compiled its mergesort slowly), and the least clearance each can reach within
    the horizon (``relevant_discs``)."""
    n = len(discs)
    gap_now, least = np.empty(n), np.empty(n)
    for i in range(n):
        disc_reach = np.hypot(discs[i, 2], discs[i, 3]) * horizon_s
        gap_now[i] = np.hypot(discs[i, 0] - x, discs[i, 1] - y) - discs[i, 4] - radius
        least[i] = gap_now[i] - agv_reach - disc_reach
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        j = i
        while j > 0 and gap_now[order[j - 1]] > gap_now[i]:
            order[j] = order[j - 1]
            j -= 1
        order[j] = i
    sorted_discs, sorted_least = np.empty((n, 5)), np.empty(n)
    for i in range(n):
        sorted_discs[i, :] = discs[order[i], :]
        sorted_least[i] = least[order[i]]
    return sorted_discs, sorted_least


@numba.njit(cache=True)
def _on_route(offsets, braking, clearance, tolerance):
    """``braking`` where a sample follows the route (within ``tolerance``) and it exceeds
    the clearance, else 0: numpy's ``where`` of the two tests, in one call."""
    out = np.empty(len(braking))
    for i in range(len(braking)):
        follows = offsets[i] <= tolerance and braking[i] > clearance[i]
        out[i] = braking[i] if follows else 0.0
    return out


def admissible_mask(
    config: DwaConfig,
    commands: np.ndarray,
    clearance: np.ndarray,
    braking_room: np.ndarray | None = None,
) -> np.ndarray:
    """Eq. (7) plus no contact: the AGV can brake to zero within the trajectory's clearance.

    ``braking_room`` (the default profile's ``planner.local.lane_speed``) replaces the
    clearance in the linear speed's bound; the turn rate's bound keeps the clearance.
    """
    linear = clearance if braking_room is None else braking_room
    return _admissible(commands, clearance, linear, config.max_accel, config.max_alpha)


@numba.njit(cache=True)
def _admissible(commands, clearance, linear, max_accel, max_alpha):
    """``admissible_mask``, compiled: ``linear`` is the room bounding the linear speed."""
    mask = np.empty(len(commands), dtype=np.bool_)
    for i in range(len(commands)):
        room = max(clearance[i], 0.0)
        speed = np.hypot(commands[i, 0], commands[i, 1])
        mask[i] = (
            clearance[i] > 0.0
            and speed <= np.sqrt(2.0 * max(linear[i], 0.0) * max_accel) + _EPS
            and abs(commands[i, 2]) <= np.sqrt(2.0 * room * max_alpha) + _EPS
        )
    return mask


def route_offsets(xs: np.ndarray, ys: np.ndarray, segment) -> np.ndarray:
    """(N,) the largest distance of each trajectory (N, K) from the route ``segment``."""
    (ax, ay), (bx, by) = segment
    return _largest_offsets(xs, ys, float(ax), float(ay), float(bx - ax), float(by - ay))


@numba.njit(cache=True)
def _largest_offsets(xs, ys, ax, ay, dx, dy):
    """(N,) the largest distance of each trajectory (N, K) from the segment from (ax, ay)
    along (dx, dy), as ``np.hypot(...).max(axis=1)`` gives it, bit for bit. ``math.hypot``
    is slow compiled, so it is taken only for the steps whose squared distance is within
    rounding of the largest (those alone can hold the largest hypot)."""
    length2 = dx * dx + dy * dy
    n_traj, n_steps = xs.shape
    out = np.empty(n_traj)
    ex = np.empty(n_steps)
    ey = np.empty(n_steps)
    for n in range(n_traj):
        largest2 = 0.0
        for k in range(n_steps):
            t = 0.0 if length2 < _EPS else ((xs[n, k] - ax) * dx + (ys[n, k] - ay) * dy) / length2
            t = min(max(t, 0.0), 1.0)
            ex[k] = xs[n, k] - (ax + t * dx)
            ey[k] = ys[n, k] - (ay + t * dy)
            largest2 = max(largest2, ex[k] * ex[k] + ey[k] * ey[k])
        largest = 0.0
        for k in range(n_steps):
            if ex[k] * ex[k] + ey[k] * ey[k] >= largest2 * (1.0 - 1e-9):
                largest = max(largest, math.hypot(ex[k], ey[k]))
        out[n] = largest
    return out


@numba.njit(cache=True)
def _evaluate(
    x, y, theta, vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step,
    dt, steps, horizon_s, radius, max_accel, max_alpha, samples, inv_spacing, ox, oy, discs,
    lane, room, stopping, distance, behind, offsets_wanted, ax, ay, dx, dy,
):  # fmt: skip
    """``DwaPlanner.plan``'s samples and what it judges them by, in one compiled call:
    the window's commands, their trajectories (3, N, K), each one's least clearance to
    the map (``walls``) and with the moving ``discs`` (sorted nearest first, as
    ``relevant_discs``), the route offsets (when ``offsets_wanted``; else empty), Eq. (7)'s
    admissible mask, the discs in reach of the fastest sample the lane admits (the
    fallback's choice between evading and braking looks at them), those that can lower
    a clearance below the best static one, the samples' reach and that best clearance.

    With a ``lane`` (``planner.local.lane_speed``) the linear speed of the samples that follow
    the route segment (from (ax, ay) along (dx, dy)) is bounded by their room to brake
    along it before the moving discs instead of by their clearance: the path's length
    over the horizon, the route's ``room`` and, when ``stopping`` ``distance`` away,
    the room before what stands ``behind`` that place. The others keep Eq. (7)'s
    clearance, which the lane only ever relaxes.

    The dozen kernels and numpy calls this was, called one by one from Python, cost an
    AGV process (whose caches are cold at every tick with 50 of them on 2 cores) more
    than their arithmetic. The same operations in the same order: the same values.
    """
    commands, which, omegas = _window(
        vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step
    )
    paths = _rollout(x, y, theta, commands, omegas, which, dt, steps)
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
    span = math.sqrt(_largest_square_distance(xs, ys, x, y))
    by_gap, least = _by_gap(discs, x, y, span, radius, horizon_s)
    reached = by_gap[least < bound]
    lowering = by_gap[least < static_best]
    clearance = walls
    if len(lowering):
        clearance = lower_by_discs(xs, ys, walls, lowering, dt, radius)
    offsets = np.empty(0)
    if offsets_wanted:
        offsets = _largest_offsets(xs, ys, ax, ay, dx, dy)
    linear = clearance
    if lane:
        # only the samples that follow the route get the room (0: the discs' kernel
        # skips the others); the gap to moving discs bounds it too (Eq. 7 for them)
        braking = _on_route(offsets, braking, clearance, ROUTE_TOLERANCE)
        near = by_gap[least < braking.max()]
        if len(near):
            braking = lower_by_discs(xs, ys, braking, near, dt, radius)
        linear = np.maximum(braking, clearance)
    mask = _admissible(commands, clearance, linear, max_accel, max_alpha)
    return commands, paths, walls, clearance, offsets, mask, reached, lowering, span, static_best


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
        cycle before (for the steadiness term; None: the current one).
        ``approach``: the final approach, where the dist term is replaced by
        nearness to the target (goals in docks and pockets have little clearance).
        ``segment``: the global route's segment to the target, for the ``on_route`` term.
        ``route``: the remaining global route from the AGV, along which head-on
        ``walkers`` (rows as ``moving``: the discs that do not avoid the AGV) are
        predicted, to get out of their way early (``planner.local.yielding``), and on along
        ``came_by``: the way the AGV came, from it back.
        ``lane_room``: the braking room the route ahead grants (``planner.local.lane_speed``);
        with a ``segment``, the samples that follow it are bounded by the room to brake
        along their path instead of by their clearance (None: Eq. 7 for all).
        """
        cfg = self.config
        field = self.distance_field
        discs = np.zeros((0, 5)) if moving is None else np.asarray(moving, dtype=float)
        discs = np.ascontiguousarray(discs.reshape(-1, 5))
        lane = lane_room is not None and segment is not None
        # how far each sample strays from the route: the lane and the score
        offsets_wanted = segment is not None and (lane or self.behaviour.route_weight > 0)
        room, behind = 0.0, 0.0
        distance = math.dist(pose[:2], target_xy) if stop else 0.0  # to where it stops
        if lane:
            # never less than the hardest braking from the current command needs: a replan
            # that turns the route close ahead of a fast AGV leaves it braking along the
            # route, not with nothing admissible and the fallback's choice
            hardest = braking_room(math.hypot(command[0], command[1]), cfg.max_accel, cfg.dt)
            room = float(max(lane_room, hardest))
            if stop:  # the room before what stands behind the place it stops at
                behind = node_room(field, cfg.radius, target_xy)
        (ax, ay), (bx, by) = _NO_SEGMENT if segment is None else segment
        vx, vy, omega = (float(v) for v in command)
        evaluated = _evaluate(
            float(pose[0]), float(pose[1]), float(pose[2]), vx, vy, omega,
            cfg.min_vx, cfg.max_speed, cfg.max_omega, cfg.max_accel * cfg.dt,
            cfg.max_alpha * cfg.dt, cfg.v_resolution, cfg.omega_resolution, cfg.dt, cfg.steps,
            cfg.horizon_s, cfg.radius, cfg.max_accel, cfg.max_alpha,
            field.samples, 1.0 / field.spacing, *field.origin, discs,
            lane, room, lane and stop, distance, behind,
            offsets_wanted, float(ax), float(ay), float(bx - ax), float(by - ay),
        )  # fmt: skip
        commands, paths, walls, clearance, offsets, mask, discs, lowering = evaluated[:8]
        span, static_best = evaluated[8:]
        xs, ys, thetas = paths
        offsets = offsets if offsets_wanted else None
        if self.behaviour.no_retreat and len(agvs_of(lowering, walkers)):
            ahead = ahead_on_route(pose, target_xy, segment)
            mask &= ~retreating(pose, xs[:, -1], ys[:, -1], ahead)
        if self.behaviour.yield_early and walkers is not None and len(walkers):
            ends = (xs[:, -1], ys[:, -1])
            walkers = np.asarray(walkers, dtype=float).reshape(-1, 5)
            mask = self._clear_of_walkers_later(mask, command, ends, walkers, route, came_by)
        if stop:
            speed = np.hypot(commands[:, 0], commands[:, 1])
            limit = max(math.sqrt(2.0 * cfg.max_accel * distance), float(speed.min()))
            mask &= speed <= limit + _EPS
        ok = np.flatnonzero(mask)
        if ok.size == 0:
            if self.behaviour.evade and self._evade_from(pose, span, discs, walkers, static_best):
                times = contact_times(
                    xs, ys, field.samples, 1.0 / field.spacing, discs, cfg.dt, cfg.radius,
                    *field.origin,
                )  # fmt: skip
                speeds = np.hypot(commands[:, 0], commands[:, 1])
                here = field.distance_at_point(pose[0], pose[1]) - cfg.radius
                best = evasive_index(*times, into_wall(walls, here), speeds, cfg.max_accel, cfg.dt)
                chosen = tuple(commands[best].tolist())
                path = (xs[best], ys[best], thetas[best])
                return DwaResult(chosen, _poses(path), len(commands), 0)
            brake = braking_command(cfg, command)
            path = rollout(pose, np.array([brake]), cfg.dt, cfg.steps)[:, 0, :]
            return DwaResult(brake, _poses(path), len(commands), 0)
        behaviour = self.behaviour
        route_weight = behaviour.route_weight if offsets is not None else 0.0
        weights = (cfg.alpha, cfg.beta, cfg.gamma, behaviour.face_travel_weight, route_weight)
        speed = math.hypot(command[0], command[1])
        steady = behaviour.steady_tolerance
        # with a walker coming the AGV keeps the room to yield: no speeding up out of the
        # steady choice's tolerance
        step = cfg.v_resolution
        if steady > 0 and speed >= _EPS and walker_coming(pose, walkers):
            step = math.inf
        best = choose(
            ok, commands, xs, ys, thetas, clearance, _NO_OFFSETS if offsets is None else offsets,
            float(target_xy[0]), float(target_xy[1]), float(reach), approach, weights,
            cfg.clearance_cap, steady, command, command if previous is None else previous,
            speed, step,
        )  # fmt: skip
        chosen = tuple(commands[best].tolist())
        return DwaResult(chosen, _poses((xs[best], ys[best], thetas[best])), len(commands), len(ok))

    def _clear_of_walkers_later(self, mask, command, ends, discs, route, came_by) -> np.ndarray:
        """``mask`` narrowed to the samples whose end point no disc reaches before the
        yield horizon (``planner.local.yielding``); when no admissible one is such, to those that
        leave the AGV furthest from the discs' way (it backs off towards a refuge rather
        than driving on into a walker it can no longer avoid)."""
        cfg = self.config
        speed = math.hypot(command[0], command[1])
        horizon = yield_horizon(cfg, speed, float(discs[:, 4].max()))
        later = parked_clearance(*ends, discs, route, cfg.horizon_s, horizon, cfg.radius, came_by)
        clear = mask & (later > 0.0)
        if clear.any():
            return clear
        if not mask.any():
            return mask
        return mask & (later >= later[mask].max() - YIELD_SLACK)

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

    def _evade_from(self, pose, reach: float, discs, walkers, bound: float) -> bool:
        """Whether the evasive fallback applies: against walls and walkers, not when the only
        moving discs in reach are AGVs. They plan too; an AGV that brakes is predictable to
        them, one that flees at full speed into a crowded aisle is not (the stress suite's
        warehouse-40 collisions were between two AGVs, one of them fleeing)."""
        if not len(discs):
            return True
        if walkers is None or not len(walkers):
            return False
        walkers = np.ascontiguousarray(np.asarray(walkers, dtype=float).reshape(-1, 5))
        return len(relevant_discs(self.config, pose, reach, walkers, bound)) > 0

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
