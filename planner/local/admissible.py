"""Eq. (7) plus no contact, compiled: the AGV can brake to zero within the trajectory's
clearance (Fox et al.'s minimum over the trajectory; the paper says "from its end", the
minimum is the safe reading). ``planner.local.samples`` computes it with the samples, for
the ``Admissible`` filter (``planner.local.filters``)."""

from __future__ import annotations

import numba
import numpy as np

from planner.core.physics import braking_speed
from planner.local.config import DwaConfig

_EPS = 1e-9


def admissible_mask(
    config: DwaConfig,
    commands: np.ndarray,
    clearance: np.ndarray,
    braking_room: np.ndarray | None = None,
) -> np.ndarray:
    """The mask of ``commands`` with ``clearance`` that Eq. (7) admits; ``braking_room``
    (the lane's) replaces the clearance in the linear speed's bound."""
    linear = clearance if braking_room is None else braking_room
    return admissible(commands, clearance, linear, config.max_accel, config.max_alpha)


@numba.njit(cache=True)
def admissible(commands, clearance, linear, max_accel, max_alpha):
    """``admissible_mask``, compiled: ``linear`` is the room bounding the linear speed."""
    mask = np.empty(len(commands), dtype=np.bool_)
    for i in range(len(commands)):
        room = max(clearance[i], 0.0)
        speed = np.hypot(commands[i, 0], commands[i, 1])
        mask[i] = (
            clearance[i] > 0.0
            and speed <= braking_speed(max(linear[i], 0.0), max_accel) + _EPS
            and abs(commands[i, 2]) <= braking_speed(room, max_alpha) + _EPS
        )
    return mask
