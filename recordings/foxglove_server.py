"""A Foxglove WebSocket server (subprotocol ``foxglove.websocket.v1``) for a run's channels.

Written on the ``websockets`` library rather than Foxglove's own ``foxglove-sdk``: the
SDK's server (0.30) speaks only the newer ``foxglove.sdk.v1`` subprotocol, which
Lichtblick and older Foxglove releases do not; ``foxglove.websocket.v1`` is the one
every Foxglove-protocol viewer connects with. What a viewer needs of it is small: the
server sends ``serverInfo`` and ``advertise`` (a channel per topic, with its schema),
the client sends ``subscribe`` / ``unsubscribe``, and each message goes to its
subscribers as a binary frame: opcode 1, subscription id (uint32 LE), log time in ns
(uint64 LE), the JSON payload.

A viewer that connects late still sees the run: every channel keeps its last message
(Foxglove scene channels one per entity: an AGV's body, its plan) and sends it to a new
subscriber first, as a latched ROS topic does. The server runs its own asyncio loop in
a thread; ``publish`` may be called from any thread and never blocks: a client that
cannot keep up loses its oldest queued messages, not the run its pace.
"""

from __future__ import annotations

import asyncio
import json
import struct
import threading
import time
from collections import deque
from dataclasses import dataclass, field

from websockets.asyncio.server import ServerConnection, serve
from websockets.exceptions import ConnectionClosed

from planner.core.errors import EnvironmentFailure
from recordings.channels import MESSAGE_ENCODING, SCHEMA_ENCODING, channel_schema
from recordings.foxglove import AGVS, PLANS

SUBPROTOCOL = "foxglove.websocket.v1"
DEFAULT_PORT = 8765
"""Foxglove's default port for a WebSocket connection."""
BACKLOG = 10_000
"""Messages queued for one client before its oldest are dropped."""
MESSAGE_DATA = 1
_FRAME_HEAD = struct.Struct("<BIQ")
_SCENE_TOPICS = (AGVS, PLANS)


class FoxgloveError(EnvironmentFailure):
    """The server cannot listen where asked (the port is taken, the host unknown)."""


@dataclass
class _Channel:
    id: int
    topic: str
    latched: dict[object, tuple[int, bytes]] = field(default_factory=dict)

    def advertisement(self) -> dict:
        known = channel_schema(self.topic)
        name, schema = known if known is not None else ("", b"")
        return {
            "id": self.id,
            "topic": self.topic,
            "encoding": MESSAGE_ENCODING,
            "schemaName": name,
            "schema": schema.decode(),
            "schemaEncoding": SCHEMA_ENCODING,
        }


@dataclass(eq=False)  # a member of a set, by identity
class _Client:
    connection: ServerConnection
    subscriptions: dict[int, int] = field(default_factory=dict)  # subscription -> channel
    queue: deque = field(default_factory=lambda: deque(maxlen=BACKLOG))
    ready: asyncio.Event = field(default_factory=asyncio.Event)

    def send(self, frame: bytes | str) -> None:
        self.queue.append(frame)
        self.ready.set()

    def send_message(self, channel_id: int, log_time_ns: int, payload: bytes) -> None:
        for subscription, channel in self.subscriptions.items():
            if channel == channel_id:
                self.send(_FRAME_HEAD.pack(MESSAGE_DATA, subscription, log_time_ns) + payload)


def _latch_key(topic: str, payload: bytes) -> object:
    """What a newer message replaces: the channel's last message, or on a Foxglove scene
    channel the last update of each entity."""
    if topic not in _SCENE_TOPICS:
        return None
    try:
        update = json.loads(payload)
        ids = [e["id"] for e in update["entities"]] + [d["id"] for d in update["deletions"]]
    except (ValueError, KeyError, TypeError):
        return None
    return tuple(sorted(ids))


