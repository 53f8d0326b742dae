"""Typed publish/subscribe on a run's keys, with a codec that never crashes a node.

Payloads are compact JSON of ``bridge.messages`` types, the tick's MessagePack
(``bridge.wire``). Every payload is validated
before anyone sees it: its size (``MAX_PAYLOAD_BYTES``), JSON nesting (Python's parser
stops at its recursion limit), every field's type, finite numbers, list lengths, and
that a message on ``agv/<name>/...`` names that AGV (in C by ``bridge.struct_decoder``,
else by the reference decoder here). One that fails is counted per key and logged once
per key (to the node's stderr); the node goes on. Subscribers deliver into a queue so a
node can wait with a timeout (``recv()`` of zenoh handlers has none): a
``queue.SimpleQueue``, in C: ``queue.Queue``'s Python locks cost 50 AGV processes, whose
caches are cold at every tick, 4 to 6 ms of CPU per tick in their main threads and 2.5 ms
in their receiving threads (of about 65 and 15). ``listen`` instead calls a function
with each message as it arrives (an AGV answers its tick there, in Zenoh's network
thread: one thread woken per tick, not three), and a reader may ``drop`` a message after
a look at its validated fields, before it is made into a dataclass.
"""

from __future__ import annotations

import json
import queue
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

import msgspec
import zenoh

from bridge import keys
from bridge.log import say
from bridge.messages import MessageError, from_dict
from bridge.session import MAX_MESSAGE_BYTES
from bridge.struct_decoder import decode_struct, to_message
from bridge.wire import is_binary, to_wire

MAX_PAYLOAD_BYTES = MAX_MESSAGE_BYTES
# keys counted one by one; past that, under OTHER_KEYS (a forger picks the keys)
MAX_COUNTED_KEYS = 1000
OTHER_KEYS = "(other keys)"


def decode(key: str, payload: bytes, drop: Callable[[object], bool] | None = None):
    """The message a relative key carries, decoded and validated (MessageError if not).

    ``drop``: a look at the validated message before it is made (its Struct: the same
    field names), True for one the reader does not want: then None, and the copy into the
    dataclass is saved. Every check is made first, whatever ``drop`` says."""
    cls = keys.message_type(key)
    if cls is None:
        raise MessageError("no message type for this key")
    if len(payload) > MAX_PAYLOAD_BYTES:
        raise MessageError(f"{len(payload)} bytes, more than {MAX_PAYLOAD_BYTES}")
    binary = is_binary(key)
    msg = struct = decode_struct(cls, payload, binary)
    if struct is None:  # refused by the fast path: the reference decoder decides, and says why
        msg = _reference_decode(cls, payload, binary)
    owner = keys.agv_name(key)
    if owner is not None and getattr(msg, "name", owner) != owner:  # a type may name none
        raise MessageError(f"names AGV {msg.name!r}"[:200])
    if struct is None:
        return msg
    if drop is not None and drop(struct):
        return None
    return to_message(cls, struct)


def _reference_decode(cls, payload: bytes, binary: bool = False):
    """``cls`` from ``payload`` by the json module (``binary``: msgspec's MessagePack
    reader, untyped) and ``from_dict``: slower than the fast path, and the one that names
    what is wrong."""
    if binary:
        try:
            data = msgspec.msgpack.decode(payload)
        except msgspec.DecodeError as err:
            raise MessageError(f"not MessagePack: {err}"[:200]) from None
        except RecursionError:
            raise MessageError("MessagePack nested too deeply") from None
        return from_dict(cls, data)
    try:
        data = json.loads(payload)
    except (ValueError, UnicodeDecodeError) as err:
        raise MessageError(f"not JSON: {err}"[:200]) from None
    except RecursionError:
        raise MessageError("JSON nested too deeply") from None
    return from_dict(cls, data)


