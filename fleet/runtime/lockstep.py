"""The lockstep clock of a run, written once for both modes.

Tick k goes out; every live AGV answers for tick k+1; the world advances and
its events go out; at the end the final tick and the result. In process the
answers come from a direct call (``fleet.runtime.inprocess``); over Zenoh they
are awaited on the bus (``fleet.runtime.world_server``). Both modes therefore
send the same messages in the same order, and their recordings are identical.

An *outbox* is any ``(key, message) -> None`` callable: the bus's ``publish``,
a recording sink, the live view, or a ``tee`` of several.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Protocol

from bridge import keys
from bridge.messages import AgvCommand, ResultMsg, Tick
from fleet.runtime.interrupts import interrupted, interrupts_deferred
from fleet.runtime.summary import RunSummary, summarize
from fleet.runtime.world import World, map_message

Outbox = Callable[[str, object], None]


class Collector(Protocol):
    def __call__(self, tick: Tick, world: World) -> dict[str, AgvCommand]:
        """Every live AGV's command answering ``tick``, by name (missing: no answer)."""


def tee(*outboxes: Outbox) -> Outbox:
    """One outbox that hands every message to each of ``outboxes`` in turn."""

    def publish(key: str, msg: object) -> None:
        for outbox in outboxes:
            outbox(key, msg)

    return publish


def run_lockstep(
    world: World,
    collect: Collector,
    outbox: Outbox,
    *,
    after_tick: Callable[[World], None] | None = None,
) -> RunSummary:
    """Run ``world`` to its end; ``after_tick(world)`` runs after every tick (progress,
    pacing, the live view). Ctrl-C or SIGTERM (inside ``interrupts_raised``) ends the run at
    the tick it comes in, with its final tick and result (end reason "interrupted"); the
    caller raises ``KeyboardInterrupt`` once the run's messages are out."""
    t0 = time.perf_counter()
    outbox(keys.WORLD_MAP, map_message(world.scenario.grid))
    tick = world.first_tick()
    with interrupts_deferred():
        while tick is not None:
            commands = {}
            if not interrupted():
                outbox(keys.WORLD_TICK, tick)
                commands = collect(tick, world)
            if interrupted():  # Ctrl-C: the run ends at this tick, as any run ends
                world.interrupt()
                tick = None
            else:
                tick = world.advance(commands)
            for event in world.drain_events():
                outbox(keys.WORLD_EVENT, event)
            if tick is None:
                outbox(keys.WORLD_TICK, world.final_tick())
            if after_tick and not interrupted():
                after_tick(world)
    summary = summarize(world, time.perf_counter() - t0)
    outbox(keys.WORLD_RESULT, ResultMsg(json.dumps(summary.to_json())))
    return summary
