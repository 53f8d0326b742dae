"""Watching a run in Foxglove: ``agv-fleet run --foxglove`` and ``replay --foxglove``.

Both serve the recording's channels (``recordings.channels``) over the Foxglove
WebSocket protocol (``recordings.foxglove_server``): a live run is fed message by
message from the same tap the Rerun live view uses, dated as the recorder dates them
(the run's wall-clock start plus sim time); a replay sends a recording's messages at
their recorded log times, paced at ``rate`` x real time.
"""

from __future__ import annotations

import sys
import time

from bridge.messages import encode
from recordings.channels import ChannelMessages
from recordings.foxglove_server import DEFAULT_PORT, FoxgloveServer

__all__ = ["DEFAULT_PORT", "FoxgloveLive", "serve_recording"]


class FoxgloveLive:
    """A run's sink, ``sink(key, msg)``: every bus message and what Foxglove's channels
    make of it, served on ``host:port``. A context manager; ``hold()`` after the run
    keeps serving until Ctrl-C."""

    def __init__(self, dt: float, *, host: str = "127.0.0.1", port: int = DEFAULT_PORT,
                 notify=sys.stderr):  # fmt: skip
        self._server = FoxgloveServer(host, port)
        self._outbox = ChannelMessages()
        self._dt_ns = round(dt * 1e9)
        self._notify = notify
        self.log_time_zero_ns = time.time_ns()

    def __enter__(self) -> FoxgloveLive:
        self._server.__enter__()
        print(f"Foxglove WebSocket: {self._server.url}", file=self._notify, flush=True)
        return self

    def __exit__(self, *exc) -> None:
        self._server.__exit__(*exc)

    def __call__(self, key: str, msg) -> None:
        log_time = self.log_time_zero_ns + getattr(msg, "tick", 0) * self._dt_ns
        for topic, payload in self._outbox.of(key, encode(msg), log_time):
            self._server.publish(topic, payload, log_time)

    def hold(self) -> None:
        _hold(self._server, self._notify)


def serve_recording(
    recording, *, rate: float = 1.0, host: str = "127.0.0.1", port: int = DEFAULT_PORT,
    notify=sys.stderr,
) -> None:  # fmt: skip
    """Serve a recording's messages on their recorded channels, at ``rate`` x real time,
    then keep serving (every channel's last message) until Ctrl-C."""
    with FoxgloveServer(host, port) as server:
        print(f"Foxglove WebSocket: {server.url}", file=notify, flush=True)
        messages = recording.messages
        if messages:
            first = messages[0].log_time_ns
            started = time.monotonic()
            for message in messages:
                due = started + (message.log_time_ns - first) / 1e9 / rate
                wait = due - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
                server.publish(message.topic, message.payload, message.log_time_ns)
        _hold(server, notify)


def _hold(server: FoxgloveServer, notify) -> None:
    try:
        print("serving Foxglove; Ctrl-C to stop", file=notify, flush=True)
        server.wait()
    except KeyboardInterrupt:
        return
