"""Read maps from text grids, 0/1 matrices, MovingAI benchmarks and ROS map_server files.

Every reader returns a :class:`GridMap` in the world frame of DESIGN.md (row 0 at the
bottom), named after the file stem. All file formats list the TOP row first, so they go
through :meth:`GridMap.from_rows_top_down`. Bad input raises :class:`MapError` naming the
file and the problem; nothing here writes or prints.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from planner.grid_map import GridMap, MapError
from planner.limits import check_map_cells, read_input_file

MOVINGAI_FREE = frozenset(".GS")
MOVINGAI_BLOCKED = frozenset("@OTW")
ROS_MODES = ("trinary", "scale", "raw")


# --- shared helpers --------------------------------------------------------------------
def _read_bytes(path: Path, what: str = "map file") -> bytes:
    try:
        return read_input_file(path, what)
    except FileNotFoundError:
        raise MapError(f"{what} not found: {path}") from None
    except OSError as err:
        raise MapError(f"cannot read {what} {path}: {err.strerror or err}") from None


def _read_text(path: Path) -> str:
    try:
        return _read_bytes(path).decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise MapError(f"{path}: not a UTF-8 text file (byte {err.start})") from None


def _grid(rows_top_down: np.ndarray, resolution: float, path: Path) -> GridMap:
    """Build the GridMap, putting the file name into GridMap's own errors."""
    try:
        return GridMap.from_rows_top_down(rows_top_down, resolution, path.stem)
    except MapError as err:
        raise MapError(f"{path}: {err}") from None


# --- '.'/'#' text grids ----------------------------------------------------------------
def _text_rows(text: str, where: str) -> np.ndarray:
    """The rows of a '.'/'#' grid, top row first; errors give the line number in ``text``."""
    lines = [line.rstrip() for line in text.splitlines()]
    numbered = [(i + 1, line) for i, line in enumerate(lines)]
    while numbered and not numbered[0][1]:
        numbered.pop(0)
    while numbered and not numbered[-1][1]:
        numbered.pop()
    if not numbered:
        raise MapError(f"{where}: no grid rows")
    width = len(numbered[0][1])
    check_map_cells(width, len(numbered), where)
    for lineno, line in numbered:
        if len(line) != width:
            raise MapError(
                f"{where}: line {lineno} has {len(line)} cells, expected {width} "
                "(all rows must have the same length)"
            )
        for col, char in enumerate(line):
            if char not in ".#":
                raise MapError(
                    f"{where}: unknown character {char!r} at line {lineno}, column {col + 1} "
                    "(use '.' for free and '#' for blocked)"
                )
    return np.array([[char == "#" for char in line] for _, line in numbered], dtype=bool)


def parse_text_grid(text: str, resolution: float = 1.0, name: str = "map") -> GridMap:
    """A map from rows printed top to bottom: '.' free, '#' blocked."""
    rows = _text_rows(text, f"text map {name!r}")
    return GridMap.from_rows_top_down(rows, resolution, name)


# --- 0/1 matrices ----------------------------------------------------------------------
def _matrix_rows(text: str, path: Path) -> np.ndarray:
    rows: list[list[bool]] = []
    first_lineno = 0  # the line of the first row, which sets the width
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        bad = next((t for t in tokens if t not in ("0", "1")), None)
        if bad is not None:
            raise MapError(f"{path}: line {lineno}: expected 0 or 1, got {bad!r}")
        if not rows:
            first_lineno = lineno
        elif len(tokens) != len(rows[0]):
            raise MapError(
                f"{path}: line {lineno} has {len(tokens)} values, "
                f"expected {len(rows[0])} like line {first_lineno}"
            )
        rows.append([t == "1" for t in tokens])
        check_map_cells(len(tokens), len(rows), str(path))
    if not rows:
        raise MapError(f"{path}: no grid rows (only comments or blank lines)")
    return np.array(rows, dtype=bool)


def load_matrix_text(path: str | os.PathLike, resolution: float = 1.0) -> GridMap:
    """A '#'-commented matrix of 0/1 values (1 = obstacle), first row = top row."""
    path = Path(path)
    return _grid(_matrix_rows(_read_text(path), path), resolution, path)


