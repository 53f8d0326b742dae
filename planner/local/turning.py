"""Turning on the spot within the omega and alpha limits (the default's initial turn)."""

from __future__ import annotations

import math

import numba

from planner.core.motion import Command
from planner.local.config import DwaConfig

ALIGNED = math.radians(2.0)  # rad: a heading error this small counts as aligned


def turn_command(config: DwaConfig, error: float, command: Command) -> Command | None:
    """The next command turning through the heading ``error`` (rad), or None when aligned.

    The rate is the fastest from which braking by alpha dt per period still stops within
    the error (``stopping_rate``), capped at ``max_omega``, and changes by at most alpha dt
    per period, so the turn starts and ends at rest within the limits; linear speed
    brakes meanwhile.
    """
    omega = command[2]
    if abs(error) <= ALIGNED and abs(omega) <= config.max_alpha * config.dt + 1e-9:
        return None
    dw, dv = config.max_alpha * config.dt, config.max_accel * config.dt
    wanted = math.copysign(min(config.max_omega, stopping_rate(abs(error), dw, config.dt)), error)
    new_omega = omega + min(max(wanted - omega, -dw), dw)
    vx, vy = command[0], command[1]
    return (
        math.copysign(max(abs(vx) - dv, 0.0), vx),
        math.copysign(max(abs(vy) - dv, 0.0), vy),
        new_omega,
    )


@numba.njit(cache=True)  # the straight approach's compiled turn calls it too
def stopping_rate(error: float, dw: float, dt: float) -> float:
    """The highest turn rate r >= 0 that, held for a period and then braked by ``dw`` per
    period, turns through at most ``error`` (rad) before it stops, and at most the error
    in one period. The continuous curve sqrt(2 alpha error) ignores that each rate is held
    a whole period: braking from 20 deg/s it turned about 1 deg past the target, and the
    straight approach after the turn turned the body back (an omega sign change at every
    stop-and-turn corner)."""
    # r, r - dw, ... > 0 for one period each: with r = (m + x) dw, m whole and 0 < x <= 1,
    # the turn is dt (m + 1)(r - m dw / 2); m from the continuous curve, then exact
    m = max(0, math.ceil(math.sqrt(2.0 * error / (dw * dt)) - 1.0))
    while m > 0 and dt * m * (m + 1) * dw / 2.0 > error:  # m + 0 already turns too far
        m -= 1
    rate = error / (dt * (m + 1)) + m * dw / 2.0  # turns exactly error in m + 1 periods
    return min(rate, (m + 1) * dw, error / dt)
