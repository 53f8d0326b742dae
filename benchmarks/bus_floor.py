"""The bus floors: how many lockstep ticks per second the bus allows when nobody plans.

One process per AGV, as in a real run: each opens a Zenoh client session to a router
in this process and answers every ``world/tick`` at once, in Zenoh's receiving thread
as a real AGV does (``Bus.listen(direct=True)``). This process publishes the
scenario's first tick again and again (its size is a real tick's), each time after
every AGV has answered the one before. Two floors:

- the *bus* floor: each AGV decodes and validates the tick with ``bridge.bus`` and
  answers with an encoded stop command; what is left of a real run's tick time beyond
  this is the AGVs' planning and the world's integration (``fleet_bench`` prints them
  side by side);
- the *Zenoh* floor (``raw=True``): the same bytes, but nobody decodes or encodes
  anything: each AGV puts a command's bytes back as soon as a tick's bytes arrive, and
  this process only counts them. It is what zenoh-python itself costs per round trip,
  the ceiling of any protocol on this machine; the gap between the two floors is the
  project's codec and checks.

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
import threading
import time
from pathlib import Path

import zenoh

from bridge import keys
from bridge.bus import Bus, Received
from bridge.messages import AgvCommand
from bridge.session import fresh_endpoint, open_client, open_router
from bridge.wire import to_wire

PREFIX = "bench/bus-floor"
WARM_UP_TICKS = 20
ANSWER_TIMEOUT_S = 30.0
START_S_PER_AGV = 1.0
RESEND_SETTLE_S = 1.0  # the wait for every AGV's first answer: 20 s plus this per AGV
ROOT = Path(__file__).resolve().parent.parent


class FloorError(RuntimeError):
    """The floor could not be measured (an AGV process did not answer)."""


def _answer_at_once(endpoint: str, name: str, raw: bool) -> None:
    """An AGV process that answers every tick with a stop, until the final tick (raw: an
    empty payload)."""
    bus = Bus(open_client(endpoint), PREFIX)
    key = keys.agv_command(name)
    over = threading.Event()
    if raw:
        stop = to_wire(key, AgvCommand(name, 1, 0.0, 0.0, 0.0))

        def answer_bytes(sample: zenoh.Sample) -> None:
            if len(sample.payload) == 0:
                over.set()
            else:
                bus.publish_payload(key, stop)

        handler = zenoh.handlers.Callback(answer_bytes, indirect=False)
        subscriber = bus.session.declare_subscriber(bus.full(keys.WORLD_TICK), handler)
    else:

        def answer(received: Received) -> None:
            tick = received.msg
            if tick.final:
                over.set()
            else:
                bus.publish(key, AgvCommand(name, tick.tick + 1, 0.0, 0.0, 0.0))

        bus.listen(keys.WORLD_TICK, answer, direct=True)
    over.wait()
    if raw:
        subscriber.undeclare()


def _host(endpoint: str, raw: bool, names: list[str]) -> None:
    """Fork one answering process per AGV (no Zenoh session exists here) and wait."""
    children = []
    for name in names:
        pid = os.fork()
        if pid == 0:
            code = 1
            try:
                _answer_at_once(endpoint, name, raw)
                code = 0
            finally:
                os._exit(code)
        children.append(pid)
    for pid in children:
        os.waitpid(pid, 0)


def bus_floor_ticks_per_s(tick, dt: float, ticks: int = 200, raw: bool = False) -> float:
    """Ticks per second of the lockstep over Zenoh with AGV processes that do not plan,
    ``tick`` (a real first tick) published again and again (``raw``: its bytes, neither
    decoded nor checked: the Zenoh floor); FloorError if it cannot be measured."""
    names = [state.name for state in tick.agvs]
    with tempfile.TemporaryDirectory() as folder:
        endpoint = fresh_endpoint("unix", folder)
        bus = Bus(open_router(endpoint), PREFIX)
        commands: queue.SimpleQueue = queue.SimpleQueue()  # (name, tick answered: None raw)
        if raw:
            subscriber = bus.session.declare_subscriber(
                bus.full("agv/*/command"),
                lambda sample: commands.put((str(sample.key_expr), None)),
            )
        else:
            bus.listen("agv/*/command", lambda got: commands.put((got.msg.name, got.msg.tick)))
        host = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "benchmarks.bus_floor",
                endpoint,
                "raw" if raw else "bus",
                *names,
            ],
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
                        name, answered_tick = commands.get(timeout=0.1)
                    except queue.Empty:
                        continue
                    if answered_tick in (None, k + 1):
                        answered.add(name)

            one_tick(0, 20.0 + START_S_PER_AGV * len(names), resend=0.5)
            time.sleep(RESEND_SETTLE_S)  # a raw answer names no tick: drop those to resends
            with contextlib.suppress(queue.Empty):
                while True:
                    commands.get_nowait()
            for k in range(1, WARM_UP_TICKS):
                one_tick(k, ANSWER_TIMEOUT_S)
            start = time.perf_counter()
            for k in range(WARM_UP_TICKS, WARM_UP_TICKS + ticks):
                one_tick(k, ANSWER_TIMEOUT_S)
            rate = ticks / (time.perf_counter() - start)
            tick.final = True
            if raw:
                bus.publish_payload(keys.WORLD_TICK, b"")
            else:
                bus.publish(keys.WORLD_TICK, tick)
            with contextlib.suppress(subprocess.TimeoutExpired):
                host.wait(10.0)
            if raw:
                subscriber.undeclare()
        finally:
            if host.poll() is None:
                os.killpg(host.pid, signal.SIGKILL)
                host.wait()
            bus.session.close()
    return rate


if __name__ == "__main__":
    _host(sys.argv[1], sys.argv[2] == "raw", sys.argv[3:])
