"""Getting out of a walker's way early (default profile).

A walker does not avoid the AGV: coming head-on along the route, it walks
into whatever stands on its line. DWA looks ``predict_time`` ahead, and by
the time a walker is that close an AGV at Table 1's 0.2 m/s² can no longer
brake and step aside (from 0.5 m/s: 2.5 s to stop, 3.7 s more to move 0.7 m
sideways). So each trajectory is also judged by where it leaves the AGV: if
it then stood at its end point, would a disc walking on reach it before the
``yield_horizon``? DWA keeps to the trajectories that leave the AGV clear
whenever there are any, and so steps off the walker's way while there is
still time and room. When there are none (a one-cell aisle with no refuge in
reach), it keeps to those a walker reaches last: it backs off along the way
towards a refuge instead of driving on into the walker.

Where a disc walks on is its ``sweep``: at its known velocity, except that a
disc on the AGV's remaining route and walking against it is taken to follow
the route towards the AGV (a walker keeps to the aisle it walks in; a
straight line would leave the route at its first bend and miss the AGV), and
on past the AGV along the way the AGV came. Without that way, the sweep ended
at the AGV, and backing off along its own tracks looked clear: an AGV met
head-on by a walker in an aisle fled 2 m back down it ahead of the walker,
which caught it up there.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from planner.maps.grid import Point
from planner.route.route_check import route_samples

if TYPE_CHECKING:  # planner.local.dwa imports this module
    from planner.local.config import DwaConfig

YIELD_MARGIN = 2.0
"""The time to brake and step aside, this many times over: a refuge is not always beside
the AGV."""

SWEEP_STEP = 0.1  # m: spacing of the points a sweep is checked at
ON_ROUTE = 0.5  # m: a disc centre this near the route walks along it
AGAINST = math.radians(45.0)  # rad: ... if it walks within this of the route's reverse


def yield_horizon(config: DwaConfig, speed: float, disc_radius: float) -> float:
    """Seconds ahead in which a disc must find the AGV gone from its way: the rollout, then
    braking from ``speed`` and stepping aside by both radii from rest, within the limits."""
    aside = config.radius + disc_radius
    return config.predict_time + YIELD_MARGIN * (
        speed / config.max_accel + 2.0 * math.sqrt(aside / config.max_accel)
    )


def arc_lengths(route: Sequence[Point]) -> np.ndarray:
    """(P,) the distance along ``route`` to each of its points."""
    steps = [math.dist(a, b) for a, b in itertools.pairwise(route)]
    return np.concatenate(([0.0], np.cumsum(steps)))


def along(route: Sequence[Point], lengths: np.ndarray, s: float) -> Point:
    """The point at distance ``s`` along ``route`` (clamped to its ends)."""
    s = min(max(s, 0.0), float(lengths[-1]))
    i = min(int(np.searchsorted(lengths, s, side="right")) - 1, len(route) - 2)
    span = lengths[i + 1] - lengths[i]
    t = 0.0 if span <= 0 else (s - lengths[i]) / span
    (ax, ay), (bx, by) = route[i], route[i + 1]
    return (ax + t * (bx - ax), ay + t * (by - ay))


def on_route_against(route: Sequence[Point], disc) -> float | None:
    """The distance along ``route`` of a disc that walks on it towards the route's start, or
    None (off the route, standing, or not walking against it)."""
    x, y, vx, vy = disc[:4]
    speed = math.hypot(vx, vy)
    if speed <= 0 or len(route) < 2:
        return None
    best, best_s, direction = math.inf, 0.0, (0.0, 0.0)
    lengths = arc_lengths(route)
    for i, (a, b) in enumerate(itertools.pairwise(route)):
        dx, dy = b[0] - a[0], b[1] - a[1]
        length = math.hypot(dx, dy)
        if length <= 0:
            continue
        t = min(max(((x - a[0]) * dx + (y - a[1]) * dy) / (length * length), 0.0), 1.0)
        gap = math.hypot(x - (a[0] + t * dx), y - (a[1] + t * dy))
        if gap < best:
            best, best_s, direction = gap, lengths[i] + t * length, (dx / length, dy / length)
    if best > ON_ROUTE:
        return None
    cos_against = -(vx * direction[0] + vy * direction[1]) / speed
    return best_s if cos_against >= math.cos(AGAINST) else None


def sweep(
    route: Sequence[Point] | None,
    disc,
    t_from: float,
    t_to: float,
    came_by: Sequence[Point] = (),
) -> np.ndarray:
    """(P, 2) points where ``disc`` [x, y, vx, vy, r] walks between ``t_from`` and ``t_to``:
    back along ``route`` when it walks against it there, and on along ``came_by`` (the way
    the AGV came, from the route's start back), else at its velocity."""
    x, y, vx, vy = (float(v) for v in disc[:4])
    speed = math.hypot(vx, vy)
    s = None if route is None else on_route_against(route, disc)
    if s is not None:
        way = [*reversed(came_by[1:]), *route]  # came_by[0] is route[0], the AGV
        lengths = arc_lengths(way)
        s += float(lengths[len(way) - len(route)])
        ends = (s - speed * t_from, s - speed * t_to)
        if ends[0] <= 0:  # it has passed the way's start by then
            return np.array([way[0]])
        inner = [p for p, d in zip(way, lengths, strict=True) if ends[1] < d < ends[0]]
        path = [along(way, lengths, ends[0]), *reversed(inner), along(way, lengths, ends[1])]
        return route_samples(path, SWEEP_STEP)
    start = (x + vx * t_from, y + vy * t_from)
    end = (x + vx * t_to, y + vy * t_to)
    return route_samples([start, end], SWEEP_STEP)


def parked_contact(
    end_x: np.ndarray, end_y: np.ndarray, discs: np.ndarray, route: Sequence[Point] | None,
    t_from: float, t_to: float, radius: float, came_by: Sequence[Point] = (),
) -> np.ndarray:  # fmt: skip
    """(N,) the time (s from now) at which the first of the discs (M, 5) rows [x, y, vx, vy,
    r] walking on (``sweep``) from ``t_from`` to ``t_to`` touches an AGV standing at each
    end point (``end_x``, ``end_y``); inf where none does."""
    out = np.full(len(end_x), np.inf)
    for disc in discs:
        points = sweep(route, disc, t_from, t_to, came_by)
        gap = np.hypot(end_x[:, None] - points[None, :, 0], end_y[:, None] - points[None, :, 1])
        touching = gap < disc[4] + radius
        walked = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))))
        speed = math.hypot(disc[2], disc[3])
        at = t_from + (walked / speed if speed > 0 else np.zeros_like(walked))
        first = np.where(touching.any(axis=1), at[touching.argmax(axis=1)], np.inf)
        out = np.minimum(out, first)
    return out


