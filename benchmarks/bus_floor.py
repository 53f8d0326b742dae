"""The bus floor: how many lockstep ticks per second the bus allows when nobody plans.

One process per AGV, as in a real run: each opens a Zenoh client session to a router
in this process, decodes and validates every ``world/tick`` with ``bridge.bus`` and at
once answers with a stop command. This process publishes the scenario's first tick
again and again (its size is a real tick's), each time after every AGV has answered
the one before. What is left of a real run's tick time beyond this is the AGVs'
planning and the world's integration: ``fleet_bench`` prints the two side by side.

The AGV processes are forked by one host process (``python -m benchmarks.bus_floor``)
that imports only ``bridge`` and has no Zenoh session yet, as the AGV host of a real run
does. Spawning each (a fresh interpreter importing this benchmark) cost about a second of
CPU per AGV: 100 of them on 2 cores did not come up within the floor's wait.
"""

from __future__ import annotations

import contextlib
import os
import queue
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bridge import keys
from bridge.bus import Bus
from bridge.messages import AgvCommand
from bridge.session import fresh_endpoint, open_client, open_router

PREFIX = "bench/bus-floor"
WARM_UP_TICKS = 20
ANSWER_TIMEOUT_S = 30.0
START_S_PER_AGV = 1.0  # the wait for every AGV's first answer: 20 s plus this per AGV
ROOT = Path(__file__).resolve().parent.parent


class FloorError(RuntimeError):
    """The floor could not be measured (an AGV process did not answer)."""


def _answer_at_once(endpoint: str, name: str) -> None:
    """An AGV process that answers every tick with a stop, until the final tick."""
    bus = Bus(open_client(endpoint), PREFIX)
    ticks = bus.subscribe(keys.WORLD_TICK)
    while True:
        tick = ticks.get().msg
        if tick.final:
            return
        bus.publish(keys.agv_command(name), AgvCommand(name, tick.tick + 1, 0.0, 0.0, 0.0))


def _host(endpoint: str, names: list[str]) -> None:
    """Fork one answering process per AGV (no Zenoh session exists here) and wait."""
    children = []
    for name in names:
        pid = os.fork()
        if pid == 0:
            code = 1
            try:
                _answer_at_once(endpoint, name)
                code = 0
            finally:
                os._exit(code)
        children.append(pid)
    for pid in children:
        os.waitpid(pid, 0)


def bus_floor_ticks_per_s(tick, dt: float, ticks: int = 200) -> float:
    """Ticks per second of the lockstep over Zenoh with AGV processes that do not plan,
    ``tick`` (a real first tick) published again and again; FloorError if it cannot be
    measured."""
    names = [state.name for state in tick.agvs]
    with tempfile.TemporaryDirectory() as folder:
        endpoint = fresh_endpoint("unix", folder)
        bus = Bus(open_router(endpoint), PREFIX)
        commands = bus.subscribe("agv/*/command")
        host = subprocess.Popen(
            [sys.executable, "-m", "benchmarks.bus_floor", endpoint, *names],
            cwd=ROOT,
            start_new_session=True,
        )
        try:

            def one_tick(k: int, timeout: float, resend: float | None = None) -> None:
                tick.tick, tick.time = k, k * dt
                bus.publish(keys.WORLD_TICK, tick)
                answered: set[str] = set()
                deadline = sent = time.monotonic()
                deadline += timeout
                while len(answered) < len(names):
                    now = time.monotonic()
                    if now > deadline or host.poll() is not None:
                        raise FloorError(
                            f"{len(names) - len(answered)} of {len(names)} AGV processes of "
                            f"the bus floor did not answer tick {k} within {timeout:g} s"
                        )
                    if resend is not None and now - sent > resend:  # not all subscribed yet
                        bus.publish(keys.WORLD_TICK, tick)
                        sent = now
                    try:
                        msg = commands.get(timeout=0.1).msg
                    except queue.Empty:
                        continue
                    if msg.tick == k + 1:
                        answered.add(msg.name)

            one_tick(0, 20.0 + START_S_PER_AGV * len(names), resend=0.5)
            for k in range(1, WARM_UP_TICKS):
                one_tick(k, ANSWER_TIMEOUT_S)
            start = time.perf_counter()
            for k in range(WARM_UP_TICKS, WARM_UP_TICKS + ticks):
                one_tick(k, ANSWER_TIMEOUT_S)
            rate = ticks / (time.perf_counter() - start)
            tick.final = True
            bus.publish(keys.WORLD_TICK, tick)
            with contextlib.suppress(subprocess.TimeoutExpired):
                host.wait(10.0)
        finally:
            if host.poll() is None:
                os.killpg(host.pid, signal.SIGKILL)
                host.wait()
            bus.session.close()
    return rate


if __name__ == "__main__":
    _host(sys.argv[1], sys.argv[2:])
