"""The way an AGV came: where a walker that comes head-on along the route walks on once
past the AGV (``planner.local.yielding``).

A walker keeps to the aisle it walks in, and the aisle behind the AGV is the one the AGV
drove up: its own tracks, not the plan's key nodes (a replan starts where the AGV
stands and keeps none of the way before it: after a replan mid-aisle the plan behind
the AGV can be half a metre long while its tracks run metres down the aisle the walker
comes along).
"""

from __future__ import annotations

import math
from collections import deque

from planner.maps.grid import Point

TRAIL_STEP = 0.25
"""m between the positions kept: a grid cell of the default maps, finer than a walker's way
needs."""

TRAIL_LENGTH = 20.0
"""m of tracks kept. A walker's way matters where the AGV could stand at the end of a
sample, within a few metres of it; the tracks further back only where they curl back
near the AGV. Beyond them the walker is taken to stand where they end."""


class Trail:
    """The AGV's last ``TRAIL_LENGTH`` m of positions, ``TRAIL_STEP`` apart."""

    def __init__(self) -> None:
        self._points: deque[Point] = deque(maxlen=round(TRAIL_LENGTH / TRAIL_STEP))

    def note(self, position: Point) -> None:
        """Keep ``position`` once the AGV is ``TRAIL_STEP`` from the last one kept."""
        if not self._points or math.dist(self._points[-1], position) >= TRAIL_STEP:
            self._points.append(position)

    def back_from(self, position: Point) -> list[Point]:
        """The way the AGV came, from ``position`` back."""
        return [position, *reversed(self._points)]
