"""Typed publish/subscribe on a run's keys, with a codec that never crashes a node.

Payloads are compact JSON of ``bridge.messages`` types. A payload that fails
to decode or validate is counted per key and logged once per key (to the
node's stderr); the node goes on. Subscribers deliver into a queue so a node
can wait with a timeout (``recv()`` of zenoh handlers has none).
"""

from __future__ import annotations

import json
import queue
import sys
from collections import Counter
from dataclasses import dataclass

import zenoh

from bridge import keys
from bridge.messages import MessageError, from_dict, to_dict


def encode(msg) -> bytes:
    return json.dumps(to_dict(msg), separators=(",", ":")).encode()


def decode(key: str, payload: bytes):
    """The message a relative key carries, decoded and validated (MessageError if not)."""
    cls = keys.message_type(key)
    if cls is None:
        raise MessageError(f"no message type for key {key!r}")
    try:
        data = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as err:
        raise MessageError(f"not JSON: {err}") from None
    return from_dict(cls, data)


@dataclass
class Received:
    key: str  # relative to the run prefix
    msg: object
    payload: bytes


class Bus:
    """A session seen through a run prefix."""

    def __init__(self, session: zenoh.Session, prefix: str):
        self.session = session
        self.prefix = prefix
        self.malformed: Counter[str] = Counter()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._keep: list = []  # subscribers live as long as their Python objects

    def full(self, key: str) -> str:
        return f"{self.prefix}/{key}"

    def relative(self, key_expr) -> str:
        return str(key_expr)[len(self.prefix) + 1 :]

    def publish(self, key: str, msg) -> None:
        self.publish_payload(key, encode(msg))

    def publish_payload(self, key: str, payload: bytes) -> None:
        pub = self._publishers.get(key)
        if pub is None:
            pub = self.session.declare_publisher(
                self.full(key), congestion_control=zenoh.CongestionControl.BLOCK
            )
            self._publishers[key] = pub
        pub.put(payload)

    def subscribe(self, key_expr: str, decoded: bool = True) -> queue.Queue:
        """A queue of ``Received`` for every valid message on ``<prefix>/<key_expr>``.

        With ``decoded=False`` the queue gets raw payloads (``msg`` is None),
        for the recorder, which stores them as they came.
        """
        q: queue.Queue = queue.Queue()

        def on_sample(sample: zenoh.Sample) -> None:
            key = self.relative(sample.key_expr)
            payload = sample.payload.to_bytes()
            if not decoded:
                q.put(Received(key, None, payload))
                return
            try:
                msg = decode(key, payload)
            except MessageError as err:
                self._count_malformed(key, err)
                return
            q.put(Received(key, msg, payload))

        self._keep.append(self.session.declare_subscriber(self.full(key_expr), on_sample))
        return q

    def _count_malformed(self, key: str, err: Exception) -> None:
        self.malformed[key] += 1
        if self.malformed[key] == 1:
            print(f"agv-fleet: ignoring malformed message on {key}: {err}", file=sys.stderr)

    # --- liveliness -------------------------------------------------------------------
    def declare_alive(self, key: str) -> zenoh.LivelinessToken:
        token = self.session.liveliness().declare_token(self.full(key))
        self._keep.append(token)
        return token

    def watch_alive(self, key_expr: str) -> queue.Queue:
        """A queue of (relative key, alive: bool) for tokens on ``key_expr``, present ones first."""
        q: queue.Queue = queue.Queue()

        def on_sample(sample: zenoh.Sample) -> None:
            q.put((self.relative(sample.key_expr), sample.kind == zenoh.SampleKind.PUT))

        sub = self.session.liveliness().declare_subscriber(
            self.full(key_expr), on_sample, history=True
        )
        self._keep.append(sub)
        return q
