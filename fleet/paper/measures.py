"""Measurements the report needs beyond ``recordings.analysis``, from recorded series."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from recordings.series import RunSeries


@dataclass(frozen=True)
class Spread:
    mean: float
    std: float  # sample standard deviation; 0 for one value
    low: float
    high: float


def spread(values: list[float]) -> Spread:
    a = np.asarray(values, dtype=float)
    std = float(a.std(ddof=1)) if len(a) > 1 else 0.0
    return Spread(float(a.mean()), std, float(a.min()), float(a.max()))


def goal_approach(series: RunSeries) -> tuple[float, float]:
    """Closest approach of the first AGV to its goal (the first plan's last key node) and the
    length of that plan's last leg."""
    name = series.agvs.names[0]
    plan = next((p for p in series.plans.get(name, []) if p.get("found")), None)
    if plan is None or len(plan["key_nodes"]) < 2:
        return math.nan, math.nan
    (px, py), (gx, gy) = plan["key_nodes"][-2], plan["key_nodes"][-1]
    x, y = series.agvs.columns["x"][:, 0], series.agvs.columns["y"][:, 0]
    return float(np.nanmin(np.hypot(x - gx, y - gy))), float(math.hypot(gx - px, gy - py))


def same_drive(a: RunSeries, b: RunSeries) -> bool:
    """Two runs whose first AGV went through exactly the same poses."""
    xa, xb = a.agvs.columns["x"][:, 0], b.agvs.columns["x"][:, 0]
    ya, yb = a.agvs.columns["y"][:, 0], b.agvs.columns["y"][:, 0]
    return len(xa) == len(xb) and bool(np.array_equal(xa, xb) and np.array_equal(ya, yb))


def moving_obstacle_gap(series: RunSeries) -> float | None:
    """Closest surface-to-surface approach of the first AGV to any moving obstacle."""
    mov, agv = series.moving.columns, series.agvs.columns
    if not series.moving.names:
        return None
    dx = mov["x"] - agv["x"][:, :1]
    dy = mov["y"] - agv["y"][:, :1]
    gap = np.hypot(dx, dy) - mov["radius"] - agv["radius"][:, :1]
    return float(np.nanmin(gap))
