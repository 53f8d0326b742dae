"""The recorder tap: every message of a run's bus, as it came, into one MCAP file.

It subscribes to everything under the run prefix before tick 0 (the world
waits for its liveliness token), stores valid payloads without re-encoding
them at their simulated time (invalid ones are counted by the bus; the
counts, if any, go into the ``result`` metadata as ``invalid_messages``), and ends
when the world's token goes: it then writes the run's result (from
``world/result``) and the footer. If it is killed, the
completed chunks stay readable (see recordings.writer).
"""

from __future__ import annotations

import json
import queue

from bridge import keys
from bridge.bus import Bus
from recordings.writer import RecordingWriter

POLL_S = 0.1


def _result(summary: str) -> dict | None:
    try:
        result = json.loads(summary)
    except (ValueError, RecursionError):
        return None
    return result if isinstance(result, dict) else None


def serve_recorder(bus: Bus, writer: RecordingWriter, dt: float) -> int:
    """Record until the world is gone; returns the number of messages recorded."""
    dt_ns = round(dt * 1e9)
    messages = bus.subscribe("**")
    world = bus.watch_alive(keys.alive_world())
    bus.declare_alive(keys.alive_recorder())
    result = None
    world_seen = world_gone = False
    count = 0
    while True:
        try:
            while True:
                _, alive = world.get_nowait()
                world_seen |= alive
                world_gone |= world_seen and not alive
        except queue.Empty:
            pass
        try:
            received = messages.get(timeout=POLL_S)
        except queue.Empty:
            writer.flush_if_due()
            if world_gone:  # nothing more in flight: the world closed its session
                break
            continue
        tick = getattr(received.msg, "tick", 0)
        writer.write_payload(received.key, received.payload, tick * dt_ns)
        count += 1
        if received.key == keys.WORLD_RESULT:
            result = _result(received.msg.summary)
    if result is not None:
        if bus.invalid:  # else the same result as a run in process
            result["invalid_messages"] = dict(bus.invalid)
        writer.finish(result)
    else:
        writer.close()
    return count
