"""Read a recording back, whole or cut short.

A complete file is read through its summary (``mcap.reader.make_reader``). A
file with no footer (the recorder was killed) or a damaged one is read from
the start with ``mcap.stream_reader.StreamReader``: every chunk that was
completed before the damage is kept, and the recording says so
(``truncated``, ``recovered_note``).

Messages come in file order (the order they were recorded, which is causal:
an AGV's state for tick k+1 comes before its plan made at tick k), not sorted
by log time. Reading does not decode them: each message's JSON is decoded on
first use, so ``info`` decodes nothing and ``analyze`` only the topics it uses.

A recording is input like any other: a message on one of the run's topics
that is not valid for its message type (``bridge.messages``: fields, types,
finite numbers, sizes) is undecodable and skipped (and counted), never handed
on; other topics give any JSON object. Only regular files of at most
``MAX_RECORDING_BYTES`` are read (a FIFO would hang the reader); a cut file
from which nothing could be recovered is an error.
"""

from __future__ import annotations

import gc
import json
import os
import struct
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import zstandard
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Attachment, Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import MCAP0_MAGIC

from bridge.keys import WORLD_TICK, agv_name, message_type
from bridge.messages import MessageError, from_dict
from bridge.struct_decoder import decode_valid
from planner.core.errors import BadInputError, MapError
from planner.core.limits import open_regular_file

# what mcap raises on a cut or damaged file: its own errors, short reads in struct,
# CRC mismatches (ValueError), unknown ids (KeyError) and bad compressed data
_DAMAGED = (McapError, struct.error, ValueError, KeyError, EOFError, zstandard.ZstdError)


# what ``open_recording`` reads: messages are held decompressed in memory, about ten
# times the size of their zstd chunks
MAX_RECORDING_BYTES = 1024**3


class RecordingError(BadInputError):
    """A file that cannot be read as a recording at all (missing, not MCAP, too large,
    nothing recoverable)."""


_UNDECODED = object()
# raw_decode skips json.loads's per-call setup: half the cost of a small message
_raw_decode = json.JSONDecoder().raw_decode


class RecordedMessage:
    """One recorded message; ``data`` is its JSON object, decoded on first use (None if
    the payload is not a JSON object)."""

    __slots__ = ("_data", "log_time_ns", "payload", "topic")

    def __init__(self, topic: str, log_time_ns: int, payload: bytes):
        self.topic = topic
        self.log_time_ns = log_time_ns
        self.payload = payload
        self._data = _UNDECODED

    @property
    def data(self) -> dict | None:
        if self._data is _UNDECODED:
            self._data = _decode(self.topic, self.payload)
        return self._data

    @property
    def decoded(self) -> bool:
        return self._data is not _UNDECODED

    def __repr__(self) -> str:
        return f"RecordedMessage({self.topic!r}, {self.log_time_ns}, {len(self.payload)} bytes)"


def _decode(topic: str, payload: bytes) -> dict | None:
    """The JSON object of a message, if valid for its topic's message type (any JSON
    object on a topic that has none), else None."""
    try:
        text = payload.decode()
        data, end = _raw_decode(text)
        if end != len(text) and text[end:].strip():
            raise ValueError("extra data after the JSON value")
    except ValueError:  # UnicodeDecodeError, JSONDecodeError, leading whitespace
        try:
            data = json.loads(payload)
        except (ValueError, RecursionError):
            return None
    except RecursionError:
        return None
    cls = message_type(topic)
    if cls is None:
        return data if isinstance(data, dict) else None
    if decode_valid(cls, payload) is None:  # what the compiled check refuses, from_dict decides
        try:
            from_dict(cls, data)
        except MessageError:
            return None
    return data


