"""Where a recorded map lies in the world frame: the one place both viewers ask.

The Rerun view and the Foxglove channels both draw the map's grid from its
bottom-left corner; this function is the single definition of that corner.
"""

from __future__ import annotations


def map_origin(map_data: dict) -> tuple[float, float]:
    """The world coordinates (m) of the bottom-left corner of a ``world/map`` message
    (dict form). Maps carry no origin yet, so every map starts at (0, 0): point this
    at the message's origin fields when ``MapMsg`` gets them."""
    return (0.0, 0.0)


def map_size(map_data: dict) -> tuple[float, float]:
    """Width and height of the map in metres."""
    res = map_data["resolution"]
    return map_data["width"] * res, map_data["height"] * res
