"""What a run's messages become on a recording's channels: one fact for every output.

The MCAP writer and the Foxglove WebSocket server show a run on the same channels with
the same schemas: a channel per bus key (JSON, with its message type's JSON Schema, or
no schema for a key without a type) and, beside them, the ``foxglove/*`` channels of
``recordings.foxglove`` on Foxglove's published schemas.
"""

from __future__ import annotations

import json
from functools import cache

from bridge.keys import message_type
from bridge.messages import json_schema
from recordings import foxglove

SCHEMA_ENCODING = "jsonschema"
MESSAGE_ENCODING = "json"


@cache
def channel_schema(topic: str) -> tuple[str, bytes] | None:
    """(schema name, JSON Schema bytes) of a channel, or None for a channel without one."""
    cls = message_type(topic)
    if cls is not None:
        return cls.__name__, json.dumps(json_schema(cls), separators=(",", ":")).encode()
    name = foxglove.SCHEMA_OF.get(topic)
    if name is not None:
        return name, foxglove.schema(name)
    return None


class ChannelMessages:
    """Turns each bus message (its key and JSON payload) into the messages of the
    channels: itself on its key, then what Foxglove's channels make of it."""

    def __init__(self):
        self._foxglove = foxglove.FoxgloveChannels()

    def of(self, key: str, payload: bytes, log_time_ns: int) -> list[tuple[str, bytes]]:
        out = [(key, payload)]
        if self._foxglove.wants(key):
            try:
                made = self._foxglove.feed(key, json.loads(payload), log_time_ns)
            except (ValueError, KeyError, TypeError, IndexError):
                made = []  # not a message of its type: recorded as it came, nothing drawn
            out.extend((topic, foxglove.encode(message)) for topic, message in made)
        return out
