"""The omnidirectional motion model (Guo et al. 2023, Eq. 4) in the world frame."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def wrap_angle(angle):
    """Angles wrapped to [-pi, pi) (a float or an array of them; callable from compiled
    code, and from Python at a tenth of a numba ufunc's call cost)."""
    return np.remainder(angle + np.pi, 2 * np.pi) - np.pi


def world_velocity(theta, vx, vy, omega, dt: float) -> np.ndarray:
    """World-frame velocity (..., 2) of states that applied the body-frame command
    (vx, vy, omega) over the last period ``dt`` and now have heading ``theta``.

    Eq. 4 moves the position with the heading *before* the step, so the command is
    turned by theta - omega * dt: this equals the position difference over dt, and is
    what a disc seen at this state moves with. Scalars or arrays.
    """
    heading = np.asarray(theta) - np.asarray(omega) * dt
    c, s = np.cos(heading), np.sin(heading)
    out = np.empty((*heading.shape, 2))  # np.stack's result, without its checks
    out[..., 0] = vx * c - vy * s
    out[..., 1] = vx * s + vy * c
    return out


Command = tuple[float, float, float]  # body frame: vx, vy (m/s), omega (rad/s)
_TOLERANCE = 1e-9  # float slack: DWA's window edges are sums of resolution steps


def limit_command(
    previous, requested, limits, dt: float
) -> tuple[tuple[float, float, float], bool]:
    """``requested`` (vx, vy, omega) clipped to what the vehicle can do in one period
    after ``previous``: the speed limits of ``limits`` (a ``DwaConfig``: max_speed on each
    axis and on |(vx, vy)|, min_vx, max_omega) and its acceleration limits (max_accel per
    linear axis, max_alpha). Returns the command and whether anything was clipped.

    The world applies it to every AGV's command, so a process can only ask, never move
    itself further than its vehicle could.
    """
    vx0, vy0, w0 = previous
    dv, dw = limits.max_accel * dt, limits.max_alpha * dt
    vmax = limits.max_speed
    bounds = (
        (max(vx0 - dv, limits.min_vx), min(vx0 + dv, vmax)),
        (max(vy0 - dv, -vmax), min(vy0 + dv, vmax)),
        (max(w0 - dw, -limits.max_omega), min(w0 + dw, limits.max_omega)),
    )
    out = []
    clipped = False
    for value, (low, high) in zip(requested, bounds, strict=True):
        if low > high:  # over a limit already (a changed scenario): brake towards it
            low = high = min(max(value, high), low)
        if not low - _TOLERANCE <= value <= high + _TOLERANCE:
            clipped = True
            value = min(max(value, low), high)
        out.append(float(value))
    speed = float(np.hypot(out[0], out[1]))
    if speed > vmax + _TOLERANCE:
        clipped = True
        out[0], out[1] = out[0] * vmax / speed, out[1] * vmax / speed
    return (out[0], out[1], out[2]), clipped
