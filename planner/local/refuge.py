"""Where to yield to a walker when no sample of this cycle leaves the AGV off its way.

Early yield (``planner.local.filters.YieldEarly``) keeps DWA to the samples whose end
point no walker reaches. In a one-cell lane none is, and which of them DWA drives decides
where the AGV goes. No measure of the end points alone is right: the most clearance from
the walker's way is the same for every end point in the lane, so DWA drove on into a
walker coming down it; the latest contact backs the AGV away from a bay just ahead, into
the lane's dead end. The refuge says where to go instead: the nearest place the AGV fits,
off every walker's way until the yield horizon, that it reaches before a walker does. It
is found by a wavefront from the AGV over a lattice of the places it fits, which a walker
must not overtake: a place counts as reached only if the AGV, braking and then going from rest at
``max_accel``, gets there before a walker touches it.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from planner.local.yielding import parked_contact
from planner.maps.grid import Point

if TYPE_CHECKING:
    from planner.local.config import DwaConfig
    from planner.maps.distance_field import DistanceField

SEARCH_RADIUS = 3.0  # m: refuges are looked for this far round the AGV ...
SEARCH_STEP = 0.25  # m: ... on a lattice this fine, 8-connected

REFUGE_SLACK = 0.05
"""m: end points within this of the nearest to the refuge are as good (DWA's score chooses)."""

_MOVES = [(di, dj, math.hypot(di, dj) * SEARCH_STEP)
          for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]  # fmt: skip


def time_to(config: DwaConfig, speed: float, distance: float) -> float:
    """Seconds to come to rest ``distance`` away at ``max_accel`` (half speeding up, half
    braking), after braking from ``speed`` (its direction is unknown)."""
    return speed / config.max_accel + 2.0 * math.sqrt(distance / config.max_accel)


def refuge(
    config: DwaConfig, field: DistanceField, position: Point, speed: float,
    walkers: np.ndarray, horizon: float, route: Sequence[Point] | None,
    came_by: Sequence[Point] = (),
) -> Point | None:  # fmt: skip
    """The refuge nearest to ``position`` along the lattice (None: none the AGV reaches
    first). The walkers (rows [x, y, vx, vy, r]) walk on as early yield predicts them
    (``parked_contact``), from now until ``horizon``."""
    steps = np.arange(-SEARCH_RADIUS, SEARCH_RADIUS + 1e-9, SEARCH_STEP)
    n = len(steps)
    xs, ys = np.meshgrid(position[0] + steps, position[1] + steps, indexing="ij")
    fits = field.distance_at(xs, ys) > config.radius
    touched = parked_contact(
        xs.ravel(), ys.ravel(), walkers, route, 0.0, horizon, config.radius, came_by
    ).reshape(xs.shape)
    centre = n // 2
    best = {(centre, centre): 0.0}
    queue = [(0.0, centre, centre)]
    while queue:
        walked, i, j = heapq.heappop(queue)
        if walked > best[(i, j)]:
            continue
        if math.isinf(touched[i, j]):
            return (float(xs[i, j]), float(ys[i, j]))
        for di, dj, step in _MOVES:
            a, b = i + di, j + dj
            further = walked + step
            if not (0 <= a < n and 0 <= b < n) or not fits[a, b] or further > SEARCH_RADIUS:
                continue
            if further >= best.get((a, b), math.inf):
                continue
            if touched[a, b] <= time_to(config, speed, further):  # a walker is there first
                continue
            best[(a, b)] = further
            heapq.heappush(queue, (further, a, b))
    return None
