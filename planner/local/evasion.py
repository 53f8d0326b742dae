"""The evasive fallback: when no sample is admissible, delay contact as long as possible.

The paper brakes when nothing is admissible (Guo et al. 2023, section 3). A
standing AGV is still in a walker's way, so braking is often exactly what
gets it hit. Instead every sample of the window is ranked by whether it
would meet a wall before it could brake (a wall is certain, a prediction is
not), then by its time to contact with the moving discs predicted at
constant velocity (later is better), then by its lowest clearance over the
whole horizon (higher is better): the AGV steps aside, backs away or brakes,
whichever keeps it out of contact longest without driving into a wall.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.maps.distance_field import lookup


@numba.njit(cache=True)
def contact_times(xs, ys, samples, inv_spacing, moving, dt, radius, ox=0.0, oy=0.0):
    """(N,) times of each trajectory's first contact with the static map and with a moving
    disc (inf: none), (N,) its lowest clearance.

    ``xs``, ``ys`` (N, K) as in ``clearance.static_clearance``, on a distance field whose map
    origin is (``ox``, ``oy``); moving discs (M, 5) rows
    [x, y, vx, vy, r] at constant velocity. Unlike ``clearance.lower_by_discs`` the whole
    horizon is evaluated, so the lowest clearance ranks trajectories in contact.
    """
    n_traj, n_steps = xs.shape
    static_first = np.full(n_traj, np.inf)
    moving_first = np.full(n_traj, np.inf)
    lowest = np.empty(n_traj)
    for n in range(n_traj):
        worst = np.inf
        for k in range(n_steps):
            x, y, t = xs[n, k], ys[n, k], (k + 1) * dt
            c = lookup(samples, inv_spacing, x - ox, y - oy) - radius
            if c <= 0.0 and static_first[n] == np.inf:
                static_first[n] = t
            for m in range(moving.shape[0]):
                dx = x - (moving[m, 0] + moving[m, 2] * t)
                dy = y - (moving[m, 1] + moving[m, 3] * t)
                gap = math.sqrt(dx * dx + dy * dy) - moving[m, 4] - radius
                if gap <= 0.0 and moving_first[n] == np.inf:
                    moving_first[n] = t
                c = min(c, gap)
            worst = min(worst, c)
        lowest[n] = worst
    return static_first, moving_first, lowest


WALL_SLACK = 0.01
"""m: a sample that keeps this near its start's clearance to the walls does not go into them
(the distance field's interpolation wobbles along a wall the AGV touches)."""


def into_wall(walls: np.ndarray, here: float) -> np.ndarray:
    """(N,) whether each sample, with ``walls`` its least clearance to the map over the
    horizon, goes into a wall: below zero, and below ``here``, the clearance where the AGV
    stands (a wall it already touches it may slide along, not press into)."""
    return walls < min(here, 0.0) - WALL_SLACK


def evasive_index(
    static_first: np.ndarray, moving_first: np.ndarray, lowest: np.ndarray,
    entering: np.ndarray, speeds: np.ndarray, max_accel: float, dt: float,
) -> int:  # fmt: skip
    """The sample that does not go into a wall (``entering``), then does not commit the AGV
    to one, then meets a moving disc last, then keeps most clearance.

    A wall met later than the AGV can brake for (twice its braking time, plus a cycle) is
    no threat: the next cycle chooses again. Ranking every wall contact first would keep
    the AGV creeping, in reach of the walker it is fleeing, wherever it has walls around.
    But once a walker has pinned the AGV against a wall, every sample touches one at
    once; the lowest clearance alone (a walker overlapping the AGV by 0.37 m outweighs a
    wall) then drove it 0.3 m into the corner where two wall cells meet, which no
    vehicle can do: those samples come last.
    """
    committed = static_first <= 2.0 * speeds / max_accel + dt
    return int(np.lexsort((-lowest, -moving_first, committed, entering))[0])
