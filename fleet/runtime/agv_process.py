"""One AGV on the bus: ``AgvNode`` fed by ``world/tick``, answering on its command key.

It runs until the world's final tick ends the run; a world that goes without
ending it is an error (see ``fleet.runtime.world_watch``), so an
AGV never waits forever and never calls an unfinished run a success. It
refuses to start when an AGV of its name is already on the bus, and ignores
(counting them on the bus, logged once) ticks that do not list exactly the
scenario's AGVs or that move the clock back. A tick sent again (the world
re-sends it after a lost link) gets the same answer again, without stepping the
node twice. If the node fails, the AGV reports it as failed, with why, before
its process ends.
"""

from __future__ import annotations

import queue

from bridge import keys
from bridge.bus import Bus
from bridge.messages import AgvCommand
from fleet.runtime.agv_node import AgvNode, NodeOutput, publish_output
from fleet.runtime.world_watch import WorldWatch
from fleet.scenario import Scenario
from planner.core.errors import BadInputError
from planner.core.status import FAILED

POLL_S = 0.05


class NameTaken(BadInputError):
    """Another process already runs an AGV of this name on this bus."""


def serve_agv(
    scenario: Scenario,
    name: str,
    bus: Bus,
    endpoint: str,
    grace: float,
    start_timeout: float = 60.0,
) -> int:
    """Answer ticks until the run ends; returns the number of ticks answered."""
    node = AgvNode(scenario, name)
    names = sorted(a.name for a in scenario.agvs)
    ticks = bus.subscribe(keys.WORLD_TICK)
    world = WorldWatch(bus, endpoint, grace, start_timeout)
    if bus.is_alive(keys.alive_agv(name)):
        raise NameTaken(f"an AGV named {name!r} is already on this bus")
    bus.declare_alive(keys.alive_agv(name))
    answered = 0
    last_tick, last_time, last_out = -1, 0.0, None
    listed_before: list[str] = []  # the names of the last valid tick, in its order
    while True:
        try:
            tick = ticks.get(timeout=POLL_S).msg
        except queue.Empty:
            world.check(last_time)
            continue
        if tick.final:
            return answered  # the run's end state: nothing to answer, the run is over
        if tick.tick == last_tick and last_out is not None:
            publish_output(bus.publish, last_out)  # a re-sent tick: the same answer
            continue
        listed = [s.name for s in tick.agvs]
        if (listed != listed_before and sorted(listed) != names) or tick.tick < last_tick:
            bus.count_invalid(keys.WORLD_TICK, f"tick {tick.tick} is not the next of this run")
            continue
        listed_before = listed
        last_tick, last_time = tick.tick, tick.time
        try:
            last_out = node.on_tick(tick)
        except Exception as err:  # said to the world (an event), then to the host
            why = f"its process crashed: {err!r}"[:200]
            failed = AgvCommand(name, tick.tick + 1, 0.0, 0.0, 0.0, FAILED, failure=why)
            publish_output(bus.publish, NodeOutput(failed))
            raise
        if last_out is not None:
            publish_output(bus.publish, last_out)
        answered += 1
