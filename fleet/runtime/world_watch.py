"""Whether the world is still there, for a process that serves it (an AGV, the recorder).

An AGV leaves on the run's final tick, the recorder on its result, and the world
waits for them to leave before its liveliness token goes; so a token that goes
while one of them still waits means the run did not end for it. Either the
world's endpoint now refuses connections: nothing listens there any more (its
process died) and the run is over at once; or the link may come back (a Zenoh
client reconnects by itself) and the process waits up to the grace period, as
the world waits for it.
"""

from __future__ import annotations

import queue
import time

from bridge import keys
from bridge.bus import Bus
from bridge.session import refuses
from planner.core.errors import EnvironmentFailure

PROBE_EVERY_S = 0.5
# how long a lost link may last before the world fails an AGV (and an AGV or the
# recorder gives up on the world): long enough for a network to recover
DEFAULT_GRACE_S = 10.0


class WorldGone(EnvironmentFailure):
    """The world never appeared, or went away without ending the run."""


class WorldWatch:
    def __init__(self, bus: Bus, endpoint: str, grace: float, start_timeout: float):
        self.endpoint = endpoint
        self.grace = grace
        self.start_timeout = start_timeout
        self._tokens = bus.watch_alive(keys.alive_world())
        self._started = time.monotonic()
        self._seen = False
        self._lost_since: float | None = None
        self._probed = 0.0

    def check(self, at: float) -> None:
        """Call when no message is waiting. The run's last message ends a caller's loop
        before the world leaves, so a world that left raises WorldGone: without ending the
        run (``at``: the simulated time reached), or it never came."""
        try:
            while True:
                _, alive = self._tokens.get_nowait()
                self._seen |= alive
                if alive:
                    self._lost_since = None
                elif self._lost_since is None:
                    self._lost_since = time.monotonic()
        except queue.Empty:
            pass
        now = time.monotonic()
        if not self._seen:
            if now - self._started > self.start_timeout:
                raise WorldGone(f"no world appeared within {self.start_timeout:g} s")
            return
        if self._lost_since is None:
            return
        if now - self._probed > PROBE_EVERY_S:
            self._probed = now
            if refuses(self.endpoint):
                raise WorldGone(
                    f"the world went away at t = {at:.1f} s without ending the run "
                    f"(nothing listens at {self.endpoint} any more)"
                )
        if now - self._lost_since > self.grace:
            raise WorldGone(f"lost the world at t = {at:.1f} s for more than {self.grace:g} s")
