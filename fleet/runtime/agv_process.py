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

An AGV a shift holds at its goal (``loading``, ``parked``: ``HELD``) answers nothing
and the world waits for nobody held (``World.awaited``); yet every tick still woke its
process twice, the receiving thread to decode it and the main thread to find itself
held. ``HeldTicks`` drops such a tick in the receiving thread, after every check of
the bus and before it is copied into a ``Tick``: idle AGVs cost a decode per tick, no
more. Only the next tick of the run that lists exactly the AGVs of the last one taken
is dropped; any other goes to the main loop, which decides as before.
"""

from __future__ import annotations

import queue

from bridge import keys
from bridge.bus import Bus
from bridge.messages import AgvCommand
from fleet.runtime.agv_node import AgvNode, NodeOutput, publish_output
from fleet.runtime.world import HELD
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
    held = HeldTicks(name)
    ticks = bus.subscribe(keys.WORLD_TICK, drop=held)
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
        held.took(tick.tick, listed)
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


class HeldTicks:
    """The ticks an AGV drops unread: see the module docstring. Called in Zenoh's
    receiving thread with each valid tick (a Struct with the fields of ``Tick``); the
    main loop tells it each tick it took (``took``)."""

    def __init__(self, name: str):
        self.name = name
        self.last = -1  # the last tick taken or dropped
        # the AGVs of the last tick taken, in its order, and this one's place in them
        # (one value: the receiving thread never sees one without the other)
        self.view: tuple[tuple[str, ...], int] = ((), -1)
        self.dropped = 0

    def took(self, tick: int, listed: list[str]) -> None:
        if tuple(listed) != self.view[0]:
            self.view = (tuple(listed), listed.index(self.name) if self.name in listed else -1)
        self.last = max(self.last, tick)

    def __call__(self, tick) -> bool:
        """Whether to drop ``tick``: the run's next, listing the same AGVs, and holding this
        one at its goal (its node would answer nothing: ``AgvNode.on_tick``)."""
        listed, index = self.view
        agvs = tick.agvs
        if (
            tick.final
            or tick.tick != self.last + 1
            or index < 0
            or len(agvs) != len(listed)
            or agvs[index].status not in HELD
            or any(a.name != n for a, n in zip(agvs, listed, strict=True))
        ):
            return False
        self.last = tick.tick
        self.dropped += 1
        return True
