"""Stopping physics of a vehicle under a constant deceleration: written once, used everywhere.

A body at speed v that brakes at a stops within v² / 2a; to stop within d it may go at
most √(2ad). The same holds for turning with ω and the angular acceleration.
"""

from __future__ import annotations

import math

import numba


@numba.njit(cache=True)
def braking_distance(speed, decel):
    """Distance (m, or rad for a turn) to stop from ``speed`` braking at ``decel``."""
    return speed * speed / (2.0 * decel)


@numba.njit(cache=True)
def braking_speed(distance, decel):
    """The highest speed from which a body braking at ``decel`` stops within ``distance``."""
    return math.sqrt(2.0 * decel * distance)
