"""MovingAI benchmark maps (``.map``) and their scenario files (``.scen``)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from planner.core.errors import MapError
from planner.core.limits import check_map_cells
from planner.maps.grid import GridMap
from planner.maps.map_files import grid_from_rows, read_text

MOVINGAI_FREE = frozenset(".GS")
MOVINGAI_BLOCKED = frozenset("@OTW")


def _movingai_header(lines: list[str], path: Path) -> tuple[int, int, int]:
    """(height, width, index of the first grid line) from 'type/height/width/map'."""
    fields: dict[str, str] = {}
    for i, line in enumerate(lines):
        words = line.split()
        if words == ["map"]:
            break
        if len(words) != 2 or words[0] not in ("type", "height", "width"):
            raise MapError(
                f"{path}: bad MovingAI header at line {i + 1}: {line.strip()!r} "
                "(expected 'type octile', 'height H', 'width W', then 'map')"
            )
        fields[words[0]] = words[1]
    else:
        raise MapError(f"{path}: bad MovingAI header: no 'map' line")
    for key in ("type", "height", "width"):
        if key not in fields:
            raise MapError(f"{path}: bad MovingAI header: no '{key}' line")
    if fields["type"] != "octile":
        raise MapError(f"{path}: unsupported MovingAI map type {fields['type']!r}, want 'octile'")
    sizes = []
    for key in ("height", "width"):
        value = fields[key]
        if not (value.isascii() and value.isdigit()) or int(value) == 0:
            raise MapError(
                f"{path}: bad MovingAI header: {key} {value!r} is not a positive integer"
            )
        sizes.append(int(value))
    check_map_cells(sizes[1], sizes[0], str(path))
    return sizes[0], sizes[1], i + 1


def load_movingai(path: str | os.PathLike, resolution: float = 1.0) -> GridMap:
    """A MovingAI ``.map``: '.', 'G', 'S' free; '@', 'O', 'T', 'W' blocked; top row first."""
    path = Path(path)
    lines = [line.rstrip() for line in read_text(path).splitlines()]
    height, width, start = _movingai_header(lines, path)
    body = lines[start:]
    while body and not body[-1]:
        body.pop()
    if len(body) != height:
        raise MapError(f"{path}: header says height {height} but the map has {len(body)} rows")
    for i, line in enumerate(body):
        lineno = start + i + 1
        if len(line) != width:
            raise MapError(
                f"{path}: line {lineno} has {len(line)} cells but the header says width {width}"
            )
        bad = set(line) - MOVINGAI_FREE - MOVINGAI_BLOCKED
        if bad:
            raise MapError(
                f"{path}: unknown map character {min(bad)!r} at line {lineno} "
                "(free: '.', 'G', 'S'; blocked: '@', 'O', 'T', 'W')"
            )
    rows = np.array([[char in MOVINGAI_BLOCKED for char in line] for line in body], dtype=bool)
    return grid_from_rows(rows, resolution, path)


@dataclass(frozen=True)
class MovingAiScenario:
    """One line of a MovingAI ``.scen`` file, rows converted to the world frame (0 = bottom)."""

    bucket: int
    map_name: str
    width: int
    height: int
    start_col: int
    start_row: int
    goal_col: int
    goal_row: int
    optimal_length: float

    @property
    def start(self) -> tuple[int, int]:
        return self.start_col, self.start_row

    @property
    def goal(self) -> tuple[int, int]:
        return self.goal_col, self.goal_row


def _scenario(fields: list[str], path: Path, lineno: int) -> MovingAiScenario:
    where = f"{path}: line {lineno}"
    if len(fields) != 9:
        raise MapError(f"{where}: expected 9 fields, got {len(fields)}")
    try:
        bucket, width, height, sx, sy, gx, gy = (int(fields[i]) for i in (0, 2, 3, 4, 5, 6, 7))
        optimal = float(fields[8])
    except ValueError:
        raise MapError(f"{where}: expected integers and a final length, got {fields}") from None
    if width <= 0 or height <= 0:
        raise MapError(f"{where}: map size {width}x{height} is not positive")
    for what, x, y in (("start", sx, sy), ("goal", gx, gy)):
        if not (0 <= x < width and 0 <= y < height):
            raise MapError(f"{where}: {what} ({x}, {y}) is outside the {width}x{height} map")
    if not (math.isfinite(optimal) and optimal >= 0):
        raise MapError(f"{where}: optimal length {fields[8]!r} is not a non-negative number")
    flip = height - 1
    return MovingAiScenario(bucket, fields[1], width, height, sx, flip - sy, gx, flip - gy, optimal)


def load_movingai_scenarios(path: str | os.PathLike) -> list[MovingAiScenario]:
    """The entries of a MovingAI ``.scen`` file (an optional 'version' line first)."""
    path = Path(path)
    scenarios = []
    for lineno, line in enumerate(read_text(path).splitlines(), start=1):
        fields = line.split()
        if not fields or (lineno == 1 and fields[0] == "version"):
            continue
        scenarios.append(_scenario(fields, path, lineno))
    return scenarios
