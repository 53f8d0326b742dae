"""The recoveries of a stalled AGV as one sequence (Nav2's recovery subtree: clear the
costmap, spin, back up, wait), bounded: when it runs out without progress the AGV fails.

Each stall starts the next recovery of ``RECOVERIES`` (``planner.nav.recovery``). With
another AGV near, a back-off or rotation is a wait instead: the others plan too, and
moving into their room only pushes them. An AGV that had another near at one of the
sequence's stalls is in a jam of AGVs, not at a dead end, and starts the sequence again
(``JAM_RESTARTS`` times) before it fails. Progress kept up for ``CALM_WINDOWS`` progress
windows after the last stall starts the sequence from its first recovery again; coming
back to where the sequence has been is no progress (``planner.nav.old_ground``).
"""

from __future__ import annotations

import math

import numpy as np

from planner.core.status import BACK_OFF, ROTATE, WAIT
from planner.local.yielding import agvs_of
from planner.maps.grid import Point
from planner.nav.old_ground import OldGround
from planner.nav.recovery import DURATION_S, RECOVERIES, Recovery

CALM_WINDOWS = 3
"""Progress windows without a stall after which the recoveries start again from the first:
a stall that far after the last is a new obstacle, not the old one still in the way."""

JAM_RANGE = 2.0
"""m, centre to centre: another AGV this near at a stall means a jam of AGVs (they clear
as the others move on), not a dead end."""

JAM_RESTARTS = 2
"""How many times a jammed AGV's sequence starts again before it fails: each run of the
sequence gives the others its whole length (about half a minute) to move on."""

END_SLACK = 1e-9
"""s: a recovery ends at its end time despite float rounding of the sim clock."""


class RecoverySequence:
    """Which recoveries this stall sequence has run, and the one running now."""

    def __init__(self, progress_window: float, progress_distance: float):
        self.progress_window = progress_window
        self.ground = OldGround(progress_distance)  # where the sequence has been
        self.run: list[str] = []  # the kinds this sequence has started
        self.jam_restarts = 0  # sequences started again in a jam
        self.jammed = False  # another AGV was near at a stall of this sequence
        self.last_stall = -math.inf  # sim time of the last stall
        self.active: Recovery | None = None  # a timed recovery being driven

    def progressed(self, now: float) -> None:
        """The AGV made progress at ``now``: long enough after the last stall, the next
        stall starts a new sequence."""
        if now - self.last_stall >= CALM_WINDOWS * self.progress_window:
            self.run, self.jam_restarts = [], 0
            self.jammed = False
            self.ground.clear()

    def next(self, now: float, position: Point, agv_near: bool) -> str | None:
        """The recovery to start at the stall at ``now`` and ``position`` (``agv_near``:
        another AGV within ``JAM_RANGE``); None when the sequence has run out: the AGV fails."""
        self.last_stall = now
        self.ground.stall(position)
        self.jammed = self.jammed or agv_near
        exhausted = len(self.run) >= len(RECOVERIES)
        if exhausted and self.jammed and self.jam_restarts < JAM_RESTARTS:
            self.jam_restarts += 1
            self.run, self.jammed = [], False
        elif exhausted:
            return None
        kind = RECOVERIES[len(self.run)]
        if kind in (BACK_OFF, ROTATE) and agv_near:
            kind = WAIT  # the others plan too: moving into their room only pushes them
        self.run.append(kind)
        if DURATION_S[kind] > 0:
            self.active = Recovery(kind, now + DURATION_S[kind])
        return kind

    def running(self, now: float) -> str | None:
        """The kind of the timed recovery still being driven at ``now``, or None (it ended)."""
        if self.active is not None and now < self.active.until - END_SLACK:
            return self.active.kind
        self.active = None
        return None


def agv_near(position: Point, moving, walkers) -> bool:
    """Whether another AGV (a moving disc that is not a walker) is within ``JAM_RANGE``."""
    agvs = agvs_of(moving, walkers)
    return bool((np.hypot(agvs[:, 0] - position[0], agvs[:, 1] - position[1]) < JAM_RANGE).any())
