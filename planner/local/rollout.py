"""The rollout: every sample held for the horizon (Eq. 4), and what its trajectory's shape says.

All samples and steps as arrays: positions are ``vx * C(omega) - vy * S(omega)`` with C, S
the cumulative sums of the heading's cosine and sine, so trigonometry is only evaluated per
distinct omega. How far the trajectories reach (``sample_reach``) bounds which moving discs
can matter; how far each strays from the route (``route_offsets``) is what the lane and
the route critic look at.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.core.motion import Pose

_EPS = 1e-9


def rollout(pose: Pose, commands: np.ndarray, dt: float, steps: int) -> np.ndarray:
    """(3, N, K): x, y and theta after steps 1..K of each command held constant (Eq. 4).
    (A control cycle rolls out the window's samples with their turn rates as ``window``
    found them, in ``planner.local.samples``: no search.)"""
    x0, y0, theta0 = pose
    omegas, which = np.unique(commands[:, 2], return_inverse=True)
    return rollout_turns(float(x0), float(y0), float(theta0), commands, omegas, which, dt, steps)


@numba.njit(cache=True)
def rollout_turns(x0, y0, theta0, commands, omegas, which, dt, steps):
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


def sample_reach(pose: Pose, xs: np.ndarray, ys: np.ndarray) -> float:
    """How far from ``pose`` the samples' trajectories (N, K) reach."""
    return math.sqrt(largest_square_distance(xs, ys, float(pose[0]), float(pose[1])))


@numba.njit(cache=True)
def largest_square_distance(xs, ys, x0, y0):
    """The largest (x - x0)² + (y - y0)² over the trajectories, in one pass (numpy's four
    (N, K) temporaries were 5 % of the planning time with 40 AGVs on one map); the same
    operations, so the same value."""
    largest = -np.inf
    for n in range(xs.shape[0]):
        for k in range(xs.shape[1]):
            dx, dy = xs[n, k] - x0, ys[n, k] - y0
            largest = max(largest, dx * dx + dy * dy)
    return largest


def route_offsets(xs: np.ndarray, ys: np.ndarray, segment) -> np.ndarray:
    """(N,) the largest distance of each trajectory (N, K) from the route ``segment``."""
    (ax, ay), (bx, by) = segment
    return largest_offsets(xs, ys, float(ax), float(ay), float(bx - ax), float(by - ay))


@numba.njit(cache=True)
def largest_offsets(xs, ys, ax, ay, dx, dy):
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
