"""All nodes in one process, no bus: fast and deterministic (``--in-process``)."""

from __future__ import annotations

import time
from collections.abc import Callable

from fleet.agv_node import AgvNode
from fleet.scenario import Scenario
from fleet.summary import RunSummary, summarize
from fleet.world import World

# called with (bus key below the run prefix, message) for every message of the run
Sink = Callable[[str, object], None]


def run_in_process(
    scenario: Scenario,
    sink: Sink | None = None,
    progress: Callable[[World], None] | None = None,
) -> RunSummary:
    t0 = time.perf_counter()
    world = World(scenario)
    nodes = {a.name: AgvNode(scenario, a.name) for a in scenario.agvs}
    tick = world.first_tick()
    while tick is not None:
        if sink:
            sink("world/tick", tick)
        replies = {}
        for name in world.live_agvs():
            out = nodes[name].on_tick(tick)
            replies[name] = out.state
            if sink:
                sink(f"agv/{name}/state", out.state)
                if out.plan:
                    sink(f"agv/{name}/plan", out.plan)
                if out.trajectory:
                    sink(f"agv/{name}/trajectory", out.trajectory)
        tick = world.advance(replies)
        if sink:
            for event in world.events:
                sink("world/event", event)
        if progress:
            progress(world)
    return summarize(world, time.perf_counter() - t0)
