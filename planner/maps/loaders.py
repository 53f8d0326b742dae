"""Read a map file of any kind: text grids, 0/1 matrices, MovingAI maps, ROS map_server.

Every reader returns a :class:`GridMap` in the world frame of DESIGN.md (row 0 at the
bottom), named after the file stem. All file formats list the TOP row first, so they go
through :meth:`GridMap.from_rows_top_down`. Bad input raises :class:`MapError` naming the
file and the problem; nothing here writes or prints.
"""

from __future__ import annotations

import os
from pathlib import Path

from planner.core.errors import MapError
from planner.maps.grid import GridMap
from planner.maps.movingai import load_movingai
from planner.maps.ros_map import UNKNOWN_CHOICES, load_ros_map
from planner.maps.text_maps import load_text_map


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
        return load_text_map(path, res)
    raise MapError(
        f"{path}: unknown map file extension {path.suffix or '(none)'!r}: "
        "expected .map (MovingAI), .yaml/.yml (ROS map_server) or .txt/.grid (text grid)"
    )
