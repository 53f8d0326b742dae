"""The bytes each key carries on the bus: compact JSON, but MessagePack for the tick.

Every AGV receives and decodes every tick: with 100 AGVs, a hundred copies of a
22 KB JSON text per tick, most of it numbers printed in decimal and parsed back.
MessagePack (msgspec, the same library and Structs as the JSON fast path) carries a
float in 9 bytes and reads it without parsing text: a warm 100-AGV tick 17 % smaller
and decoded 25 % faster (``benchmarks/fleet_bench.py`` prints both per tick). Only the
tick changed: the other messages are small, and JSON keeps them readable on the bus.

Recordings stay JSON (``json_payload``), so ``info``, ``analyze``, ``replay``, Foxglove
and every recording made before read them as before: the recorder turns a tick's
MessagePack back into the JSON the in-process run writes, byte for byte (MessagePack
keeps the field order and tells ints from floats, and msgspec prints a float the same
way from either).
"""

from __future__ import annotations

import msgspec

from bridge import keys
from bridge.messages import encode, plain_number

BINARY_KEYS = frozenset({keys.WORLD_TICK})
"""Keys whose payloads are MessagePack on the bus."""

_PACKER = msgspec.msgpack.Encoder(enc_hook=plain_number)


def is_binary(key: str) -> bool:
    return key in BINARY_KEYS


def to_wire(key: str, msg) -> bytes:
    """``msg`` as the bus carries it on ``key``."""
    return _PACKER.encode(msg) if key in BINARY_KEYS else encode(msg)


def json_payload(key: str, payload: bytes) -> bytes:
    """A valid bus payload on ``key`` as the JSON a recording stores (``encode``'s)."""
    if key not in BINARY_KEYS:
        return payload
    return msgspec.json.encode(msgspec.msgpack.decode(payload))
