"""Moving obstacles: discs that follow waypoints at constant speed.

Their position is a pure function of time, so the world, every AGV process
and the replay agree on where an obstacle is without sending its history.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MODES = ("bounce", "loop", "once")


@dataclass(frozen=True)
class MovingObstacle:
    """A disc of ``radius`` moving along ``waypoints`` at ``speed`` (m/s).

    mode ``bounce`` goes back and forth, ``loop`` returns to the first waypoint
    and starts again, ``once`` stops at the last waypoint. It starts moving at
    ``start_at`` seconds and stands at the first waypoint before that.
    """

    name: str
    radius: float
    waypoints: tuple[tuple[float, float], ...]
    speed: float
    mode: str = "bounce"
    start_at: float = 0.0

    def _route(self) -> np.ndarray:
        pts = np.asarray(self.waypoints, dtype=float)
        if self.mode == "loop":
            pts = np.vstack([pts, pts[:1]])
        return pts

    def state_at(self, t: float) -> tuple[float, float, float, float]:
        """World-frame (x, y, vx, vy) at time t."""
        pts = self._route()
        seg = np.diff(pts, axis=0)
        lengths = np.hypot(seg[:, 0], seg[:, 1])
        total = float(lengths.sum())
        if total == 0.0 or self.speed == 0.0 or t <= self.start_at:
            return float(pts[0, 0]), float(pts[0, 1]), 0.0, 0.0
        s = (t - self.start_at) * self.speed
        direction = 1.0
        if self.mode == "once":
            if s >= total:
                return float(pts[-1, 0]), float(pts[-1, 1]), 0.0, 0.0
        elif self.mode == "loop":
            s %= total
        else:  # bounce: the route forwards then backwards
            s %= 2.0 * total
            if s > total:
                s = 2.0 * total - s
                direction = -1.0
        ends = np.cumsum(lengths)
        i = min(int(np.searchsorted(ends, s, side="right")), len(lengths) - 1)
        while lengths[i] == 0.0 and i > 0:
            i -= 1
        along = s - (ends[i] - lengths[i])
        unit = seg[i] / lengths[i]
        x, y = pts[i] + unit * along
        vx, vy = unit * self.speed * direction
        return float(x), float(y), float(vx), float(vy)
