"""One AGV on the bus: ``AgvNode`` fed by ``world/tick``, answering on its state key.

It runs until the world's liveliness token goes away (the run ended, or the
world died), so an AGV never waits forever.
"""

from __future__ import annotations

import queue
import time

from bridge import keys
from bridge.bus import Bus
from fleet.runtime.agv_node import AgvNode, publish_output
from fleet.scenario import Scenario
from planner.errors import EnvironmentFailure

POLL_S = 0.05


class WorldGone(EnvironmentFailure):
    """The world never appeared, or went away without ending the run."""


def serve_agv(scenario: Scenario, name: str, bus: Bus, start_timeout: float = 60.0) -> int:
    """Answer ticks until the world is gone; returns the number of ticks answered."""
    node = AgvNode(scenario, name)
    ticks = bus.subscribe(keys.WORLD_TICK)
    world = bus.watch_alive(keys.alive_world())
    bus.declare_alive(keys.alive_agv(name))
    world_seen = False
    answered = 0
    started = time.monotonic()
    while True:
        try:
            while True:
                _, alive = world.get_nowait()
                if not alive:
                    return answered
                world_seen = True
        except queue.Empty:
            pass
        if not world_seen and time.monotonic() - started > start_timeout:
            raise WorldGone(f"no world appeared within {start_timeout:g} s")
        try:
            tick = ticks.get(timeout=POLL_S).msg
        except queue.Empty:
            continue
        if tick.final:
            continue  # the run's end state: the world's token goes next
        out = node.on_tick(tick)
        if out is not None:
            publish_output(bus.publish, out)
        answered += 1