class FoxgloveServer:
    """Serves channels on ``ws://host:port`` (port 0: a free one) while the ``with``
    block runs; ``publish`` adds a message (and, on first use, its channel)."""

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, name: str = "agv-fleet"):
        self.host, self.port, self.name = host, port, name
        self._channels: dict[str, _Channel] = {}
        self._clients: set[_Client] = set()
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True)
        self._server = None

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def __enter__(self) -> FoxgloveServer:
        self._thread.start()
        try:
            self._server = asyncio.run_coroutine_threadsafe(self._start(), self._loop).result()
        except OSError as err:
            self._stop_loop()
            raise FoxgloveError(
                f"cannot serve Foxglove on {self.host}:{self.port}: {err.strerror or err}"
            ) from None
        self.port = self._server.sockets[0].getsockname()[1]
        return self

    def __exit__(self, *exc) -> None:
        asyncio.run_coroutine_threadsafe(self._close(), self._loop).result(timeout=10)
        self._stop_loop()

    def publish(self, topic: str, payload: bytes, log_time_ns: int) -> None:
        self._loop.call_soon_threadsafe(self._publish, topic, payload, log_time_ns)

    def wait(self) -> None:
        """Serve until interrupted (KeyboardInterrupt, or SIGTERM made one)."""
        while self._thread.is_alive():
            time.sleep(0.2)

    # --- in the server's loop -------------------------------------------------------
    async def _start(self):
        return await serve(
            self._serve_client,
            self.host,
            self.port,
            subprotocols=[SUBPROTOCOL],  # a client that offers none is refused (HTTP 400)
            max_size=2**20,
            compression=None,
        )

    async def _close(self) -> None:
        self._server.close()
        await self._server.wait_closed()

    def _stop_loop(self) -> None:
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(timeout=10)

    def _publish(self, topic: str, payload: bytes, log_time_ns: int) -> None:
        channel = self._channels.get(topic)
        if channel is None:
            channel = self._channels[topic] = _Channel(len(self._channels) + 1, topic)
            advertise = json.dumps({"op": "advertise", "channels": [channel.advertisement()]})
            for client in self._clients:
                client.send(advertise)
        channel.latched[_latch_key(topic, payload)] = (log_time_ns, payload)
        for client in self._clients:
            client.send_message(channel.id, log_time_ns, payload)

    async def _serve_client(self, connection: ServerConnection) -> None:
        client = _Client(connection)
        client.send(json.dumps(self._server_info()))
        channels = [c.advertisement() for c in self._channels.values()]
        client.send(json.dumps({"op": "advertise", "channels": channels}))
        self._clients.add(client)
        sender = asyncio.create_task(self._send_queued(client))
        try:
            async for text in connection:
                self._on_request(client, text)
        except ConnectionClosed:
            pass
        finally:
            self._clients.discard(client)
            sender.cancel()

    def _server_info(self) -> dict:
        return {
            "op": "serverInfo",
            "name": self.name,
            "capabilities": [],
            "supportedEncodings": [],
            "metadata": {},
            "sessionId": str(id(self)),
        }

    def _on_request(self, client: _Client, text) -> None:
        """A client's subscribe or unsubscribe; anything else is ignored (a viewer sends
        requests for capabilities this server does not advertise)."""
        try:
            request = json.loads(text)
            op = request["op"]
            if op == "subscribe":
                for s in request["subscriptions"]:
                    self._subscribe(client, int(s["id"]), int(s["channelId"]))
            elif op == "unsubscribe":
                for subscription in request["subscriptionIds"]:
                    client.subscriptions.pop(int(subscription), None)
        except (ValueError, KeyError, TypeError):
            return

    def _subscribe(self, client: _Client, subscription: int, channel_id: int) -> None:
        channel = next((c for c in self._channels.values() if c.id == channel_id), None)
        if channel is None:
            return
        client.subscriptions[subscription] = channel_id
        for log_time_ns, payload in sorted(channel.latched.values(), key=lambda m: m[0]):
            client.send(_FRAME_HEAD.pack(MESSAGE_DATA, subscription, log_time_ns) + payload)

    @staticmethod
    async def _send_queued(client: _Client) -> None:
        try:
            while True:
                await client.ready.wait()
                client.ready.clear()
                while client.queue:
                    await client.connection.send(client.queue.popleft())
        except ConnectionClosed:
            return