@dataclass
class Recording:
    """A recording in memory. ``records`` holds every message as recorded; ``messages``
    and ``of(topic)`` give the decoded ones, skipping (and counting) undecodable ones."""

    path: Path
    records: list[RecordedMessage]
    metadata: dict[str, dict[str, str]]
    attachments: dict[str, bytes]
    channels: dict[str, str]  # topic -> message type (schema name, "" for none)
    truncated: bool = False
    recovered_note: str = ""
    _by_topic: dict[str, list[RecordedMessage]] | None = field(default=None, repr=False)
    _decoded: dict[str | None, list[RecordedMessage]] = field(default_factory=dict, repr=False)

    @property
    def messages(self) -> list[RecordedMessage]:
        """Every decodable message, in file order."""
        return self._decode_once(None, self.records)

    def of(self, topic: str) -> list[RecordedMessage]:
        """The decodable messages of one topic, in file order."""
        return self._decode_once(topic, self._records_of(topic))

    def data_of(self, topic: str) -> Iterator[dict]:
        """The decoded data of one topic's messages, decoded afresh and not kept: one pass
        over a large topic holds no more than the caller keeps (``of`` keeps it all)."""
        for m in self._records_of(topic):
            if m.decoded:
                data = m.data
            else:
                data = _decode(m.topic, m.payload)
                if data is None:
                    m._data = None  # remembered for ``undecodable``
            if data is not None:
                yield data

    def _records_of(self, topic: str) -> list[RecordedMessage]:
        if self._by_topic is None:
            index: dict[str, list[RecordedMessage]] = {}
            for m in self.records:
                index.setdefault(m.topic, []).append(m)
            self._by_topic = index
        return self._by_topic.get(topic, [])

    def _decode_once(self, key, records):
        decoded = self._decoded.get(key)
        if decoded is None:
            with paused_gc():
                decoded = [m for m in records if m.data is not None]
            self._decoded[key] = decoded
        return decoded

    @property
    def undecodable(self) -> int:
        """Messages found undecodable so far (topics are decoded on first use)."""
        return sum(1 for m in self.records if m.decoded and m.data is None)

    def topics(self) -> dict[str, int]:
        """Message count per topic (nothing decoded), every channel listed, even empty."""
        counts = Counter(m.topic for m in self.records)
        return {t: counts.get(t, 0) for t in {**self.channels, **counts}}

    def agv_names(self) -> list[str]:
        """AGVs with an ``agv/<name>/...`` channel, in order of appearance."""
        names = (agv_name(t) for t in self.topics())
        return list(dict.fromkeys(n for n in names if n))

    @property
    def scenario_text(self) -> str | None:
        data = self.attachments.get("scenario.toml")
        return None if data is None else data.decode("utf-8", errors="replace")

    @property
    def run(self) -> dict:
        """The ``run`` metadata (run id, version, parameters, start), decoded."""
        return _metadata_values(self.metadata.get("run", {}))

    @property
    def log_time_zero_ns(self) -> int:
        """The log time of sim time 0 (the run's wall-clock start; 0 in recordings
        made before log times were wall-clock times)."""
        return int(self.run.get("log_time_zero_ns", 0))

    @property
    def result(self) -> dict | None:
        """How the run ended (the ``result`` metadata, decoded), None if it did not finish."""
        record = self.metadata.get("result")
        return None if record is None else _metadata_values(record)


def _metadata_values(record: dict[str, str]) -> dict:
    """Metadata values are JSON texts (see recordings.writer); undecodable ones stay text."""
    out = {}
    for key, text in record.items():
        try:
            out[key] = json.loads(text)
        except ValueError:
            out[key] = text
    return out