def _is_matrix(text: str) -> bool:
    """Tell a 0/1 matrix from a '.'/'#' grid (whose rows may also start with '#').

    The first line that does not start with '#' decides; if every line starts with '#',
    it is a grid only if it holds nothing but '#' and '.'.
    """
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    for line in lines:
        if not line.startswith("#"):
            return line[0] in "01"
    return any(set(line) - set("#.") for line in lines)


# --- MovingAI --------------------------------------------------------------------------
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
    lines = [line.rstrip() for line in _read_text(path).splitlines()]
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
    return _grid(rows, resolution, path)


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
    for lineno, line in enumerate(_read_text(path).splitlines(), start=1):
        fields = line.split()
        if not fields or (lineno == 1 and fields[0] == "version"):
            continue
        scenarios.append(_scenario(fields, path, lineno))
    return scenarios


# --- ROS map_server --------------------------------------------------------------------
@dataclass(frozen=True)
class RosMapInfo:
    """The contents of a ROS map_server YAML file, ``image`` resolved against its folder.

    ``origin`` (x, y, yaw) is the pose of the image's bottom-left pixel in the ROS ``map``
    frame; load_ros_map makes (x, y) the GridMap's origin, so world coordinates are the
    ones a ROS user reads in RViz. A non-zero yaw is refused there (see ``check_yaw``).
    """

    image: Path
    resolution: float
    origin: tuple[float, float, float]
    occupied_thresh: float
    free_thresh: float
    negate: bool
    mode: str = "trinary"


def _number(value, key: str, path: Path) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise MapError(f"{path}: '{key}' must be a number, got {value!r}")
    return float(value)


def read_ros_map_info(yaml_path: str | os.PathLike) -> RosMapInfo:
    """Parse and check a ROS map_server YAML file (the image is not read)."""
    path = Path(yaml_path)
    try:
        doc = yaml.safe_load(_read_text(path))
    except yaml.YAMLError as err:
        raise MapError(f"{path}: invalid YAML: {err}") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path}: expected a YAML mapping of map_server keys")
    required = ("image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate")
    missing = [key for key in required if key not in doc]
    if missing:
        raise MapError(f"{path}: missing key(s): {', '.join(missing)}")
    if not isinstance(doc["image"], str) or not doc["image"]:
        raise MapError(f"{path}: 'image' must be a file name, got {doc['image']!r}")
    resolution = _number(doc["resolution"], "resolution", path)
    if resolution <= 0:
        raise MapError(f"{path}: 'resolution' must be positive, got {resolution:g}")
    origin = doc["origin"]
    if not isinstance(origin, list) or len(origin) != 3:
        raise MapError(f"{path}: 'origin' must be a list [x, y, yaw], got {origin!r}")
    origin = tuple(_number(value, "origin", path) for value in origin)
    occupied = _number(doc["occupied_thresh"], "occupied_thresh", path)
    free = _number(doc["free_thresh"], "free_thresh", path)
    if not 0 <= free <= occupied <= 1:
        raise MapError(
            f"{path}: need 0 <= free_thresh <= occupied_thresh <= 1, "
            f"got free_thresh {free:g} and occupied_thresh {occupied:g}"
        )
    if doc["negate"] not in (0, 1):  # also accepts YAML true/false
        raise MapError(f"{path}: 'negate' must be 0 or 1, got {doc['negate']!r}")
    mode = doc.get("mode", "trinary")
    if mode not in ROS_MODES:
        raise MapError(f"{path}: 'mode' must be one of {', '.join(ROS_MODES)}, got {mode!r}")
    image = path.parent / doc["image"]  # an absolute image path stays absolute
    return RosMapInfo(image, resolution, origin, occupied, free, bool(doc["negate"]), mode)


