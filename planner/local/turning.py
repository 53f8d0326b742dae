"""Turning on the spot within the omega and alpha limits (the default's initial turn)."""

from __future__ import annotations

import math

from planner.core.motion import Command
from planner.core.physics import braking_speed
from planner.local.config import DwaConfig

ALIGNED = math.radians(2.0)  # rad: a heading error this small counts as aligned


def turn_command(config: DwaConfig, error: float, command: Command) -> Command | None:
    """The next command turning through the heading ``error`` (rad), or None when aligned.

    The rate follows the braking curve sqrt(2 alpha |error|), capped at
    ``max_omega``, and changes by at most alpha dt per period, so the turn
    starts and ends at rest within the limits; linear speed brakes meanwhile.
    """
    omega = command[2]
    if abs(error) <= ALIGNED and abs(omega) <= config.max_alpha * config.dt + 1e-9:
        return None
    dw, dv = config.max_alpha * config.dt, config.max_accel * config.dt
    wanted = math.copysign(
        min(config.max_omega, braking_speed(abs(error), config.max_alpha)), error
    )
    new_omega = omega + min(max(wanted - omega, -dw), dw)
    vx, vy = command[0], command[1]
    return (
        math.copysign(max(abs(vx) - dv, 0.0), vx),
        math.copysign(max(abs(vy) - dv, 0.0), vy),
        new_omega,
    )
