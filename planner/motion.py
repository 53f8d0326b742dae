"""The omnidirectional motion model (Guo et al. 2023, Eq. 4) in the world frame."""

from __future__ import annotations

import numpy as np


def world_velocity(theta, vx, vy, omega, dt: float) -> np.ndarray:
    """World-frame velocity (..., 2) of states that applied the body-frame command
    (vx, vy, omega) over the last period ``dt`` and now have heading ``theta``.

    Eq. 4 moves the position with the heading *before* the step, so the command is
    turned by theta - omega * dt: this equals the position difference over dt, and is
    what a disc seen at this state moves with. Scalars or arrays.
    """
    heading = np.asarray(theta) - np.asarray(omega) * dt
    c, s = np.cos(heading), np.sin(heading)
    return np.stack((vx * c - vy * s, vx * s + vy * c), axis=-1)
