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
from recordings.rerun_blueprint import Bounds, blueprint
from recordings.rerun_fleet import FleetCounts, fleet_style_rows
from recordings.rerun_rows import AGV_ROW_TOPICS, TIMELINE, Row, RowMaker, map_bounds

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


def rows_of(maker: RowMaker, fleet: FleetCounts, topic: str, data: dict) -> list[Row]:
    """The rows of one message: its own, and the fleet's counts at a tick."""
    rows = maker.feed(topic, data)
    if topic == keys.WORLD_TICK:
        rows += fleet.rows(data)
    return rows


def layout_of(messages) -> tuple[list[str], Bounds | None, float]:
    """The AGVs (in the order the rows meet them), the map's bounds and the end time of
    a whole recording, read from a few messages: what its blueprint needs, known before
    any row is made."""
    names: list[str] = []
    bounds, ticked = None, False
    for m in messages:
        if m.topic == keys.WORLD_TICK:
            if not ticked:
                ticked = True
                names += [s["name"] for s in m.data["agvs"] if s["name"] not in names]
        elif m.topic == keys.WORLD_MAP:
            bounds = map_bounds(m.data)
        else:
            name = keys.agv_name(m.topic)
            if name is not None and name not in names and m.topic.endswith(AGV_ROW_TOPICS):
                names.append(name)
    end_time = next((m.data["time"] for m in reversed(messages) if m.topic == keys.WORLD_TICK), 0)
    return names, bounds, end_time


def send_recording(
    stream: rr.RecordingStream, messages, follow=None, rate=None, stations=()
) -> None:
    """Send a whole recording's blueprint (options: see ``rerun_blueprint.blueprint``),
    then the recording converted (``stations``: a shift's, ``rerun_tasks.stations_of``)."""
    names, bounds, end_time = layout_of(messages)
    stream.send_blueprint(blueprint(names, bounds, end_time, follow=follow, rate=rate))
    maker, fleet = RowMaker(recording_dt(messages), stations), FleetCounts()
    columns = Columns(stream)
    columns.add(fleet_style_rows())
    for m in messages:
        columns.add(rows_of(maker, fleet, m.topic, m.data))
    columns.send()


class Live:
    """Messages as they come: sent every ``LIVE_PERIOD``, the blueprint (re)sent, before
    the rows, when the map or an AGV appears. ``send()`` sends what is waiting (call it
    at the end)."""

    def __init__(self, stream: rr.RecordingStream, dt: float, stations=()):
        self._stream = stream
        self._maker = RowMaker(dt, stations)
        self._fleet = FleetCounts()
        self._columns = Columns(stream)
        self._shown: tuple | None = None  # (AGVs, map bounds) of the blueprint sent
        self._due = time.monotonic() + LIVE_PERIOD

    def feed(self, topic: str, data: dict) -> None:
        rows = rows_of(self._maker, self._fleet, topic, data)
        shown = (len(self._maker.agv_names), self._maker.map_bounds)
        if shown != self._shown:
            self._stream.send_blueprint(blueprint(self._maker.agv_names, shown[1]))
            if self._shown is None:
                self._columns.add(fleet_style_rows())
            self._shown = shown
        self._columns.add(rows)
        if time.monotonic() >= self._due:
            self.send()

    def send(self) -> None:
        self._columns.send()
        self._due = time.monotonic() + LIVE_PERIOD
