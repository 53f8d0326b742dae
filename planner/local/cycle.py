"""What one control cycle is asked: the vehicle, the map and the situation, in one object.

The filters, the critics and the fallback each read what they need of it, instead of a
positional argument list threaded through every call (``DwaPlanner.plan`` documents each).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from planner.core.motion import Command, Pose
from planner.local.config import DwaConfig
from planner.maps.distance_field import DistanceField


@dataclass(slots=True)
class Cycle:
    """One control cycle's question (built by ``DwaPlanner.plan``; see its arguments).

    ``discs``: the moving discs as a contiguous (M, 5) array; ``previous``: the command
    of the cycle before (the current one when unknown); ``distance``: to the target when
    the AGV stops there, else 0.
    """

    config: DwaConfig
    field: DistanceField
    pose: Pose
    command: Command
    target: tuple[float, float]
    discs: np.ndarray
    reach: float
    stop: bool
    previous: Command
    approach: bool
    segment: tuple[tuple[float, float], tuple[float, float]] | None
    route: list[tuple[float, float]] | None
    came_by: Sequence[tuple[float, float]]
    walkers: np.ndarray | None
    lane_room: float | None
    distance: float

    @property
    def lane(self) -> bool:
        """Whether the samples that follow the route get the lane's braking room."""
        return self.lane_room is not None and self.segment is not None
