"""Limits on the size of inputs, each checked before anything is allocated for them.

A map costs about 22 bytes a cell in every process that plans on it (the grid,
its prefix sums, distance field, costmap and A*'s arrays): 20000 x 20000
cells grew past 9 GB. ``MAX_MAP_CELLS`` (2000 x 2000, ~90 MB a process) is
above every public benchmark map (MovingAI's largest are 1024 x 1024).
``MAX_INPUT_FILE_BYTES`` bounds what is read of any input file (a map,
its image, a scenario): the largest map in its most verbose format fits.
Only regular files are read: a FIFO would hang the reader and a link to
/dev/zero would be read until memory runs out.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO

from planner.core.errors import MapError

MAX_MAP_CELLS = 4_000_000
MAX_INPUT_FILE_BYTES = 64 * 1024 * 1024


def check_map_cells(width: int, height: int, where: str) -> None:
    """MapError if a ``width`` x ``height`` map is larger than MAX_MAP_CELLS."""
    if width * height > MAX_MAP_CELLS:
        raise MapError(
            f"{where}: a {width} x {height} map has {width * height:,} cells, "
            f"more than the {MAX_MAP_CELLS:,} allowed"
        )


def read_input_file(path: Path, what: str) -> bytes:
    """The bytes of a regular file of at most MAX_INPUT_FILE_BYTES (symbolic links
    followed); OSError or MapError with one line otherwise."""
    with open_regular_file(path, what) as f:
        data = f.read(MAX_INPUT_FILE_BYTES + 1)
    if len(data) > MAX_INPUT_FILE_BYTES:
        raise MapError(f"{what} {path} is larger than {MAX_INPUT_FILE_BYTES // 2**20} MiB")
    return data


def open_regular_file(path: Path, what: str) -> BinaryIO:
    """``path`` open for reading if it is a regular file (links followed), else
    MapError; opening never blocks (a FIFO's open waits for a writer otherwise)."""
    f = open(path, "rb", opener=lambda p, flags: os.open(p, flags | os.O_NONBLOCK))  # noqa: SIM115
    if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
        f.close()
        raise MapError(f"{what} {path} is not a regular file")
    return f
