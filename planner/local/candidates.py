"""The admissible samples as the critics see them: gathered once per cycle, compiled.

Every critic scores all candidates at once, as an array (one value per admissible
sample, in window order); what several of them read (the end poses, the speeds, the
directions of travel) is gathered here once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from planner.local.samples import Samples

_EPS = 1e-9


@dataclass(slots=True)
class Candidates:
    """The admissible samples: ``ok`` their indices into ``samples``; ``commands`` (n, 3);
    the trajectories' end poses; ``speeds`` |(vx, vy)|; ``travel`` the direction of travel
    off the body heading (``travel_angles``); ``clearance`` their least clearance."""

    ok: np.ndarray
    samples: Samples
    commands: np.ndarray
    end_x: np.ndarray
    end_y: np.ndarray
    end_theta: np.ndarray
    speeds: np.ndarray
    travel: np.ndarray
    clearance: np.ndarray

    @classmethod
    def of(cls, ok: np.ndarray, samples: Samples) -> Candidates:
        """The samples ``ok`` (indices) of ``samples``."""
        s = samples
        return cls(ok, s, *gather(ok, s.commands, s.xs, s.ys, s.thetas, s.clearance))


@numba.njit(cache=True)
def gather(ok, commands, xs, ys, thetas, clearance):
    """``Candidates``' arrays of the samples ``ok``, in one call."""
    n, last = ok.size, xs.shape[1] - 1
    sampled = np.empty((n, 3))
    end_x, end_y, end_theta, least = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        k = ok[i]
        sampled[i, 0], sampled[i, 1], sampled[i, 2] = commands[k, 0], commands[k, 1], commands[k, 2]
        end_x[i], end_y[i], end_theta[i] = xs[k, last], ys[k, last], thetas[k, last]
        least[i] = clearance[k]
    speeds = speeds_of(sampled)
    return sampled, end_x, end_y, end_theta, speeds, travel_angles(sampled, speeds), least


@numba.njit(cache=True)
def speeds_of(commands):
    """(N,) |(vx, vy)| of (N, 3) commands."""
    out = np.empty(len(commands))
    for i in range(len(commands)):
        out[i] = np.hypot(commands[i, 0], commands[i, 1])
    return out


@numba.njit(cache=True)
def travel_angles(commands, speeds):
    """(N,) each sample's direction of travel off the body heading, atan2(vy, vx) (0 when
    standing): an omnidirectional AGV need not face where it goes. ``speeds``:
    ``speeds_of(commands)``."""
    out = np.zeros(len(commands))
    for i in range(len(commands)):
        if speeds[i] > _EPS:
            out[i] = np.arctan2(commands[i, 1], commands[i, 0])
    return out
