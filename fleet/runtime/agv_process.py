"""One AGV on the bus: ``AgvNode`` fed by ``world/tick``, answering on its command key.

It runs until the world's liveliness token goes away (the run ended, or the
world died), so an AGV never waits forever. It refuses to start when an AGV of
its name is already on the bus, and ignores (counting them on the bus, logged
once) ticks that do not list exactly the scenario's AGVs or that do not move
the clock forward.
"""

from __future__ import annotations

import queue
import time

from bridge import keys
from bridge.bus import Bus
from fleet.runtime.agv_node import AgvNode, publish_output
from fleet.scenario import Scenario
from planner.errors import BadInputError, EnvironmentFailure

POLL_S = 0.05


class WorldGone(EnvironmentFailure):
    """The world never appeared, or went away without ending the run."""


class NameTaken(BadInputError):
    """Another process already runs an AGV of this name on this bus."""


def serve_agv(scenario: Scenario, name: str, bus: Bus, start_timeout: float = 60.0) -> int:
    """Answer ticks until the world is gone; returns the number of ticks answered."""
    node = AgvNode(scenario, name)
    names = sorted(a.name for a in scenario.agvs)
    ticks = bus.subscribe(keys.WORLD_TICK)
    world = bus.watch_alive(keys.alive_world())
    if bus.is_alive(keys.alive_agv(name)):
        raise NameTaken(f"an AGV named {name!r} is already on this bus")
    bus.declare_alive(keys.alive_agv(name))
    world_seen = False
    answered = 0
    last_tick = -1
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
        if sorted(s.name for s in tick.agvs) != names or tick.tick <= last_tick:
            bus.count_invalid(keys.WORLD_TICK, f"tick {tick.tick} is not the next of this run")
            continue
        last_tick = tick.tick
        out = node.on_tick(tick)
        if out is not None:
            publish_output(bus.publish, out)
        answered += 1
