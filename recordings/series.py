"""A recording as numpy arrays: what the analysis and the plots work on.

The source is the ``world/tick`` messages, the final one included: at every
tick the world lists every AGV's state (its copy of the AGV's answer, the
command that led there included) and every moving obstacle and temporary
obstacle cell it shows. These are the positions the world counts distance and
checks contacts on, aligned across AGVs, so every metric comes from one
source. (The ``agv/<name>/state`` messages carry the same states; reading the
ticks alone also halves the decoding of a large recording.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from operator import itemgetter

import numpy as np

from bridge import keys
from planner.core.errors import BadInputError
from planner.maps.grid import GridMap
from recordings.map_frame import map_origin
from recordings.reader import Recording, paused_gc

AGV_FIELDS = ("x", "y", "theta", "vx", "vy", "omega", "radius", "plan_time_ms")
MOVING_FIELDS = ("x", "y", "radius")


class SeriesError(BadInputError, ValueError):
    """Messages without the fields of agv-fleet messages (not a recording of this tool)."""


@dataclass(frozen=True)
class Discs:
    """Named discs listed at every tick: ``columns[field]`` is a (T, N) array, NaN
    where a disc is missing from a tick; ``labels[field]`` likewise for text fields."""

    names: list[str]
    columns: dict[str, np.ndarray]
    labels: dict[str, np.ndarray]

    def index(self, name: str) -> int:
        return self.names.index(name)


@dataclass(frozen=True)
class RunSeries:
    grid: GridMap | None
    tick: np.ndarray  # (T,) int
    time: np.ndarray  # (T,) s
    agvs: Discs  # AGV_FIELDS, labels "status"
    moving: Discs  # MOVING_FIELDS
    temporary: list[tuple[tuple[int, int], ...]]  # (T,) obstacle cells shown at each tick
    plans: dict[str, list[dict]]  # PlanMsg dicts per AGV, in order
    events: list[dict]

    @property
    def dt(self) -> float | None:
        """The control period, from the ticks' clock (None with fewer than two ticks)."""
        if len(self.tick) < 2 or self.tick[-1] == self.tick[0]:
            return None
        return float((self.time[-1] - self.time[0]) / (self.tick[-1] - self.tick[0]))


def extract(rec: Recording) -> RunSeries:
    try:
        return _extract(rec)
    except (KeyError, TypeError, ValueError, IndexError) as err:
        raise SeriesError(
            f"{rec.path}: messages without the fields of agv-fleet messages "
            f"({type(err).__name__}: {err})"
        ) from None


def _extract(rec: Recording) -> RunSeries:
    maps = rec.of(keys.WORLD_MAP)
    with paused_gc():
        tick, time, agvs, moving, temporary = _from_ticks(rec)
    names = list(dict.fromkeys([*agvs.names, *rec.agv_names()]))
    return RunSeries(
        grid=map_grid(maps[0].data) if maps else None,
        tick=tick,
        time=time,
        agvs=agvs,
        moving=moving,
        temporary=temporary,
        plans={n: [m.data for m in rec.of(keys.agv_plan(n))] for n in names},
        events=[m.data for m in rec.of(keys.WORLD_EVENT)],
    )


def _from_ticks(rec: Recording):
    """Arrays from the ticks. The decoded ticks (every AGV's state at every tick: most of
    a recording) die when this returns, before the garbage collector resumes, so it
    never has to walk them."""
    ticks = list(rec.data_of(keys.WORLD_TICK))
    return (
        np.array([t["tick"] for t in ticks], dtype=np.int64),
        np.array([t["time"] for t in ticks], dtype=float),
        _discs([t["agvs"] for t in ticks], AGV_FIELDS, ("status",)),
        _discs([t["moving"] for t in ticks], MOVING_FIELDS, ()),
        [tuple(tuple(c) for c in t["temporary"]) for t in ticks],
    )


def map_grid(msg: dict) -> GridMap:
    """The GridMap of a decoded ``world/map`` message (``MapMsg``), in the run's world
    frame: its origin honoured (absent in older recordings: (0, 0)). The one place that
    turns a map message back into a map."""
    cells = np.frombuffer("".join(msg["rows"]).encode(), dtype=np.uint8)
    blocked = cells.reshape(msg["height"], msg["width"]) == ord("#")
    return GridMap.from_rows_top_down(blocked, msg["resolution"], msg["name"], map_origin(msg))


def _discs(per_tick: list[list[dict]], fields: tuple[str, ...], text: tuple[str, ...]) -> Discs:
    flat = [d for discs in per_tick for d in discs]
    listed = [d["name"] for d in flat]
    names = list(dict.fromkeys(listed))
    shape = (len(per_tick), len(names))
    row = np.dtype((float, len(fields)))
    numbers = np.fromiter(map(itemgetter(*fields), flat), dtype=row, count=len(flat))
    labels_flat = {f: np.array(list(map(itemgetter(f), flat)), dtype=object) for f in text}
    if listed == names * shape[0]:  # the usual case: the same discs in order at every tick
        columns = {f: numbers[:, i].reshape(shape) for i, f in enumerate(fields)}
        labels = {f: v.reshape(shape) for f, v in labels_flat.items()}
        return Discs(names, columns, labels)
    rows = np.repeat(np.arange(shape[0]), [len(discs) for discs in per_tick])
    column = {n: j for j, n in enumerate(names)}
    cols = np.array([column[n] for n in listed], dtype=np.int64)
    columns = {f: np.full(shape, math.nan) for f in fields}
    labels = {f: np.full(shape, None, dtype=object) for f in text}
    for i, f in enumerate(fields):
        columns[f][rows, cols] = numbers[:, i]
    for f, v in labels_flat.items():
        labels[f][rows, cols] = v
    return Discs(names, columns, labels)
