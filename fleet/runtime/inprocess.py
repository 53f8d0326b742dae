"""All nodes in one process, no bus: fast and deterministic (``--in-process``)."""

from __future__ import annotations

import json
import time
from collections.abc import Callable

from bridge import keys
from bridge.messages import ResultMsg
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.summary import RunSummary, summarize
from fleet.runtime.world import World, map_message
from fleet.scenario import Scenario

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
    if sink:
        sink(keys.WORLD_MAP, map_message(scenario.grid))
    tick = world.first_tick()
    while tick is not None:
        if sink:
            sink(keys.WORLD_TICK, tick)
        replies = {}
        for name in world.live_agvs():
            out = nodes[name].on_tick(tick)
            replies[name] = out.state
            if sink:
                sink(keys.agv_state(name), out.state)
                if out.plan:
                    sink(keys.agv_plan(name), out.plan)
                if out.trajectory:
                    sink(keys.agv_trajectory(name), out.trajectory)
        tick = world.advance(replies)
        events = world.drain_events()
        if sink:
            for event in events:
                sink(keys.WORLD_EVENT, event)
            if tick is None:
                sink(keys.WORLD_TICK, world.final_tick())
        if progress:
            progress(world)
    summary = summarize(world, time.perf_counter() - t0)
    if sink:
        sink(keys.WORLD_RESULT, ResultMsg(json.dumps(summary.to_json())))
    return summary