_PGM_SEP = rb"(?:\s|#[^\r\n]*[\r\n])+"  # whitespace and '#' comments between header fields
_PGM_HEADER = re.compile(
    rb"(P[25])" + _PGM_SEP + rb"(\d+)" + _PGM_SEP + rb"(\d+)" + _PGM_SEP + rb"(\d+)\s"
)


def _read_pgm(path: str | os.PathLike) -> tuple[np.ndarray, int]:
    """(pixels, maxval) of a binary (P5, 8 or 16 bit) or plain (P2) PGM; top row first."""
    path = Path(path)
    if path.suffix.lower() != ".pgm":
        raise MapError(
            f"{path}: only PGM map images are supported, not {path.suffix or 'no extension'!r} "
            "(convert it to .pgm)"
        )
    data = _read_bytes(path, "map image")
    match = _PGM_HEADER.match(data)
    if match is None:
        problem = "bad PGM header" if data[:2] in (b"P2", b"P5") else "not a PGM file (no P2/P5)"
        raise MapError(f"{path}: {problem}")
    magic, width, height, maxval = match[1], int(match[2]), int(match[3]), int(match[4])
    if width == 0 or height == 0 or not 0 < maxval < 65536:
        raise MapError(f"{path}: bad PGM header: size {width}x{height}, maxval {maxval}")
    check_map_cells(width, height, str(path))
    count = width * height
    if magic == b"P5":
        dtype = np.dtype("u1" if maxval < 256 else ">u2")
        available = (len(data) - match.end()) // dtype.itemsize
        if available < count:
            raise MapError(f"{path}: truncated PGM: {available} of {count} pixels present")
        pixels = np.frombuffer(data, dtype, count, match.end())
    else:
        tokens = data[match.end() :].split()
        if len(tokens) < count:
            raise MapError(f"{path}: truncated PGM: {len(tokens)} of {count} pixels present")
        if not all(token.isdigit() for token in tokens[:count]):
            raise MapError(f"{path}: plain PGM pixels must be non-negative integers")
        pixels = np.array([int(token) for token in tokens[:count]], dtype=np.int64)
    if pixels.max() > maxval:
        raise MapError(f"{path}: pixel value {pixels.max()} exceeds maxval {maxval}")
    return pixels.reshape(height, width), maxval


OCC_FREE, OCC_OCCUPIED, OCC_UNKNOWN = 0, 100, -1  # nav_msgs/OccupancyGrid values


def ros_occupancy(pixels: np.ndarray, maxval: int, info: RosMapInfo) -> np.ndarray:
    """The nav_msgs/OccupancyGrid values map_server publishes for these pixels (top row
    first): 0 free, 100 occupied, -1 unknown, 1-99 partly occupied (nav2_map_server's
    ``loadMapFromFile``).

    shade = pixel / maxval; occupancy p = 1 - shade (shade if ``negate``).
    trinary: p > occupied_thresh occupied, p < free_thresh free, anything between unknown.
    scale: the same, but between the thresholds p is scaled linearly to 1-99 (a PGM has no
    alpha channel, so nothing is unknown). raw: the value is round(shade * 255) - the
    occupancy in percent, ``negate`` not applied, as map_server does - and above 100 unknown.
    """
    shade = pixels / maxval
    if info.mode == "raw":
        percent = np.rint(shade * 255).astype(np.int16)
        return np.where(percent <= OCC_OCCUPIED, percent, OCC_UNKNOWN).astype(np.int8)
    occ = shade if info.negate else 1.0 - shade
    out = np.full(pixels.shape, OCC_UNKNOWN, dtype=np.int8)
    if info.mode == "scale":
        span = max(info.occupied_thresh - info.free_thresh, 1e-12)
        between = np.rint((occ - info.free_thresh) / span * 100.0)
        out = np.clip(between, 1, 99).astype(np.int8)
    out[occ > info.occupied_thresh] = OCC_OCCUPIED
    out[occ < info.free_thresh] = OCC_FREE
    return out


UNKNOWN_CHOICES = ("obstacle", "free")


