"""The dynamic window (Guo et al. 2023, Eqs. 5, 6): the commands one control period reaches.

Per axis, the speed limits intersected with what one control period of acceleration
reaches from the current command, sampled on the resolution grid centred on the current
command (so the current command is always a sample); then the samples faster than
``max_speed`` in |(vx, vy)| are dropped. ``braking_command`` is the paper's answer when no
sample is admissible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from planner.core.motion import Command
from planner.local.config import DwaConfig

_EPS = 1e-9


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
        *window_samples(
            vx, vy, omega, config.min_vx, config.max_speed, config.max_omega, dv, dw,
            config.v_resolution, config.omega_resolution,
        )
    )  # fmt: skip


@numba.njit(cache=True)
def window_samples(vx, vy, omega, min_vx, max_speed, max_omega, dv, dw, v_step, omega_step):
    """``window``'s commands, their turn rates' indices and the turn rates, in one compiled
    call (four from Python cost more than the sampling)."""
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
