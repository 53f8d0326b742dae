"""Sending rows to a Rerun recording stream as columns, whole recordings or live.

Static rows are logged at once; temporal rows wait in a ``Columns`` buffer, one
list per entity, and go out with one ``rr.send_columns`` per entity. A replay
sends everything in one go; the live view sends what came in every
``LIVE_PERIOD`` seconds (one ``rr.log`` per row costs ~50 µs, so a live view
logging row by row tripled the time of a fast in-process run).
"""

from __future__ import annotations

import time

import numpy as np
import rerun as rr

from bridge import keys
from planner.core.motion import CONTROL_PERIOD
from recordings.rerun_blueprint import blueprint
from recordings.rerun_rows import TIMELINE, Row, RowMaker

LIVE_PERIOD = 0.1  # s of wall time between sends of a live view


def recording_dt(messages) -> float:
    """The control period of a run, from its first tick after tick 0."""
    for m in messages:
        if m.topic == keys.WORLD_TICK and m.data["tick"] > 0:
            return m.data["time"] / m.data["tick"]
    return CONTROL_PERIOD  # a recording cut before its second tick: the default period


class Columns:
    """Rows waiting to be sent, by entity."""

    def __init__(self, stream: rr.RecordingStream):
        self._stream = stream
        self._waiting: dict[str, tuple[object, list[float], list]] = {}

    def add(self, rows: list[Row]) -> None:
        for row in rows:
            if row.time is None:
                self._stream.log(row.path, *row.payload, static=True)
            else:
                entry = self._waiting.setdefault(row.path, (row.kind, [], []))
                entry[1].append(row.time)
                entry[2].append(row.payload)

    def send(self) -> None:
        for path, (kind, times, payloads) in self._waiting.items():
            self._stream.send_columns(
                path,
                indexes=[rr.TimeColumn(TIMELINE, duration=_nanoseconds(times))],
                columns=kind(payloads),
            )
        self._waiting.clear()


def _nanoseconds(seconds: list[float]) -> np.ndarray:
    """Rounded, as ``set_time`` does for one time; TimeColumn truncates float seconds
    (0.3 s would become 0.299999999 s)."""
    return np.round(np.asarray(seconds) * 1e9).astype(np.int64).astype("timedelta64[ns]")


def send_recording(stream: rr.RecordingStream, messages, follow=None, rate=None) -> None:
    """Convert a whole recording and send it, with its blueprint (options: see
    ``rerun_blueprint.blueprint``)."""
    maker = RowMaker(recording_dt(messages))
    columns = Columns(stream)
    for m in messages:
        columns.add(maker.feed(m.topic, m.data))
    columns.send()
    stream.send_blueprint(
        blueprint(maker.agv_names, maker.map_bounds, maker.end_time, follow=follow, rate=rate)
    )


class Live:
    """Messages as they come: sent every ``LIVE_PERIOD``, the blueprint (re)sent when
    an AGV appears. ``send()`` sends what is waiting (call it at the end)."""

    def __init__(self, stream: rr.RecordingStream, dt: float):
        self._stream = stream
        self._maker = RowMaker(dt)
        self._columns = Columns(stream)
        self._agvs_shown = 0
        self._due = time.monotonic() + LIVE_PERIOD

    def feed(self, topic: str, data: dict) -> None:
        self._columns.add(self._maker.feed(topic, data))
        names = self._maker.agv_names
        if len(names) != self._agvs_shown:
            self._agvs_shown = len(names)
            self._stream.send_blueprint(blueprint(names, self._maker.map_bounds))
        if time.monotonic() >= self._due:
            self.send()

    def send(self) -> None:
        self._columns.send()
        self._due = time.monotonic() + LIVE_PERIOD