def open_recording(path) -> Recording:
    """Read a whole recording; RecordingError if it is missing or not MCAP."""
    path = Path(path)
    try:
        with open_regular_file(path, "recording") as f:
            if os.fstat(f.fileno()).st_size > MAX_RECORDING_BYTES:
                raise RecordingError(
                    f"{path} is larger than the {MAX_RECORDING_BYTES // 2**20} MiB "
                    "a recording may have"
                )
            if f.read(len(MCAP0_MAGIC)) != MCAP0_MAGIC:
                raise RecordingError(f"{path} is not an MCAP recording (bad magic bytes)")
            f.seek(-len(MCAP0_MAGIC), os.SEEK_END)
            complete = f.read() == MCAP0_MAGIC  # a cut file does not end with the magic
            with paused_gc():
                if complete:
                    try:
                        f.seek(0)
                        return _read_complete(f, path)
                    except (*_DAMAGED, OSError):
                        pass  # a real I/O error comes back from the stream reader
                f.seek(0)
                return _read_stream(f, path)
    except FileNotFoundError:
        raise RecordingError(f"no such file: {path}") from None
    except MapError as err:  # not a regular file
        raise RecordingError(str(err)) from None
    except OSError as err:
        raise RecordingError(f"cannot read {path}: {err.strerror or err}") from None


@contextmanager
def paused_gc() -> Iterator[None]:
    """No garbage collection inside: building millions of small objects (messages,
    decoded dicts, rows) triggers full collections over and over, which makes reading
    and analysing a large recording about 1.5x slower; they hold no reference cycles."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _read_complete(f, path: Path) -> Recording:
    reader = make_reader(f)
    summary = reader.get_summary()
    if summary is None:
        raise McapError("no summary section")
    channels = {
        c.topic: summary.schemas[c.schema_id].name if c.schema_id else ""
        for c in summary.channels.values()
    }
    messages = [
        RecordedMessage(channel.topic, message.log_time, message.data)
        for _, channel, message in reader.iter_messages(log_time_order=False)
    ]
    metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    attachments = {a.name: a.data for a in reader.iter_attachments()}
    return Recording(path, messages, metadata, attachments, channels)


def _read_stream(f, path: Path) -> Recording:
    schemas: dict[int, str] = {}
    channels: dict[int, str] = {}  # id -> topic
    topics: dict[str, str] = {}  # topic -> message type
    metadata: dict[str, dict[str, str]] = {}
    attachments: dict[str, bytes] = {}
    messages: list[RecordedMessage] = []
    chunks = 0
    try:
        for record in StreamReader(f, emit_chunks=True, validate_crcs=True).records:
            if isinstance(record, Chunk):
                inner = breakup_chunk(record, validate_crc=True)  # the whole chunk or nothing
                chunks += 1
            else:
                inner = [record]
            found = []  # appended after the whole chunk was understood
            for r in inner:
                if isinstance(r, Message):
                    found.append(RecordedMessage(channels[r.channel_id], r.log_time, r.data))
                elif isinstance(r, Channel):
                    channels[r.id] = r.topic
                    topics[r.topic] = schemas.get(r.schema_id, "")
                elif isinstance(r, Schema):
                    schemas[r.id] = r.name
                elif isinstance(r, Metadata):
                    metadata[r.name] = r.metadata
                elif isinstance(r, Attachment):
                    attachments[r.name] = r.data
            messages.extend(found)
    except _DAMAGED as err:
        if f.tell() >= os.fstat(f.fileno()).st_size:
            why = "no footer (the file ends early)"
        else:
            why = f"damaged at byte {f.tell()} ({type(err).__name__}: {err})"
        truncated = True
    else:  # a whole file whose summary or index could not be used
        why, truncated = "summary unusable, read sequentially", False
    note = f"{why}: recovered {chunks} complete chunks, {len(messages)} messages"
    if truncated and not (messages or metadata or attachments):
        raise RecordingError(f"{path}: {why}, and nothing could be recovered from it")
    return Recording(path, messages, metadata, attachments, topics, truncated, note)


def held_seconds(path) -> float | None:
    """The simulated time of a recording's last readable tick; None if it has none."""
    try:
        rec = open_recording(path)
    except RecordingError:
        return None
    ticks = rec.of(WORLD_TICK)
    return (ticks[-1].log_time_ns - rec.log_time_zero_ns) / 1e9 if ticks else None
