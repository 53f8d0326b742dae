"""The omnidirectional motion model (Guo et al. 2023, Eq. 4) in the world frame."""

from __future__ import annotations

import math

import numba
import numpy as np

from planner.core.cpython_math import remainder

Pose = tuple[float, float, float]
"""x, y (m, world frame), theta (rad)."""
Command = tuple[float, float, float]
"""vx, vy (m/s, body frame), omega (rad/s)."""

CONTROL_PERIOD = 0.1
"""s, the paper's control period (section 5): a scenario's ``dt`` when it gives none. A
run has one period, the scenario's: the world steps by it and every AGV's DwaConfig
carries it (``fleet.scenario.Scenario`` refuses one that disagrees)."""


@numba.njit(cache=True)
def step_pose(pose: Pose, command: Command, dt: float) -> Pose:
    """Eq. (4): ``pose`` after ``dt`` under the body-frame ``command``, theta in [-pi, pi]
    (compiled: the straight approach's rollout calls it from compiled code)."""
    x, y, theta = pose
    vx, vy, omega = command
    c, s = math.cos(theta), math.sin(theta)
    return (
        x + (vx * c - vy * s) * dt,
        y + (vx * s + vy * c) * dt,
        remainder(theta + omega * dt, math.tau),
    )


@numba.njit(cache=True)
def wrap_angle(angle):
    """Angles wrapped to [-pi, pi) (a float or an array of them; callable from compiled
    code, and from Python at a tenth of a numba ufunc's call cost)."""
    return np.remainder(angle + np.pi, 2 * np.pi) - np.pi


@numba.njit(cache=True)
def turned_velocity(theta, vx, vy, omega, dt):
    """World-frame velocity (vx, vy) of a state that applied the body-frame command
    (vx, vy, omega) over the last period ``dt`` and now has heading ``theta``.

    Eq. 4 moves the position with the heading *before* the step, so the command is
    turned by theta - omega * dt: this equals the position difference over dt, and is
    what a disc seen at this state moves with.
    """
    heading = theta - omega * dt
    c, s = np.cos(heading), np.sin(heading)
    return vx * c - vy * s, vx * s + vy * c


def world_velocity(theta, vx, vy, omega, dt: float) -> np.ndarray:
    """``turned_velocity`` of many states: (..., 2) for scalars or arrays that broadcast."""
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta, vx, vy, omega)))
    flat = [np.ascontiguousarray(a).reshape(-1) for a in arrays]
    out = np.empty((flat[0].size, 2))
    _turned_velocities(*flat, float(dt), out)
    return out.reshape((*arrays[0].shape, 2))


@numba.njit(cache=True)
def _turned_velocities(theta, vx, vy, omega, dt, out):
    for i in range(theta.size):
        out[i, 0], out[i, 1] = turned_velocity(theta[i], vx[i], vy[i], omega[i], dt)


@numba.njit(cache=True)
def moving_discs(states, skip, walkers, dt):
    """The discs a planner avoids, rows [x, y, vx, vy, radius] in the world frame: the
    AGVs of ``states`` (rows [x, y, theta, vx, vy, omega, radius], as a tick lists them,
    body-frame commands) but row ``skip`` (the planning AGV itself), each moving with its
    ``turned_velocity``, then the ``walkers`` (rows as the result's) as they are. Compiled:
    it runs for every AGV at every tick, and numpy's dozen calls on a few dozen rows
    cost more than the arithmetic."""
    n = states.shape[0] - 1
    out = np.empty((n + walkers.shape[0], 5))
    row = 0
    for i in range(states.shape[0]):
        if i == skip:
            continue
        x, y, theta, vx, vy, omega, radius = states[i]
        out[row, 0], out[row, 1] = x, y
        out[row, 2], out[row, 3] = turned_velocity(theta, vx, vy, omega, dt)
        out[row, 4] = radius
        row += 1
    out[n:] = walkers
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
