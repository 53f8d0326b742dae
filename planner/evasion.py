"""The evasive fallback: when no sample is admissible, delay contact as long as possible.

The paper brakes when nothing is admissible (Guo et al. 2023, section 3). A
standing AGV is still in a walker's way, so braking is often exactly what
gets it hit. Instead every sample of the window is ranked by its time to
contact with the static map and the moving discs predicted at constant
velocity (later is better), then by its lowest clearance over the whole
horizon (higher is better): the AGV steps aside, backs away or brakes,
whichever keeps it out of contact longest.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.distance_field import lookup


@numba.njit(cache=True)
def contact_times(xs, ys, samples, inv_spacing, moving, dt, radius):
    """(N,) time of each trajectory's first contact (inf: none), (N,) its lowest clearance.

    ``xs``, ``ys`` (N, K) as in ``dwa.min_clearance``; moving discs (M, 5) rows
    [x, y, vx, vy, r] at constant velocity. Unlike ``min_clearance`` the whole
    horizon is evaluated, so the lowest clearance ranks trajectories in contact.
    """
    n_traj, n_steps = xs.shape
    first = np.full(n_traj, np.inf)
    lowest = np.empty(n_traj)
    for n in range(n_traj):
        worst = np.inf
        for k in range(n_steps):
            x, y, t = xs[n, k], ys[n, k], (k + 1) * dt
            c = lookup(samples, inv_spacing, x, y) - radius
            for m in range(moving.shape[0]):
                dx = x - (moving[m, 0] + moving[m, 2] * t)
                dy = y - (moving[m, 1] + moving[m, 3] * t)
                c = min(c, math.sqrt(dx * dx + dy * dy) - moving[m, 4] - radius)
            if c <= 0.0 and first[n] == np.inf:
                first[n] = t
            worst = min(worst, c)
        lowest[n] = worst
    return first, lowest


def evasive_index(first_contact: np.ndarray, lowest_clearance: np.ndarray) -> int:
    """The sample whose contact comes last; among equals, the one with the most clearance."""
    return int(np.lexsort((-lowest_clearance, -first_contact))[0])
