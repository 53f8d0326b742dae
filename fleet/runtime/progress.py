"""Progress lines on stderr while a run goes: sim time and AGVs done."""

from __future__ import annotations

import sys
import time

from fleet.runtime.world import World
from fleet.scenario import Scenario
from planner.core.status import ARRIVED, FAILED


class Progress:
    """Prints at most every ``interval`` seconds of wall time, to stderr."""

    def __init__(self, scenario: Scenario, interval: float = 1.0, stream=None):
        self.scenario = scenario
        self.interval = interval
        self.stream = stream or sys.stderr
        self._last = time.monotonic()
        self._tty = self.stream.isatty()

    def __call__(self, world: World) -> None:
        now = time.monotonic()
        if now - self._last < self.interval and not world.ended:
            return
        self._last = now
        arrived = sum(r.status == ARRIVED for r in world.records.values())
        failed = sum(r.status == FAILED for r in world.records.values())
        line = (
            f"t={world.time:7.1f}/{self.scenario.time_limit:g} s  tick {world.tick}  "
            f"arrived {arrived}/{len(world.records)}"
            + (f"  failed {failed}" if failed else "")
            + f"  collisions {world.collisions}"
        )
        end = "\r" if self._tty and not world.ended else "\n"
        print(line.ljust(70), end=end, file=self.stream, flush=True)
