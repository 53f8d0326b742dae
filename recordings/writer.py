"""Write a run to one MCAP file: a channel per bus key, JSON messages, zstd chunks.

Layout of a recording:

- one channel per relative bus key (``world/tick``, ``agv/agv1/state``, ...),
  message encoding ``json``, with the JSON Schema of the key's message type
  (schema encoding ``jsonschema``, one schema record per type). A key with no
  message type (``bridge.keys.message_type`` gives None) still gets a channel,
  with no schema (schema id 0): the recording keeps what the bus carried.
- log time = publish time = the run's wall-clock start (run fact
  ``log_time_zero_ns``) + the message's simulated time (tick * dt): viewers such
  as Foxglove show real dates, and two recordings of one scenario still line up
  message for message after subtracting their zero (callers pass sim time: the
  in-process sink is ``record_sink``; a bus recorder passes tick * dt to
  ``write_payload``). The sim time itself is in the messages.
- beside them, the channels of ``recordings.foxglove`` (map, AGV frames and
  bodies, plans on ``foxglove.*`` schemas) for Foxglove's 3D panel.
- metadata ``run`` at open and ``result`` at ``finish``: a string value as it is,
  anything else (numbers, lists, objects) as JSON text (metadata values must be
  strings); a string that would read as JSON (``"1"``) is JSON-quoted.
- attachment ``scenario.toml``: the scenario file as given.

Durability: a chunk is closed when it holds ``CHUNK_BYTES`` or is
``CHUNK_SECONDS`` old, and the file is flushed after every chunk, so a
recorder killed with SIGKILL loses at most the chunk in progress (about half a
second); every completed chunk stays readable (``recordings.reader``).
The age check runs on every write; a recorder idling on the bus calls
``flush_if_due()`` when its wait times out.
"""

from __future__ import annotations

import json
import time
import uuid
from collections.abc import Callable
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

from bridge.messages import encode
from recordings.channels import MESSAGE_ENCODING, SCHEMA_ENCODING, ChannelMessages, channel_schema

CHUNK_BYTES = 256 * 1024
"""Uncompressed bytes per chunk: ~1000 AGV states, a few ms of a fast run."""
CHUNK_SECONDS = 0.5
"""Longest wall time a chunk stays open (bounds the loss of a killed recorder)."""
_RECORD_OVERHEAD = 31  # bytes around a message's data: opcode, length, channel, seq, 2 times
_NEVER = 1 << 62  # mcap's own size trigger is off: this class closes (and flushes) chunks


def tool_version() -> str:
    try:
        return version("agv-fleet")
    except PackageNotFoundError:
        return "unknown"


def _metadata_text(value) -> str:
    if isinstance(value, str):
        try:
            json.loads(value)
        except ValueError:
            return value  # plain text reads back as itself
    return json.dumps(value, separators=(",", ":"))


def _metadata_values(values: dict) -> dict[str, str]:
    return {str(k): _metadata_text(v) for k, v in values.items()}


class RecordingWriter:
    """A context manager that writes one MCAP recording; see the module docstring."""

    def __init__(self, path, *, scenario_name: str, scenario_text: str, run_facts: dict):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)  # as the default runs/ is
        self._file = open(self.path, "wb")  # noqa: SIM115 (closed by finish/close)
        self._mcap = Writer(self._file, chunk_size=_NEVER, compression=CompressionType.ZSTD)
        self._mcap.start(library=f"agv-fleet/{tool_version()} {LIBRARY_IDENTIFIER}")
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}  # schema name -> id
        self._outbox = ChannelMessages()
        self._pending = 0
        self._due = time.monotonic() + CHUNK_SECONDS
        self._closed = False
        self.log_time_zero_ns = time.time_ns()
        started = datetime.fromtimestamp(self.log_time_zero_ns / 1e9, UTC)
        facts = {
            "run_id": uuid.uuid4().hex,
            **run_facts,
            "scenario": scenario_name,
            "version": tool_version(),
            "started_utc": started.isoformat(timespec="seconds"),
            "log_time_zero_ns": self.log_time_zero_ns,
        }
        self.run_id = facts["run_id"]
        self._mcap.add_metadata("run", _metadata_values(facts))
        self._mcap.add_attachment(
            create_time=self.log_time_zero_ns,
            log_time=self.log_time_zero_ns,
            name="scenario.toml",
            media_type="application/toml",
            data=scenario_text.encode(),
        )
        self._file.flush()

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def write(self, key: str, msg, sim_time_ns: int) -> None:
        """Record a message dataclass of ``bridge.messages`` on ``key``."""
        self.write_payload(key, encode(msg), sim_time_ns)

    def write_payload(self, key: str, payload: bytes, sim_time_ns: int) -> None:
        """Record JSON bytes as they came from the bus (not checked), at the run's
        start + ``sim_time_ns``, and what Foxglove needs of them."""
        log_time = self.log_time_zero_ns + sim_time_ns
        for topic, data in self._outbox.of(key, payload, log_time):
            self._add(topic, data, log_time)
        if self._pending >= CHUNK_BYTES or time.monotonic() >= self._due:
            self._close_chunk()

    def _add(self, key: str, payload: bytes, log_time: int) -> None:
        channel = self._channels.get(key)
        if channel is None:
            channel = self._register(key)
        self._mcap.add_message(channel, log_time, payload, log_time)
        self._pending += len(payload) + _RECORD_OVERHEAD

    def flush_if_due(self) -> None:
        """Close the chunk in progress if it is ``CHUNK_SECONDS`` old (for idle loops)."""
        if self._pending and time.monotonic() >= self._due:
            self._close_chunk()

    def finish(self, result: dict) -> None:
        """Store how the run ended (metadata ``result``, e.g. RunSummary.to_json()) and close."""
        self._close_chunk()
        self._mcap.add_metadata("result", _metadata_values(result))
        self.close()

    def close(self) -> None:
        """Write the summary and footer and close the file (without ``result`` unless
        ``finish`` was called: the recording then says the run did not finish)."""
        if self._closed:
            return
        self._closed = True
        try:
            self._mcap.finish()
        finally:
            self._file.close()

    def _register(self, key: str) -> int:
        schema = 0
        known = channel_schema(key)
        if known is not None:
            name, data = known
            schema = self._schemas.get(name, 0)
            if not schema:
                schema = self._mcap.register_schema(name, SCHEMA_ENCODING, data)
                self._schemas[name] = schema
        channel = self._mcap.register_channel(key, MESSAGE_ENCODING, schema)
        self._channels[key] = channel
        return channel

    def _close_chunk(self) -> None:
        self._mcap.flush()  # ends the chunk (if it has messages) and flushes the file
        self._pending = 0
        self._due = time.monotonic() + CHUNK_SECONDS


def record_sink(writer: RecordingWriter, dt: float) -> Callable[[str, object], None]:
    """A ``fleet.runtime.inprocess`` sink that records every message at its simulated time
    (tick * dt; messages without a tick, the map, at 0) after the run's start."""
    dt_ns = round(dt * 1e9)
    write = writer.write

    def sink(key: str, msg) -> None:
        write(key, msg, getattr(msg, "tick", 0) * dt_ns)

    return sink


def default_recording_path(scenario_name: str, runs_dir: Path | str = "runs") -> Path:
    """``runs/<scenario>-<UTC time>.mcap`` (creating ``runs/``)."""
    folder = Path(runs_dir)
    folder.mkdir(parents=True, exist_ok=True)
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S.%fZ")
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in scenario_name) or "run"
    return folder / f"{safe}-{stamp}.mcap"