def contact_later(
    config: DwaConfig, end_x: np.ndarray, end_y: np.ndarray, walkers: np.ndarray,
    speed: float, route: Sequence[Point] | None, came_by: Sequence[Point] = (),
) -> np.ndarray:  # fmt: skip
    """(N,) when a walker walking on from the end of the rollout until the ``yield_horizon``
    (from ``speed``) first touches the AGV left standing at each of its end points
    (``end_x``, ``end_y``); inf: none does, the end point is off every walker's way. What
    early yield asks of DWA's samples (``planner.local.filters.YieldEarly``) and the
    straight approach of its end."""
    horizon = yield_horizon(config, speed, float(walkers[:, 4].max()))
    return parked_contact(
        end_x, end_y, walkers, route, config.horizon_s, horizon, config.radius, came_by
    )


STILL = 0.01
"""m/s: a walker slower than this stands still."""

WALKER_RANGE = 12.0
"""m: with a walker this near, the AGV leaves the room to yield: no straight approach to a
tight corner (``planner.nav.tight_turns``) while it stands still, no speeding up out of a
steady choice (DWA) while it is not walking away. A walker at 1 m/s and an AGV at 2 m/s
close 12 m in 4 s, about the yield horizon at Table 1's limits (nav_bench: 4, 6, 8 m left
2, 2, 1 collisions; 12 m, 1)."""


def _walkers_in_range(pose, walkers) -> np.ndarray:
    """The rows [x, y, vx, vy, r] of ``walkers`` within ``WALKER_RANGE`` of ``pose``."""
    if walkers is None or not len(walkers):
        return np.zeros((0, 5))
    walkers = np.asarray(walkers, dtype=float).reshape(-1, 5)
    return walkers[np.hypot(walkers[:, 0] - pose[0], walkers[:, 1] - pose[1]) < WALKER_RANGE]


def walker_near(pose, walkers) -> bool:
    """Whether a walker (rows [x, y, vx, vy, r]) is within ``WALKER_RANGE`` of ``pose``."""
    return len(_walkers_in_range(pose, walkers)) > 0


def walker_standing_near(pose, walkers) -> bool:
    """Whether a walker within ``WALKER_RANGE`` of ``pose`` stands still: it may start
    towards the AGV at any time."""
    near = _walkers_in_range(pose, walkers)
    return bool((np.hypot(near[:, 2], near[:, 3]) < STILL).any())


def walkers_standing(pose, walkers) -> bool:
    """Whether every walker within ``WALKER_RANGE`` of ``pose`` stands still (True for none)."""
    near = _walkers_in_range(pose, walkers)
    return bool((np.hypot(near[:, 2], near[:, 3]) < STILL).all())


def walker_coming(pose, walkers) -> bool:
    """Whether a walker within ``WALKER_RANGE`` of ``pose`` is not walking away from it.

    One that walks away has passed, or never came: an AGV that let it by from a bay and
    kept crawling there (the steady choice, with no speeding up near a walker) was still
    in the bay 1 s later when the walker turned off the route into it.
    A standing walker counts as coming: it may start towards the AGV at any time.
    """
    near = _walkers_in_range(pose, walkers)
    if not len(near):  # every control cycle asks, mostly with no walker about
        return False
    away = (near[:, 0] - pose[0]) * near[:, 2] + (near[:, 1] - pose[1]) * near[:, 3] > 0.0
    return bool((~away).any())


def agvs_of(moving, walkers) -> np.ndarray:
    """The rows of ``moving`` that are not walkers (``walkers`` are rows of it too): the
    other AGVs."""
    if moving is None or not len(moving):
        return np.zeros((0, 5))
    moving = np.asarray(moving, dtype=float).reshape(-1, 5)
    if walkers is None or not len(walkers):
        return moving
    walkers = np.asarray(walkers, dtype=float).reshape(-1, 5)
    is_walker = (moving[:, None, :] == walkers[None, :, :]).all(axis=2).any(axis=1)
    return moving[~is_walker]