def _direct(callback):
    """``callback`` as a handler zenoh-python calls in its network thread (``indirect``,
    unstable in zenoh-python 1.x; a version without it calls it in its own thread)."""
    try:
        return zenoh.handlers.Callback(callback, indirect=False)
    except (AttributeError, TypeError):
        return callback


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
        self.invalid: Counter[str] = Counter()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._keep: list = []  # subscribers live as long as their Python objects

    def full(self, key: str) -> str:
        return f"{self.prefix}/{key}"

    def relative(self, key_expr) -> str:
        return str(key_expr)[len(self.prefix) + 1 :]

    def publish(self, key: str, msg) -> None:
        self.publish_payload(key, to_wire(key, msg))

    def publish_payload(self, key: str, payload: bytes) -> None:
        pub = self._publishers.get(key)
        if pub is None:
            pub = self.session.declare_publisher(
                self.full(key), congestion_control=zenoh.CongestionControl.BLOCK
            )
            self._publishers[key] = pub
        pub.put(payload)

    def subscribe(
        self, key_expr: str, drop: Callable[[object], bool] | None = None, *, direct: bool = False
    ) -> queue.SimpleQueue:
        """A queue of ``Received`` for every valid message on ``<prefix>/<key_expr>``
        (with its payload as it came, which the recorder stores, as JSON: ``bridge.wire``).

        ``drop`` (see ``decode``) runs in Zenoh's receiving thread on every valid message:
        one it drops never reaches the queue, and the thread waiting on the queue is not
        woken for it (an AGV held at its goal skips the ticks it would not answer)."""
        q: queue.SimpleQueue = queue.SimpleQueue()
        self.listen(key_expr, q.put, drop, direct=direct)
        return q

    def listen(
        self,
        key_expr: str,
        deliver: Callable[[Received], None],
        drop: Callable[[object], bool] | None = None,
        *,
        direct: bool = False,
    ) -> None:
        """``deliver(Received)`` for every valid message on ``<prefix>/<key_expr>`` as it
        arrives (``subscribe`` delivers into a queue); ``drop`` as for ``subscribe``.

        zenoh-python calls a callback in a Python thread of its own, which its network
        thread wakes for each message: ``direct`` calls it in the network thread itself,
        one thread woken per message instead of two, for a process that does nothing else
        meanwhile (an AGV answering its ticks). Not for a router's session: while the
        callback waits for the GIL, that network thread forwards nobody's messages."""

        def on_sample(sample: zenoh.Sample) -> None:
            key = self.relative(sample.key_expr)
            payload = sample.payload.to_bytes()
            try:
                msg = decode(key, payload, drop)
            except MessageError as err:
                self.count_invalid(key, err)
                return
            if msg is not None:
                deliver(Received(key, msg, payload))

        handler = _direct(on_sample) if direct else on_sample
        self._keep.append(self.session.declare_subscriber(self.full(key_expr), handler))

    def count_invalid(self, key: str, why) -> None:
        """Count a message that was not used (a node's own checks call this too)."""
        if key not in self.invalid and len(self.invalid) >= MAX_COUNTED_KEYS:
            key = OTHER_KEYS
        self.invalid[key] += 1
        if self.invalid[key] == 1:
            shown = key if len(key) <= 100 else key[:100] + "..."
            say(f"agv-fleet: ignoring invalid message on {shown}: {why}")

    # --- liveliness -------------------------------------------------------------------
    def declare_alive(self, key: str) -> zenoh.LivelinessToken:
        token = self.session.liveliness().declare_token(self.full(key))
        self._keep.append(token)
        return token

    def is_alive(self, key: str, timeout: float = 2.0) -> bool:
        """Whether a liveliness token on ``key`` exists now (a query to the router)."""
        replies = self.session.liveliness().get(self.full(key), timeout=timeout)
        return any(reply.ok is not None for reply in replies)

    def watch_alive(self, key_expr: str) -> queue.SimpleQueue:
        """A queue of (relative key, alive: bool) for tokens on ``key_expr``, present ones first."""
        q: queue.SimpleQueue = queue.SimpleQueue()

        def on_sample(sample: zenoh.Sample) -> None:
            q.put((self.relative(sample.key_expr), sample.kind == zenoh.SampleKind.PUT))

        sub = self.session.liveliness().declare_subscriber(
            self.full(key_expr), on_sample, history=True
        )
        self._keep.append(sub)
        return q