def ros_blocked(occupancy: np.ndarray, info: RosMapInfo, unknown: str = "obstacle") -> np.ndarray:
    """Which OccupancyGrid cells a planner must keep out of.

    Occupied (100) always. Partly occupied (1-99), since a planner must not enter
    uncertain space: in scale mode always (the value lies between the thresholds), in
    raw mode when the percentage reaches ``free_thresh``. Unknown (-1) unless
    ``unknown == "free"``: an unexplored area is not known to be empty.
    """
    if unknown not in UNKNOWN_CHOICES:
        raise MapError(
            f"unknown cells must be one of {', '.join(UNKNOWN_CHOICES)}, got {unknown!r}"
        )
    partly = (occupancy > OCC_FREE) & (occupancy < OCC_OCCUPIED)
    if info.mode == "raw":
        partly &= occupancy.astype(np.float64) / 100.0 >= info.free_thresh
    blocked = partly | (occupancy == OCC_OCCUPIED)
    if unknown == "obstacle":
        blocked |= occupancy == OCC_UNKNOWN
    return blocked


def check_yaw(info: RosMapInfo, path: Path) -> None:
    """A rotated map (origin yaw != 0) is refused rather than silently drawn unrotated."""
    yaw = info.origin[2]
    if yaw != 0.0:
        raise MapError(
            f"{path}: origin yaw {yaw:g} rad is not supported (the map's cells must be "
            "aligned with the map frame): rotate the image and set the yaw to 0"
        )


def load_ros_map(
    yaml_path: str | os.PathLike, resolution: float | None = None, unknown: str = "obstacle"
) -> GridMap:
    """A ROS map_server map (YAML + PGM) in its ``map`` frame: the YAML's origin (x, y) is
    the GridMap's origin, and its resolution is used unless one is given. ``unknown``:
    whether unknown cells are obstacles (default) or free (see :func:`ros_blocked`).
    """
    path = Path(yaml_path)
    info = read_ros_map_info(path)
    check_yaw(info, path)
    if unknown not in UNKNOWN_CHOICES:
        raise MapError(
            f"{path}: unknown cells must be one of {', '.join(UNKNOWN_CHOICES)}, got {unknown!r}"
        )
    if not info.image.is_file():
        raise MapError(f"{path}: map image not found: {info.image}")
    pixels, maxval = _read_pgm(info.image)
    blocked = ros_blocked(ros_occupancy(pixels, maxval, info), info, unknown)
    res = info.resolution if resolution is None else resolution
    try:
        return GridMap.from_rows_top_down(blocked, res, path.stem, info.origin[:2])
    except MapError as err:
        raise MapError(f"{path}: {err}") from None


# --- any file --------------------------------------------------------------------------
def load_map(
    path: str | os.PathLike, resolution: float | None = None, unknown: str = "obstacle"
) -> GridMap:
    """Load a map, choosing the reader by extension.

    ``.map`` MovingAI, ``.yaml``/``.yml`` ROS map_server, ``.txt``/``.grid`` a 0/1 matrix
    or a '.'/'#' grid (told apart by content). ``resolution`` defaults to 1.0, or to the
    YAML's value for ROS maps. ROS maps keep their origin (the ``map`` frame) and their
    unknown cells are obstacles unless ``unknown="free"``; the other formats have their
    origin at (0, 0) and no unknown cells.
    """
    path = Path(path)
    if not path.exists():
        raise MapError(f"map file not found: {path}")
    if unknown not in UNKNOWN_CHOICES:
        raise MapError(
            f"unknown cells must be one of {', '.join(UNKNOWN_CHOICES)}, got {unknown!r}"
        )
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return load_ros_map(path, resolution, unknown)
    res = 1.0 if resolution is None else resolution
    if suffix == ".map":
        return load_movingai(path, res)
    if suffix in (".txt", ".grid"):
        text = _read_text(path)
        rows = _matrix_rows(text, path) if _is_matrix(text) else _text_rows(text, str(path))
        return _grid(rows, res, path)
    raise MapError(
        f"{path}: unknown map file extension {path.suffix or '(none)'!r}: "
        "expected .map (MovingAI), .yaml/.yml (ROS map_server) or .txt/.grid (text grid)"
    )
