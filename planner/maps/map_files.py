"""Reading a map file: sizes checked before reading, errors that name the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from planner.core.errors import MapError
from planner.core.limits import read_input_file
from planner.maps.grid import GridMap


def read_bytes(path: Path, what: str = "map file") -> bytes:
    try:
        return read_input_file(path, what)
    except FileNotFoundError:
        raise MapError(f"{what} not found: {path}") from None
    except OSError as err:
        raise MapError(f"cannot read {what} {path}: {err.strerror or err}") from None


def read_text(path: Path) -> str:
    try:
        return read_bytes(path).decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise MapError(f"{path}: not a UTF-8 text file (byte {err.start})") from None


def grid_from_rows(rows_top_down: np.ndarray, resolution: float, path: Path) -> GridMap:
    """Build the GridMap, putting the file name into GridMap's own errors."""
    try:
        return GridMap.from_rows_top_down(rows_top_down, resolution, path.stem)
    except MapError as err:
        raise MapError(f"{path}: {err}") from None
