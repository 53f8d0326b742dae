"""The recorder tap: every message of a run's bus, as it came, into one MCAP file.

It subscribes to everything under the run prefix before tick 0 (the world
waits for its liveliness token), stores valid payloads without re-encoding
them at their simulated time (invalid ones are counted by the bus; the
counts, if any, go into the ``result`` metadata as ``invalid_messages``; a message
sent again after a lost link is stored once), and ends on the run's last message,
``world/result``: it then writes the run's result (from ``world/result``) and the footer. A
world gone without a result leaves a file without one. If it is killed, the
completed chunks stay readable (see recordings.writer).
"""

from __future__ import annotations

import json
import math
import queue

from bridge import keys
from bridge.bus import Bus
from bridge.wire import json_payload
from fleet.runtime.world_watch import WorldWatch
from recordings.writer import RecordingWriter

POLL_S = 0.1


def _result(summary: str) -> dict | None:
    try:
        result = json.loads(summary)
    except (ValueError, RecursionError):
        return None
    return result if isinstance(result, dict) else None


def serve_recorder(
    bus: Bus, writer: RecordingWriter, dt: float, endpoint: str, grace: float
) -> int:
    """Record until the world ended the run and left; returns the number of messages
    recorded. A world gone without ending it (see fleet.runtime.world_watch) closes the
    file without a result and raises WorldGone."""
    dt_ns = round(dt * 1e9)
    messages = bus.subscribe("**")
    world = WorldWatch(bus, endpoint, grace, start_timeout=math.inf)
    bus.declare_alive(keys.alive_recorder())
    result = None
    last: dict[str, bytes] = {}  # per key, what was stored last
    count = 0
    at = 0.0
    try:
        while True:
            try:
                received = messages.get(timeout=POLL_S)
            except queue.Empty:
                writer.flush_if_due()
                world.check(at)
                continue
            if last.get(received.key) == received.payload:
                continue  # sent again after a lost link: stored once
            last[received.key] = received.payload
            tick = getattr(received.msg, "tick", 0)
            at = max(at, tick * dt)
            payload = json_payload(received.key, received.payload)  # recordings are JSON
            writer.write_payload(received.key, payload, tick * dt_ns)
            count += 1
            if received.key == keys.WORLD_RESULT:  # the run's last message
                result = _result(received.msg.summary)
                break
    finally:
        if result is not None:
            if bus.invalid:  # else the same result as a run in process
                result["invalid_messages"] = dict(bus.invalid)
            writer.finish(result)
        else:
            writer.close()
    return count
