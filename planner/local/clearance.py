"""The samples' clearance: the least, over a trajectory's steps, distance to what it can touch.

Static obstacles are read from the DistanceField; moving discs [x, y, vx, vy, r] (other
AGVs, walkers, moving obstacles) are predicted at constant velocity. Both minus the AGV's
radius, so a clearance <= 0 is a contact.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.core.motion import Pose
from planner.local.config import DwaConfig
from planner.maps.distance_field import lookup


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
    nearest_first, least = discs_by_gap(
        discs, float(pose[0]), float(pose[1]), agv_reach, config.radius, config.horizon_s
    )
    return np.ascontiguousarray(nearest_first[least < bound])


@numba.njit(cache=True)
def discs_by_gap(discs, x, y, agv_reach, radius, horizon_s):
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
