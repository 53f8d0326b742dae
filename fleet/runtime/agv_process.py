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

A tick is answered in Zenoh's receiving thread as it arrives (``TickAnswers``), not
handed through a queue to the main thread: one thread woken per tick instead of two,
on the path every tick of the lockstep waits for (on 2 busy cores, a woken thread
waits its turn). The main thread only watches the world (``WorldWatch``) until the
run is over.

An AGV a shift holds at its goal (``loading``, ``parked``: ``HELD``) answers nothing
and the world waits for nobody held (``World.awaited``). ``HeldTicks`` drops such a
tick after every check of the bus and before it is copied into a ``Tick``: idle AGVs
cost a decode per tick, no more. Only the next tick of the run that lists exactly the
AGVs of the last one taken is dropped; any other is decided on as before.
"""

from __future__ import annotations

import threading

from bridge import keys
from bridge.bus import Bus, Received
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
    answers = TickAnswers(AgvNode(scenario, name), bus, sorted(a.name for a in scenario.agvs))
    world = WorldWatch(bus, endpoint, grace, start_timeout)
    if bus.is_alive(keys.alive_agv(name)):
        raise NameTaken(f"an AGV named {name!r} is already on this bus")
    bus.listen(keys.WORLD_TICK, answers, drop=answers.held, direct=True)  # before the token:
    bus.declare_alive(keys.alive_agv(name))  # see WorldServer._wait_for_agvs
    while not answers.over.wait(POLL_S):
        world.check(answers.last_time)
    if answers.error is not None:
        raise answers.error
    return answers.answered


class TickAnswers:
    """An AGV's answers to the ticks, given in Zenoh's receiving thread (see the module
    docstring); ``over`` is set on the run's final tick, or when the node failed
    (``error``: what it raised, after its failure went to the world)."""

    def __init__(self, node: AgvNode, bus: Bus, names: list[str]):
        self.node = node
        self.bus = bus
        self.names = names  # the scenario's AGVs, sorted
        self.held = HeldTicks(node.name)
        self.over = threading.Event()
        self.error: BaseException | None = None
        self.answered = 0
        self.last_tick, self.last_time, self.last_out = -1, 0.0, None
        self.listed: list[str] = []  # the names of the last valid tick, in its order
        self._lock = threading.Lock()  # one tick at a time, whatever thread Zenoh calls in

    def __call__(self, received: Received) -> None:
        with self._lock:
            if not self.over.is_set():
                self._answer(received.msg)

    def _answer(self, tick) -> None:
        bus, name = self.bus, self.node.name
        if tick.final:
            self.over.set()  # the run's end state: nothing to answer, the run is over
            return
        if tick.tick == self.last_tick and self.last_out is not None:
            publish_output(bus.publish, self.last_out)  # a re-sent tick: the same answer
            return
        listed = [s.name for s in tick.agvs]
        if (listed != self.listed and sorted(listed) != self.names) or tick.tick < self.last_tick:
            bus.count_invalid(keys.WORLD_TICK, f"tick {tick.tick} is not the next of this run")
            return
        self.listed = listed
        self.last_tick, self.last_time = tick.tick, tick.time
        self.held.took(tick.tick, listed)
        try:
            self.last_out = self.node.on_tick(tick)
        except Exception as err:  # said to the world (an event), then to the host
            why = f"its process crashed: {err!r}"[:200]
            failed = AgvCommand(name, tick.tick + 1, 0.0, 0.0, 0.0, FAILED, failure=why)
            publish_output(bus.publish, NodeOutput(failed))
            self.error = err
            self.over.set()
            return
        if self.last_out is not None:
            publish_output(bus.publish, self.last_out)
        self.answered += 1


class HeldTicks:
    """The ticks an AGV drops unread: see the module docstring. Called with each valid
    tick (a Struct with the fields of ``Tick``) before it is made; told each tick taken
    (``took``)."""

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
