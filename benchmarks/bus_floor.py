"""The bus floor: how many lockstep ticks per second the bus allows when nobody plans.

One process per AGV, as in a real run: each opens a Zenoh client session to a router
in this process, decodes and validates every ``world/tick`` with ``bridge.bus`` and at
once answers with a stop command. This process publishes the scenario's first tick
again and again (its size is a real tick's), each time after every AGV has answered
the one before. What is left of a real run's tick time beyond this is the AGVs'
planning and the world's integration: ``fleet_bench`` prints the two side by side.
"""

from __future__ import annotations

import multiprocessing
import queue
import tempfile
import time

from bridge import keys
from bridge.bus import Bus
from bridge.messages import AgvCommand
from bridge.session import fresh_endpoint, open_client, open_router
from fleet.runtime.world import World
from fleet.scenario import Scenario

PREFIX = "bench/bus-floor"
WARM_UP_TICKS = 20
ANSWER_TIMEOUT_S = 30.0


def _answer_at_once(endpoint: str, name: str, ready) -> None:
    """An AGV process that answers every tick with a stop, until the final tick."""
    bus = Bus(open_client(endpoint), PREFIX)
    ticks = bus.subscribe(keys.WORLD_TICK)
    ready.put(name)
    while True:
        tick = ticks.get().msg
        if tick.final:
            return
        bus.publish(keys.agv_command(name), AgvCommand(name, tick.tick + 1, 0.0, 0.0, 0.0))


def bus_floor_ticks_per_s(scenario: Scenario, ticks: int = 200) -> float:
    """Ticks per second of the lockstep over Zenoh with AGV processes that do not plan."""
    tick = World(scenario).first_tick()
    names = [state.name for state in tick.agvs]
    with tempfile.TemporaryDirectory() as folder:
        endpoint = fresh_endpoint("unix", folder)
        # spawned: a process forked from one that has run Zenoh cannot open a session
        spawned = multiprocessing.get_context("spawn")
        ready = spawned.Queue()
        processes = [
            spawned.Process(target=_answer_at_once, args=(endpoint, name, ready), daemon=True)
            for name in names
        ]
        for process in processes:
            process.start()
        try:
            bus = Bus(open_router(endpoint), PREFIX)
            commands = bus.subscribe("agv/*/command")
            for _ in names:
                ready.get(timeout=ANSWER_TIMEOUT_S)
            time.sleep(1.0)  # every subscription has reached the router

            def one_tick(k: int) -> None:
                tick.tick, tick.time = k, k * scenario.dt
                bus.publish(keys.WORLD_TICK, tick)
                answered = 0
                while answered < len(names):
                    answered += commands.get(timeout=ANSWER_TIMEOUT_S).msg.tick == k + 1

            for k in range(WARM_UP_TICKS):
                one_tick(k)
            start = time.perf_counter()
            for k in range(WARM_UP_TICKS, WARM_UP_TICKS + ticks):
                one_tick(k)
            rate = ticks / (time.perf_counter() - start)
            tick.final = True
            bus.publish(keys.WORLD_TICK, tick)
            bus.session.close()
        except queue.Empty:
            raise RuntimeError("an AGV process of the bus floor did not answer") from None
        finally:
            for process in processes:
                process.join(2.0)
                if process.is_alive():
                    process.terminate()
    return rate
