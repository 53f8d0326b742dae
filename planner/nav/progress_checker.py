"""Whether the AGV still makes progress (Nav2's ``ProgressChecker``).

Progress is the remaining route length (to the current target, then along the key nodes
to the goal), not the distance moved: an AGV circling a key node moves but comes no
nearer. The checker keeps the best remaining length seen and when it was seen; the AGV
has stalled when that best has not dropped by ``distance`` for ``window`` seconds.
"""

from __future__ import annotations

import math


class ProgressChecker:
    """The best remaining route length so far and the time it was last bettered."""

    def __init__(self, window: float, distance: float):
        self.window = window  # s without progress that make a stall
        self.distance = distance  # m the remaining route must shrink by to count
        self.best = math.inf
        self.since = 0.0  # sim time the best was last bettered (or progress last excused)

    def check(self, remaining: float, now: float) -> bool:
        """Whether ``remaining`` is progress: shorter than the best by ``distance``; it
        becomes the new best."""
        if remaining < self.best - self.distance:
            self.best, self.since = remaining, now
            return True
        return False

    def stalled(self, now: float) -> bool:
        """No progress for ``window`` seconds up to ``now``."""
        return now - self.since >= self.window

    def excuse(self, now: float, remaining: float | None = None) -> None:
        """Count ``now`` as progress (turning on the spot, waiting where the traffic rule
        holds the AGV); with ``remaining``, keep the best no longer than it."""
        self.since = now
        if remaining is not None:
            self.best = min(self.best, remaining)

    def restart(self, best: float, since: float | None = None) -> None:
        """Measure anew from ``best`` (a new route's length, or inf), from ``since`` when
        given (a recovery's end: its time is not a stall)."""
        self.best = best
        if since is not None:
            self.since = since
