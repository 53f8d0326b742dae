"""Where a recorded map lies in the world frame: the one place both viewers ask.

The Rerun view and the Foxglove channels both draw the map's grid from its
bottom-left corner; this function is the single definition of that corner.
"""

from __future__ import annotations


def map_origin(map_data: dict) -> tuple[float, float]:
    """The world coordinates (m) of the bottom-left corner of a ``world/map`` message
    (dict form): the ROS map's ``origin``; (0, 0) for text maps and for recordings made
    before maps carried one."""
    x, y = map_data.get("origin") or (0.0, 0.0)
    return (float(x), float(y))


def map_size(map_data: dict) -> tuple[float, float]:
    """Width and height of the map in metres."""
    res = map_data["resolution"]
    return map_data["width"] * res, map_data["height"] * res
