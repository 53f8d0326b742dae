"""Is the remaining route blocked by what is sensed?

One function of (distance field, route, required clearance), so that the
field can be swapped for a costmap's. The route is sampled every half
lattice spacing, so no obstacle cell can slip between two samples.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from planner.maps.distance_field import DistanceField
from planner.maps.grid import Point


def route_samples(route: Sequence[Point], step: float) -> np.ndarray:
    """(N, 2) points along the polyline ``route``, at most ``step`` apart, ends included."""
    points = [np.asarray(route[0], dtype=float)[None, :]]
    for a, b in itertools.pairwise(route):
        n = max(1, math.ceil(math.dist(a, b) / step))
        t = np.arange(1, n + 1)[:, None] / n
        points.append(np.asarray(a) + t * (np.asarray(b) - np.asarray(a)))
    return np.concatenate(points)


def blocked_point(
    field: DistanceField,
    route: Sequence[Point],
    clearance: float,
    unblocked: DistanceField | None = None,
) -> Point | None:
    """The first point of ``route`` with less than ``clearance`` to the nearest obstacle.

    With ``unblocked`` (the field without the sensed obstacles), a point counts
    only where the sensed obstacles made it tighter: a route the global
    planner knowingly drew close to a static wall is not blocked by it.
    """
    if len(route) < 2:
        return None
    points = route_samples(route, field.spacing / 2)
    gap = field.distance_at(points[:, 0], points[:, 1])
    tight = gap < clearance
    if unblocked is not None:
        tight &= gap < unblocked.distance_at(points[:, 0], points[:, 1]) - 1e-9
    hits = np.flatnonzero(tight)
    return None if hits.size == 0 else (float(points[hits[0], 0]), float(points[hits[0], 1]))
